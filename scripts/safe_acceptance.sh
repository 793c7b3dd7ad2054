#!/bin/bash
# Issue 34's acceptance runs, seeds in sequence, each robot in turn, each run cached in DIR (a run
# already there is skipped: stop it and start it again at will). so101-issue: the issue's own scene
# (its post at (0.21, 0, 0.045)); so101: our earlier, three times as obstructed one (docs/SAFETY.md).
#   scripts/safe_acceptance.sh kinematic DIR     # the kinematic robot (baseline: compiled babble)
#   scripts/safe_acceptance.sh mujoco DIR        # the MuJoCo plant, contacts on
MODE=${1:?kinematic or mujoco}
DIR=${2:?a cache folder}
cd "$(dirname "$0")/.." || exit 1
PYTHON=${PYTHON:-.venv/bin/python}
for s in 0 1 2 3 4; do
  for r in so101-issue so101 panda; do
    if [ "$MODE" = kinematic ]; then
      nice -n 10 "$PYTHON" scripts/safe_babbling.py --kinematic --movements 10000 --seeds "$s" --robots "$r" --cache "$DIR"
    else
      nice -n 10 "$PYTHON" scripts/safe_babbling.py --movements 10000 --seeds "$s" --robots "$r" --cache "$DIR"
    fi
  done
done
