"""What the commands share: their parser class, option helpers, the learner's options.

:class:`CommandParser` lets each command module add its own options.

The six learner options (``--learning-rate`` ... ``--p-home``) of ``babble`` and ``trials`` are
generated from :data:`gb_pin.learn.config.HYPERPARAMETERS`: option name, type and help text are
defined there once. Their default is None: the robot preset's value, else the table's; the
values go on to ``babble(...)`` and ``run_trials(...)`` by the table's names
(:func:`learner_values`).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from gb_pin.exceptions import GbPinError, InvalidArgumentError

if TYPE_CHECKING:
    from gb_pin.learn.config import Hyperparameter


class CommandParser(argparse.ArgumentParser):
    """A sub-command's parser: ``sub.add_parser(name, help=..., configure=f)`` calls ``f(parser)``.

    ``f`` adds the command's options and ``func`` (what :func:`gb_pin.cli.main` calls), so each
    command module keeps its options next to the code that runs it.
    """

    def __init__(
        self, *args: Any, configure: Callable[[argparse.ArgumentParser], None] | None = None, **kwargs: Any
    ) -> None:
        super().__init__(*args, **kwargs)
        if configure is not None:
            configure(self)


if TYPE_CHECKING:
    Subparsers = argparse._SubParsersAction[CommandParser]
    """What ``add_subparsers()`` returns: each command's ``add_<command>(sub)`` registers it there."""


def _learner_help(h: Hyperparameter) -> str:
    """``--help`` text of one learner option: the table's text and where the default comes from."""
    default = "" if h.default is None else f"; default {h.default:g}"
    # argparse %-formats help texts: a literal percent sign must be doubled.
    return f"{h.help}{default}, or the robot preset's".replace("%", "%%")


def add_learner_options(parser: argparse.ArgumentParser) -> None:
    """The learner's hyperparameters as options (None: the robot preset's or the table's default)."""
    from gb_pin.learn.config import HYPERPARAMETERS  # the table only: numba is not imported

    for h in HYPERPARAMETERS:
        parser.add_argument(h.option, dest=h.name, type=h.type, default=None, help=_learner_help(h))


def learner_values(args: argparse.Namespace, *, given_only: bool = False) -> dict[str, Any]:
    """The learner options' values by hyperparameter name; ``given_only`` drops those left at None."""
    from gb_pin.learn.config import NAMES

    values = {name: getattr(args, name) for name in NAMES}
    return {k: v for k, v in values.items() if v is not None} if given_only else values


def comma_list(text: str) -> list[str]:
    """``"planar5, planar20,"`` as ``["planar5", "planar20"]``: stripped, empty items dropped."""
    return [item.strip() for item in text.split(",") if item.strip()]


def add_trial_seed(parser: argparse.ArgumentParser) -> None:
    """``--seed`` of commands running several trials."""
    parser.add_argument("--seed", type=int, default=0, help="seed of trial 0; trial i uses seed + i")


def add_workers(parser: argparse.ArgumentParser, text: str = "processes (default: all cores)") -> None:
    """``--workers``: local processes for the trials."""
    parser.add_argument("--workers", type=int, default=None, help=text)


def add_quiet(parser: argparse.ArgumentParser, text: str = "no progress bar") -> None:
    """``--quiet``: no progress bar."""
    parser.add_argument("--quiet", action="store_true", help=text)


def add_port(parser: argparse.ArgumentParser) -> None:
    """``--port`` of the browser viewer."""
    parser.add_argument("--port", type=int, default=None, help="viewer port (default: first free from 7000)")


def add_overwrite(parser: argparse.ArgumentParser, what: str) -> None:
    """``--overwrite`` (or ``--force``): let the command's output files replace existing ones.

    Without it a command whose output file exists refuses before any work, in one line naming the
    file (:func:`gb_pin.cli.checks.no_clobber`): two runs never silently replace each other's files.
    """
    parser.add_argument(
        "--overwrite",
        "--force",
        action="store_true",
        help=f"let {what} replace an existing file (without it, the command refuses before it starts)",
    )


def add_html(parser: argparse.ArgumentParser) -> None:
    """``--html``: write one offline file instead of serving."""
    parser.add_argument("--html", default=None, help="write one self-contained HTML file instead of serving")


ROBOT_HELP = (
    "a preset (e.g. planar5, talos_left_arm: `gb-pin robots`), a URDF file (my_arm.urdf) or erd:NAME "
    "(a robot of example-robot-data, e.g. erd:z1) with --frame, or MODULE:NAME (a module or a .py file, "
    "and a robot in it or a function of no arguments returning one, e.g. examples/continuum_arm.py:robot)"
)


def add_robot_options(b: argparse.ArgumentParser, default: str | None) -> None:
    """--robot (a preset, a URDF, erd:NAME or MODULE:NAME; ``default`` if not given) and the model options."""
    shown = f" (default {default})" if default else ""
    b.add_argument("--robot", default=None, help=f"the robot{shown}: {ROBOT_HELP}")
    add_model_options(b)


def add_model_options(b: argparse.ArgumentParser, robot: bool = False, task: bool = True) -> None:
    """--frame, --joints, --home, --axes, --srdf (and --robot if ``robot``): a URDF or erd:NAME model.

    ``robot``: add ``--robot`` too (``show``, ``replay``, ``plot``, ``ik``: the robot a result was
    learned on, when its file cannot rebuild it: a robot built in Python, loaded by MODULE:NAME, or a
    model moved or edited since; see :func:`result_robot`).
    """
    if robot:
        b.add_argument(
            "--robot",
            default=None,
            help="the run's robot, if the file cannot rebuild it (default: the one the file records): "
            + ROBOT_HELP,
        )
    b.add_argument(
        "--frame", default=None, help="with --robot FILE.urdf or erd:NAME: the effector frame (required)"
    )
    b.add_argument(
        "--joints",
        default=None,
        help="comma-separated joints the learner moves, others locked (default: chosen, the joints that "
        "move --frame)",
    )
    b.add_argument(
        "--home",
        default=None,
        help="home posture: comma-separated values over --joints, or a named posture of the SRDF "
        "(default: chosen, inside the limits and away from them and from singularities)",
    )
    b.add_argument("--axes", default=None, help="task axes, e.g. xyz or xy (default xyz)")
    b.add_argument(
        "--srdf",
        default=None,
        help="with --robot FILE.urdf: an SRDF file whose group states name postures for --home "
        "(example-robot-data robots have theirs)",
    )
    if task:
        b.add_argument(
            "--task",
            dest="model_task",
            default=None,
            choices=("position", "pose", "pointing"),
            help="with --robot FILE.urdf or erd:NAME: what the hand's x is: its position (default), its "
            "pose (position and orientation) or position and the direction of --pointing-axis "
            "(docs/TASKS.md)",
        )
        b.add_argument(
            "--pointing-axis",
            default=None,
            help="with --task pointing: the frame's axis, x, y, z, -z (default z)",
        )


def is_model_spec(spec: str) -> bool:
    """Whether ``--robot`` names a URDF file or an example-robot-data robot (``erd:NAME``)."""
    return spec.lower().endswith(".urdf") or spec.startswith("erd:")


def model_robot(args: argparse.Namespace, targets: Any = None) -> Any:
    """--robot FILE.urdf or erd:NAME (with --frame, --joints, --home, --axes, --srdf) as a KinematicTarget.

    None when ``--robot`` names no model. What the options leave out is chosen by measurement
    (:mod:`gb_pin.robot.onboarding`; :func:`onboarding_lines` says what); ``targets`` (the points of
    ``--targets``) are the robot's goal set, so that no goal grid nor radius is chosen.

    Raises:
        InvalidArgumentError: --frame missing, or model options given with a preset or MODULE:NAME.
    """
    if args.robot is None and args.frame is None:
        return None
    spec = str(args.robot)
    options = {"--frame": args.frame, "--joints": args.joints, "--home": args.home, "--axes": args.axes}
    options["--srdf"] = getattr(args, "srdf", None)
    options["--task"] = getattr(args, "model_task", None)
    options["--pointing-axis"] = getattr(args, "pointing_axis", None)
    given = [name for name, value in options.items() if value is not None]
    if not is_model_spec(spec):
        if given:
            raise InvalidArgumentError(
                f"{', '.join(given)}: only with --robot FILE.urdf or erd:NAME, not with --robot {spec!r}"
            )
        return None
    if not args.frame:
        raise InvalidArgumentError(
            f"--robot {spec} needs --frame, the effector frame (e.g. --frame tool){_frame_hint(spec)}"
        )
    from gb_pin.robot.target import KinematicTarget

    joints = comma_list(args.joints) if args.joints else None
    home: Any = None
    if args.home:
        try:
            home = [float(v) for v in comma_list(args.home)]
        except ValueError:
            home = args.home.strip()  # a named posture (SRDF / example-robot-data)
    common: dict[str, Any] = {"home": home, "axes": args.axes, "targets": targets}
    if options["--pointing-axis"] is not None and options["--task"] != "pointing":
        raise InvalidArgumentError("--pointing-axis goes with --task pointing")
    if options["--task"] not in (None, "position"):
        common["task"] = options["--task"]
        common["pointing_axis"] = options["--pointing-axis"]
    if spec.startswith("erd:"):
        if options["--srdf"] is not None:
            raise InvalidArgumentError(f"--srdf: only with --robot FILE.urdf; {spec} brings its own SRDF")
        return KinematicTarget.from_example_robot_data(spec[4:], args.frame, joints, **common)
    return KinematicTarget.from_urdf(spec, args.frame, joints, srdf=options["--srdf"], **common)


def _frame_hint(spec: str) -> str:
    """``; its links, chain ends first: a, b, ...`` for a model that loads, else ``""``."""
    try:
        import pinocchio as pin

        from gb_pin.robot.models import load_example_robot, load_urdf_model

        model = load_example_robot(spec[4:])[0] if spec.startswith("erd:") else load_urdf_model(spec)
    except Exception:  # the error about the model itself comes with --frame
        return ""
    parents = {int(model.parents[j]) for j in range(1, model.njoints)}
    bodies = [f for f in model.frames if f.type == pin.FrameType.BODY and int(f.parentJoint) > 0]
    names = [f.name for f in bodies if int(f.parentJoint) not in parents] + [f.name for f in bodies]
    names = list(dict.fromkeys(names))
    more = f", ... ({len(names)} in all)" if len(names) > 20 else ""
    return f"; its links, the ends of its chains first: {', '.join(names[:20])}{more}" if names else ""


def robot_argument(args: argparse.Namespace, default: str | None = None, targets: Any = None) -> Any:
    """The robot ``--robot`` and the model options name: a preset's name, a model or a loaded MODULE:NAME.

    A preset stays a name (its learner defaults come with it); a URDF or erd:NAME model is built
    (:func:`model_robot`, with ``targets`` if given); a MODULE:NAME is imported (:mod:`gb_pin.robot.spec`).

    Raises:
        InvalidArgumentError, UnknownRobotError: bad model options, an unknown preset or spec.
    """
    if args.robot is None and default is not None and args.frame is None:
        args.robot = default
    robot = model_robot(args, targets)
    if robot is not None or args.robot is None:
        return robot
    from gb_pin.robot.spec import is_robot_spec, load_robot_spec

    if is_robot_spec(args.robot):
        return load_robot_spec(args.robot)
    from gb_pin.robot.presets import get_preset

    get_preset(args.robot)  # an unknown preset is reported here, with the closest names
    return args.robot


def robot_list(args: argparse.Namespace, names: list[str]) -> list[Any]:
    """Each of ``names`` as :func:`robot_argument` resolves it (the model options apply to URDF / erd ones).

    Raises:
        InvalidArgumentError, UnknownRobotError: bad model options, an unknown preset or spec.
    """
    out = []
    for name in names:
        one = argparse.Namespace(**vars(args))
        one.robot = name
        if not is_model_spec(name):  # the model options are for the URDF / erd:NAME entries
            for key in ("frame", "joints", "home", "axes", "srdf"):
                setattr(one, key, None)
        out.append(robot_argument(one))
    return out


def result_robot(args: argparse.Namespace) -> Any:
    """The robot ``--robot`` (and the model options) name for a result file, or None: the file's own.

    ``show``, ``replay``, ``plot`` and ``ik`` rebuild the robot the file records (a preset, a URDF or an
    example-robot-data model); ``--robot`` overrides it, e.g. ``MODULE:NAME``, which a file alone
    never imports (importing runs the module's code).

    Raises:
        InvalidArgumentError, UnknownRobotError: bad model options, an unknown preset or spec.
    """
    robot = robot_argument(args)
    if isinstance(robot, str):
        from gb_pin.robot.presets import load_robot

        return load_robot(robot)
    return robot


def onboarding_lines(robot: Any) -> list[str]:
    """What onboarding chose for ``robot`` (:mod:`gb_pin.robot.onboarding`), as the summary's lines."""
    record = getattr(robot, "onboarding", None)
    if record is None:
        return []
    targets = 0 if robot.targets is None else len(robot.targets)
    lines = record.lines(robot.joints, robot.home, targets)
    given = {"joints": "--joints", "home": "--home", "targets": "--targets", "radius": "--radius"}
    given["sigma"] = "--sigma"
    options = ", ".join(given[c] for c in record.chosen)
    head = f"chosen           by measurement (give {options} to choose yourself):"
    if "targets" in record.chosen:
        from gb_pin.robot.workspace import WorkspaceRegion, extent

        try:
            L = extent(WorkspaceRegion().final_goals(robot))
            lines.append(
                "or        --targets workspace:fraction=0.5: the hand positions of half of every joint's "
                f"range ({L:.2f} m across) instead of this grid (docs/WORKSPACE.md)"
            )
        except GbPinError:  # a model whose region cannot be drawn: the grid alone
            pass
    return [head, *(f"  {line}" for line in lines)]
