#!/bin/bash
# Cold starts of the README's first command (an empty numba cache each time), source trees alternated:
#   scripts/cold_start.sh ROUNDS TREE [TREE ...]      e.g. scripts/cold_start.sh 3 . /tmp/wt90
# (a tree is a checkout: git worktree add /tmp/wt90 90efb21). Prints per run: tree, user and system CPU
# time [s], wall time [s], load average. Uses this checkout's .venv for every tree (PYTHONPATH=TREE).
set -euo pipefail
PY=${PYTHON:-$(cd "$(dirname "$0")/.." && pwd)/.venv/bin/python}
rounds=$1
shift
work=$(mktemp -d)
for _ in $(seq "$rounds"); do
  for tree in "$@"; do
    cache=$(mktemp -d)
    tree=$(cd "$tree" && pwd)
    times=$( { cd "$work" && /usr/bin/time -f "%U %S %e" env NUMBA_CACHE_DIR="$cache" PYTHONPATH="$tree" \
      "$PY" -m gb_pin babble --robot planar20 --movements 1000 --seed 0 --quiet > /dev/null; } 2>&1 | tail -1)
    echo "$tree $times $(uptime | sed 's/.*average: //')"
    rm -rf "$cache"
  done
done
rm -rf "$work"
