"""Reach errors over a test set summarised as a user reads them: median, 90 %, coverage.

E^X (Eq. 9) is a mean; over a large region a few points near the joint limits or behind the robot
dominate it, and a median with its 90 % quantile says more (docs/WORKSPACE.md). Coverage is the
share of the test points reached within a tolerance (1 cm, 2 mm).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

COVERAGE_LEVELS = (0.01, 0.002)  # [m]: the coverage reported (1 cm, 2 mm)


class ReachErrors(NamedTuple):
    """Per-point reach errors ||x*_i - f(g(x*_i))|| of a learned inverse over test points.

    Attributes:
        errors: (N,) error of each test point [task units, m].
        median: their median.
        p90: their 90 % quantile.
        mean: their mean (E^X, Eq. 9).
        coverage: (share within 1 cm, share within 2 mm) of :data:`COVERAGE_LEVELS`.
    """

    errors: NDArray[np.float64]
    median: float
    p90: float
    mean: float
    coverage: tuple[float, ...]

    @classmethod
    def of(cls, errors: ArrayLike) -> ReachErrors:
        """The summary of an (N,) array of errors."""
        e = np.asarray(errors, dtype=float).ravel()
        return cls(
            e,
            float(np.median(e)),
            float(np.quantile(e, 0.9)),
            float(e.mean()),
            tuple(float(np.mean(e <= level)) for level in COVERAGE_LEVELS),
        )

    def summary(self) -> str:
        """One line: ``median 1.93 mm, 90 % 9.1 mm, within 1 cm 91.0 %, within 2 mm 52.3 %``."""
        cover = ", ".join(
            f"within {level * 1000:g} mm {share:.1%}"
            if level < 0.01
            else f"within {level * 100:g} cm {share:.1%}"
            for level, share in zip(COVERAGE_LEVELS, self.coverage, strict=True)
        )
        head = f"median {self.median * 1000:.3g} mm, 90 % {self.p90 * 1000:.3g} mm"
        return f"{head}, {cover} ({len(self.errors)} points)"
