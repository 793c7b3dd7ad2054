"""The learner's hyperparameters, defined once (paper Secs. II-III).

:data:`HYPERPARAMETERS` is the single table of the seven hyperparameters (the paper's six and the
map's cutoff, which is not the paper's): names (the paper's meaning), symbols, defaults, validation
and help texts. Everything else derives from it:
:class:`BabbleConfig`, :class:`~gb_pin.learn.learner.GoalBabbling`'s defaults, ``babble()``'s
keyword arguments, the CLI options (``--learning-rate`` ...), the preset overrides of
``robots/*.toml`` (``[learner]`` tables) and the trial and sweep arguments.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass
from typing import Any

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError


def default_sigma(n_joints: int) -> float:
    """Exploration noise per joint keeping the effector deviation at 0.05 sqrt(3) (Eq. 12).

    sigma^X = sigma sqrt((m + 1) / 2) = 0.05 sqrt(3), i.e. sigma = 0.05 at m = 5 (Sec. III-A/B).
    """
    return 0.05 * math.sqrt(3.0) / math.sqrt((n_joints + 1) / 2.0)


@dataclass(frozen=True)
class Hyperparameter:
    """One hyperparameter of the learner.

    Attributes:
        name: the keyword name (the paper's meaning), e.g. ``"learning_rate"``.
        symbol: the paper's symbol, e.g. ``"eta"``.
        default: the default value; None where it derives from the robot (sigma, sigma_delta).
        type: ``float`` or ``int``, what the CLI parses.
        validate: ``validate(name, value)`` returns the value converted, or raises
            :class:`~gb_pin.exceptions.InvalidArgumentError`.
        help: one line for ``--help`` and the docs, with the unit.
    """

    name: str
    symbol: str
    default: float | int | None
    type: type
    validate: Callable[[str, Any], Any]
    help: str

    @property
    def option(self) -> str:
        """The CLI option, e.g. ``--learning-rate``."""
        return "--" + self.name.replace("_", "-")

    def check(self, value: Any) -> Any:
        """``value`` validated and converted (an int for ``path_length``, floats otherwise)."""
        return self.validate(self.name, value)


def _cutoff(name: str, value: Any) -> float | None:
    """None (no truncation) or a cutoff in radii, in (0, 26]."""
    if value is None:
        return None
    c = check.positive_float(name, value)
    if c > 26.0:
        raise InvalidArgumentError(f"{name} is in radii, at most 26 (or none), got {value!r}")
    return c


MAX_PATH_LENGTH = 10**6
"""The longest movement (path_length, L) accepted: the paper uses 25."""

HYPERPARAMETERS: tuple[Hyperparameter, ...] = (
    Hyperparameter(
        "learning_rate", "eta", 0.1, float, check.positive_float,
        "eta, the learning rate of the online gradient descent (paper: 0.001-0.5)",
    ),
    Hyperparameter(
        "sigma", "sigma", None, float, check.nonnegative_float,
        "exploration noise per joint (Eq. 8) [rad]; default Eq. 12 (0.05 at 5 joints)",
    ),
    Hyperparameter(
        "sigma_delta", "sigma_delta", None, float, check.nonnegative_float,
        "random-walk step of the exploration noise [rad]; default 0.1 sigma",
    ),
    Hyperparameter(
        "radius", "d", 0.1, float, check.positive_float,
        "d, the radius of the local-linear map's prototypes [m]",
    ),
    Hyperparameter(
        "path_length", "L", 25, int, lambda name, value: check.positive_int(name, value, 1, MAX_PATH_LENGTH),
        "L, time steps per movement (Eq. 3); at most 10^6",
    ),
    Hyperparameter(
        "p_home", "p_home", 0.1, float, check.probability,
        "probability of a home return after a goal-directed movement (Eq. 7)",
    ),
    Hyperparameter(
        "cutoff", "c", None, float, _cutoff,
        "c, prototypes below exp(-c^2) of the nearest one's activation left out of g [radii]; "
        "default: none (the paper's sums; a workspace region: 4)",
    ),
)  # fmt: skip

BY_NAME: dict[str, Hyperparameter] = {h.name: h for h in HYPERPARAMETERS}
NAMES: tuple[str, ...] = tuple(BY_NAME)


def check_values(values: Mapping[str, Any], what: str = "hyperparameters") -> dict[str, Any]:
    """Validate a mapping of hyperparameter values (None = default); unknown names are an error."""
    unknown = sorted(set(values) - set(NAMES))
    if unknown:
        raise InvalidArgumentError(f"unknown {what} {unknown}; valid: {', '.join(NAMES)}")
    return {k: (None if v is None else BY_NAME[k].check(v)) for k, v in values.items()}


@dataclass(frozen=True)
class BabbleConfig:
    """Hyperparameters of one run, as used (defaults resolved); ``BabbleConfig()`` is the paper's planar5.

    Attributes:
        learning_rate: eta of the online gradient descent.
        sigma: standard deviation of the exploration noise entries (Eq. 8) [rad].
        sigma_delta: standard deviation of the noise's random-walk increments [rad].
        radius: radius d of the local-linear map's prototypes [m].
        path_length: L, steps per movement (Eq. 3).
        p_home: probability of a home return after a goal-directed movement (Eq. 7).
        cutoff: c [radii]: the map's sums leave out prototypes whose activation is below
            exp(-c^2) of the nearest one's (:class:`~gb_pin.learn.llm.LocalLinearMap`); None: all.
    """

    learning_rate: float = BY_NAME["learning_rate"].default  # type: ignore[assignment]
    sigma: float = default_sigma(5)
    sigma_delta: float = 0.1 * default_sigma(5)
    radius: float = BY_NAME["radius"].default  # type: ignore[assignment]
    path_length: int = BY_NAME["path_length"].default  # type: ignore[assignment]
    p_home: float = BY_NAME["p_home"].default  # type: ignore[assignment]
    cutoff: float | None = None

    def __post_init__(self) -> None:
        # Store plain Python floats/ints (numpy scalars would break the JSON of files).
        for h in HYPERPARAMETERS:
            object.__setattr__(self, h.name, h.check(getattr(self, h.name)))

    @classmethod
    def resolve(cls, n_joints: int, **values: Any) -> BabbleConfig:
        """The configuration for a robot of ``n_joints`` joints; None or missing values take the defaults.

        sigma defaults to Eq. 12 for ``n_joints``, sigma_delta to 0.1 sigma (Sec. III-B).
        """
        given = check_values(values)
        out: dict[str, Any] = {
            h.name: given.get(h.name) if given.get(h.name) is not None else h.default for h in HYPERPARAMETERS
        }
        if out["sigma"] is None:
            out["sigma"] = default_sigma(n_joints)
        out["sigma"] = float(out["sigma"])
        if out["sigma_delta"] is None:
            out["sigma_delta"] = 0.1 * out["sigma"]
        return cls(**out)

    def as_dict(self) -> dict[str, Any]:
        """The parameters as a plain dict."""
        return asdict(self)
