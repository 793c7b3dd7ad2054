"""Loading Pinocchio models from URDF files and from the example-robot-data package.

``example-robot-data`` 6.x ships its robots (URDF, SRDF, meshes) under
``<prefix>/share/example-robot-data/robots`` but no Python loader (the separate
``example-robot-data-loaders`` pins an old version), so gb_pin keeps its own small
registry here: one :class:`RobotDescription` per robot name, in the spirit of
``robot_descriptions`` (robots are data; a test loads every entry).

Only the kinematic model is built (``pinocchio.buildModelFromUrdf``): the learner
needs no geometry, and humanoid meshes are large. :func:`build_visual_model` builds
the visual geometry on demand, for viewers.
"""

from __future__ import annotations

import contextlib
import importlib.metadata
import os
import re
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin

from gb_pin._names import closest
from gb_pin._reading import open_regular, read_bytes
from gb_pin.exceptions import GbPinError, InvalidArgumentError, UnknownRobotError
from gb_pin.robot.description_checks import SrdfStates, check_limits, check_reference_states

_SHARE = ("share", "example-robot-data", "robots")


@dataclass(frozen=True)
class RobotDescription:
    """One robot of example-robot-data.

    Attributes:
        name: the registry name (as example-robot-data's own loaders name it).
        urdf: URDF file, relative to the example-robot-data ``robots`` directory.
        srdf: SRDF file with reference configurations (e.g. ``half_sitting``), or None.
        floating_base: whether the robot is mobile: a free-flyer root joint is added,
            as example-robot-data's loaders do (its reference configurations include it).
        description: one line for listings.
    """

    name: str
    urdf: str
    srdf: str | None
    floating_base: bool
    description: str


def _d(name: str, urdf: str, srdf: str | None, floating: bool, text: str) -> RobotDescription:
    return RobotDescription(name, urdf, srdf, floating, text)


_TALOS_SRDF = "talos_data/srdf/talos.srdf"
_UR = "ur_description/urdf/"
DESCRIPTIONS: dict[str, RobotDescription] = {
    d.name: d
    for d in (
        # Humanoids (mobile: a free-flyer root joint; lock it by naming the joints you move).
        _d(
            "talos",
            "talos_data/robots/talos_reduced.urdf",
            _TALOS_SRDF,
            True,
            "TALOS humanoid (PAL Robotics)",
        ),
        _d(
            "talos_full",
            "talos_data/robots/talos_full_v2.urdf",
            _TALOS_SRDF,
            True,
            "TALOS with gripper joints",
        ),
        _d(
            "talos_arm",
            "talos_data/robots/talos_left_arm.urdf",
            None,
            False,
            "TALOS left arm alone (no arm_left_1)",
        ),
        _d(
            "romeo",
            "romeo_description/urdf/romeo.urdf",
            "romeo_description/srdf/romeo.srdf",
            True,
            "Romeo humanoid",
        ),
        _d(
            "icub",
            "icub_description/robots/icub.urdf",
            "icub_description/srdf/icub.srdf",
            True,
            "iCub humanoid",
        ),
        _d(
            "icub_reduced",
            "icub_description/robots/icub_reduced.urdf",
            "icub_description/srdf/icub.srdf",
            True,
            "iCub humanoid, reduced",
        ),
        _d("g1", "g1_description/urdf/g1_29dof_rev_1_0.urdf", None, True, "Unitree G1 humanoid, 29 joints"),
        _d(
            "g1_with_hands",
            "g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf",
            None,
            True,
            "Unitree G1 humanoid with hands",
        ),
        _d(
            "simple_humanoid",
            "simple_humanoid_description/urdf/simple_humanoid.urdf",
            "simple_humanoid_description/srdf/simple_humanoid.srdf",
            True,
            "simple humanoid (HRP-2 like)",
        ),
        _d(
            "alex",
            "alex_description/urdf/alex_nub_hands.urdf",
            "alex_description/srdf/alex_nub_hands.srdf",
            False,
            "Alex upper-body humanoid (IHMC), nub hands",
        ),
        _d("human", "human_description/robots/human.urdf", None, True, "human body model"),
        # Fixed-base arms and manipulators.
        _d("ur3", _UR + "ur3_robot.urdf", None, False, "UR3 arm (Universal Robots)"),
        _d("ur3_limited", _UR + "ur3_joint_limited_robot.urdf", None, False, "UR3, joint limits +-pi"),
        _d("ur5", _UR + "ur5_robot.urdf", None, False, "UR5 arm (Universal Robots)"),
        _d("ur5_limited", _UR + "ur5_joint_limited_robot.urdf", None, False, "UR5, joint limits +-pi"),
        _d("ur5_gripper", _UR + "ur5_gripper.urdf", None, False, "UR5 with a gripper"),
        _d("ur10", _UR + "ur10_robot.urdf", None, False, "UR10 arm (Universal Robots)"),
        _d("ur10_limited", _UR + "ur10_joint_limited_robot.urdf", None, False, "UR10, joint limits +-pi"),
        _d(
            "panda",
            "panda_description/urdf/panda.urdf",
            "panda_description/srdf/panda.srdf",
            False,
            "Franka Emika Panda arm",
        ),
        _d(
            "kinova",
            "kinova_description/robots/kinova.urdf",
            "kinova_description/srdf/kinova.srdf",
            False,
            "Kinova arm",
        ),
        _d("z1", "z1_description/urdf/z1.urdf", "z1_description/srdf/z1.srdf", False, "Unitree Z1 arm"),
        _d("xarm7", "xarm_description/urdf/xarm7.urdf", None, False, "UFactory xArm7"),
        _d("so100", "so_arm_description/urdf/so100.urdf", None, False, "SO-100 arm"),
        _d("so101", "so_arm_description/urdf/so101.urdf", None, False, "SO-101 arm"),
        _d("baxter", "baxter_description/urdf/baxter.urdf", None, False, "Baxter two-arm robot (Rethink)"),
        _d("tiago", "tiago_description/robots/tiago.urdf", None, False, "TIAGo mobile manipulator (PAL)"),
        _d("tiago_dual", "tiago_description/robots/tiago_dual.urdf", None, False, "TIAGo with two arms"),
        _d("tiago_no_hand", "tiago_description/robots/tiago_no_hand.urdf", None, False, "TIAGo, no hand"),
        _d("pr2", "pr2_description/urdf/pr2.urdf", None, False, "PR2 (Willow Garage)"),
        _d(
            "finger_edu",
            "finger_edu_description/robots/finger_edu.urdf",
            "finger_edu_description/srdf/finger_edu.srdf",
            False,
            "TriFinger-edu finger",
        ),
        _d(
            "double_pendulum",
            "double_pendulum_description/urdf/double_pendulum.urdf",
            None,
            False,
            "double pendulum",
        ),
        _d(
            "double_pendulum_continuous",
            "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
            None,
            False,
            "double pendulum, continuous joints",
        ),
        _d("asr_twodof", "asr_twodof_description/urdf/TwoDofs.urdf", None, False, "two-joint planar arm"),
        # Legged robots (mobile).
        _d("a1", "a1_description/urdf/a1.urdf", "a1_description/srdf/a1.srdf", True, "Unitree A1 quadruped"),
        _d("go1", "go1_description/urdf/go1.urdf", "go1_description/srdf/go1.srdf", True, "Unitree Go1"),
        _d("go2", "go2_description/urdf/go2.urdf", "go2_description/srdf/go2.srdf", True, "Unitree Go2"),
        _d("b1", "b1_description/urdf/b1.urdf", "b1_description/srdf/b1.srdf", True, "Unitree B1 quadruped"),
        _d(
            "anymal",
            "anymal_b_simple_description/robots/anymal.urdf",
            "anymal_b_simple_description/srdf/anymal.srdf",
            True,
            "ANYmal B quadruped",
        ),
        _d(
            "anymal_kinova",
            "anymal_b_simple_description/robots/anymal-kinova.urdf",
            "anymal_b_simple_description/srdf/anymal-kinova.srdf",
            True,
            "ANYmal B with a Kinova arm",
        ),
        _d("hyq", "hyq_description/robots/hyq_no_sensors.urdf", "hyq_description/srdf/hyq.srdf", True, "HyQ"),
        _d(
            "solo12",
            "solo_description/robots/solo12.urdf",
            "solo_description/srdf/solo.srdf",
            True,
            "Solo-12",
        ),
        _d(
            "bolt", "bolt_description/robots/bolt.urdf", "bolt_description/srdf/bolt.srdf", True, "Bolt biped"
        ),
    )
}


def example_robot_data_dir() -> Path:
    """The ``robots`` directory of the installed example-robot-data package.

    Raises:
        GbPinError: example-robot-data is not installed (``pip install example-robot-data``).
    """
    candidates: list[Path] = []
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        dist = None
    if dist is not None:
        for f in dist.files or ():
            parts = Path(str(f)).parts
            for i in range(len(parts) - 2):
                if parts[i : i + 3] == _SHARE:
                    candidates.append(Path(str(dist.locate_file(Path(*parts[: i + 3])))))
                    break
            if candidates:
                break
    # cmeel installs into <site-packages>/cmeel.prefix; a system install into <prefix>/share.
    for base in (*sys.path, sys.prefix):
        candidates.append(Path(base, "cmeel.prefix", *_SHARE))
    candidates.append(Path(sys.prefix, *_SHARE))
    for path in candidates:
        if path.is_dir():
            return path
    raise GbPinError(
        "example-robot-data is not installed (no share/example-robot-data/robots directory found); "
        "install it with `pip install example-robot-data`"
    )


def describe(name: str) -> RobotDescription:
    """The registry entry of an example-robot-data robot.

    Raises:
        UnknownRobotError: unknown name (the message lists the closest names).
    """
    if isinstance(name, str) and name in DESCRIPTIONS:
        return DESCRIPTIONS[name]
    valid = sorted(DESCRIPTIONS)
    close = closest(name, valid)
    hint = f"closest: {', '.join(close)}; " if close else ""
    raise UnknownRobotError(f"unknown example-robot-data robot {name!r}; {hint}valid: {', '.join(valid)}")


MAX_URDF_BYTES = 64 * 2**20
"""The largest URDF file read (example-robot-data's largest is under 1 MiB)."""
MAX_URDF_ELEMENTS = 1000
"""The most ``<link>`` and the most ``<joint>`` elements a URDF may have (pinocchio's parser
recurses along the tree and crashes the interpreter on chains of a few thousand links)."""


def check_urdf_size(urdf: Path) -> bytes:
    """Read a URDF file in bounds, refusing one too big for pinocchio's parser; return its bytes.

    Raises:
        InvalidArgumentError: missing, not a regular file, over :data:`MAX_URDF_BYTES` bytes, or
            over :data:`MAX_URDF_ELEMENTS` links or joints.
    """
    text = read_bytes(urdf, f"URDF file {str(urdf)!r}", "URDF file", MAX_URDF_BYTES, InvalidArgumentError)
    for tag in (b"link", b"joint"):
        count = len(re.findall(rb"<\s*" + tag + rb"[\s/>]", text))
        if count > MAX_URDF_ELEMENTS:
            raise InvalidArgumentError(
                f"URDF file {str(urdf)!r} has {count} <{tag.decode()}> elements; gb_pin reads at most "
                f"{MAX_URDF_ELEMENTS} (gb_pin.robot.models.MAX_URDF_ELEMENTS)"
            )
    return text


def load_urdf_model(
    path: str | os.PathLike[str],
    *,
    srdf: str | os.PathLike[str] | None = None,
    floating_base: bool = False,
) -> pin.Model:
    """Build the kinematic model of a URDF file (no geometry), with the SRDF's reference configurations.

    See :func:`load_urdf_states`, which also says what the SRDF's states set.
    """
    return load_urdf_states(path, srdf=srdf, floating_base=floating_base)[0]


def load_urdf_states(
    path: str | os.PathLike[str],
    *,
    srdf: str | os.PathLike[str] | None = None,
    floating_base: bool = False,
) -> tuple[pin.Model, SrdfStates | None]:
    """A URDF file's kinematic model (no geometry) with the SRDF's states, and what the states set.

    The second is None without an SRDF (see
    :func:`~gb_pin.robot.description_checks.check_used_states`).

    The files are read once, in bounds (regular files only, :func:`check_urdf_size`), and
    pinocchio parses the text read (the same model as from the path, tested).

    Args:
        path: the URDF file.
        srdf: an SRDF file whose ``group_state`` entries become the model's
            reference configurations (e.g. ``half_sitting``).
        floating_base: add a free-flyer root joint (for mobile robots).

    Raises:
        InvalidArgumentError: missing, malformed, not a regular file or too large
            (:func:`check_urdf_size`) URDF or SRDF; a joint whose lower limit exceeds its upper;
            an SRDF state holding a non-number. (A state naming a joint the URDF lacks is refused
            only where a target uses it and needs a joint it leaves unset: ``check_used_states``.)
    """
    urdf = Path(os.fspath(path))
    if not urdf.exists():
        raise InvalidArgumentError(f"URDF file {str(urdf)!r} does not exist")
    text = _xml_text(check_urdf_size(urdf))
    try:
        root = [pin.JointModelFreeFlyer()] if floating_base else []
        with captured_stderr() as said:  # urdfdom prints its errors from C++, before ours
            model = pin.buildModelFromXML(text, *root)
    except (ValueError, RuntimeError, IndexError) as exc:
        detail = f"{str(exc)[:300]}" + (f" (urdfdom: {said[0][:300]})" if said and said[0] else "")
        raise InvalidArgumentError(f"malformed URDF file {str(urdf)!r}: {detail}") from exc
    if model.njoints <= 1:
        raise InvalidArgumentError(f"URDF file {str(urdf)!r} describes no joint: nothing to move")
    check_limits(model, f"URDF file {str(urdf)!r}")
    states = None
    if srdf is not None:
        srdf_path = Path(os.fspath(srdf))
        if not srdf_path.exists():
            raise InvalidArgumentError(f"SRDF file {str(srdf_path)!r} does not exist")
        label = f"SRDF file {str(srdf_path)!r}"
        xml = _xml_text(read_bytes(srdf_path, label, "SRDF file", MAX_URDF_BYTES, InvalidArgumentError))
        try:
            pin.loadReferenceConfigurationsFromXML(model, xml, False)
        except (ValueError, RuntimeError, IndexError) as exc:
            raise InvalidArgumentError(f"malformed SRDF file {str(srdf_path)!r}: {str(exc)[:300]}") from exc
        states = check_reference_states(model, xml, label, text)
    return model, states


@contextlib.contextmanager
def captured_stderr() -> Iterator[list[str]]:
    """Capture what C++ code writes to file descriptor 2 meanwhile (urdfdom's parse errors).

    Yields a list that holds the text, stripped and on one line, once the block ends; a failure of the
    capture itself (no fd 2, e.g. under some embedders) leaves stderr alone.
    """
    said: list[str] = []
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError, AttributeError):
        yield said
        return
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield said
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            text = sink.read(64 * 1024).decode("utf-8", "replace")
            said.append(" ".join(text.split()))


def _xml_text(data: bytes) -> str:
    """An XML file's bytes as text: UTF-8, else Latin-1 (every byte a character).

    Pinocchio reads the text it is given; a file that is not UTF-8 (a Latin-1 URDF, or a corrupted
    one) read by pinocchio itself gave names that Python could not decode (UnicodeDecodeError at
    the first ``model.names``).
    """
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def load_example_robot(name: str) -> tuple[pin.Model, RobotDescription, Path]:
    """The kinematic model of an example-robot-data robot, its registry entry and its URDF path."""
    return load_example_robot_states(name)[:3]


def load_example_robot_states(name: str) -> tuple[pin.Model, RobotDescription, Path, SrdfStates | None]:
    """:func:`load_example_robot`, and what its SRDF's states set (:func:`load_urdf_states`)."""
    entry = describe(name)
    root = example_robot_data_dir()
    srdf = None if entry.srdf is None else root / entry.srdf
    model, states = load_urdf_states(root / entry.urdf, srdf=srdf, floating_base=entry.floating_base)
    return model, entry, root / entry.urdf, states


def package_dirs_for(urdf: str | os.PathLike[str]) -> list[str]:
    """Directories where ``package://`` mesh paths of an example-robot-data URDF resolve."""
    parent = Path(os.fspath(urdf)).resolve().parent
    dirs = [str(p) for p in (parent, parent.parent, parent.parent.parent)]
    try:
        root = example_robot_data_dir()
    except GbPinError:
        return dirs
    # example-robot-data's URDFs say package://example-robot-data/robots/...: the package
    # directory is <prefix>/share.
    return [str(root.parent.parent), str(root.parent), str(root), *dirs]


def build_visual_model(
    model: pin.Model, urdf: str | os.PathLike[str], package_dirs: list[str] | None = None
) -> pin.GeometryModel:
    """The visual geometry (meshes) of a URDF for ``model``, built on demand (for viewers).

    Args:
        model: the full model built from the same URDF (see :func:`load_urdf_model`).
        urdf: the URDF file.
        package_dirs: where ``package://`` paths resolve; default next to the URDF
            and the example-robot-data directory.

    Raises:
        GbPinError: the meshes cannot be loaded.
    """
    dirs = package_dirs_for(urdf) if package_dirs is None else list(package_dirs)
    check_meshes(Path(os.fspath(urdf)), dirs)
    try:
        return pin.buildGeomFromUrdf(model, os.fspath(urdf), pin.GeometryType.VISUAL, package_dirs=dirs)
    except (ValueError, RuntimeError, IndexError) as exc:
        raise GbPinError(f"cannot load the visual meshes of {os.fspath(urdf)!r}: {exc}") from exc


MAX_MESH_BYTES = 256 * 2**20
"""The largest mesh file a URDF may name (example-robot-data's largest is a few MiB)."""


def check_meshes(urdf: Path, package_dirs: list[str]) -> None:
    """Refuse mesh files that pinocchio's loader would block on or exhaust memory with, before it runs.

    Every ``<mesh filename=...>`` of the URDF that resolves to an existing path (``package://``
    through ``package_dirs``, ``file://``, absolute, or relative to the URDF) must be a regular file
    of at most :data:`MAX_MESH_BYTES`: a FIFO would block the viewer, ``/dev/zero`` never end.

    Raises:
        GbPinError: naming the mesh and what it is.
    """
    text = check_urdf_size(urdf)
    for raw in re.findall(rb"<\s*mesh\b[^>]*?\bfilename\s*=\s*[\"']([^\"']*)[\"']", text):
        name = raw.decode("utf-8", "replace")
        if name.startswith("package://"):
            rest = name[len("package://") :]
            candidates = [Path(d) / rest for d in package_dirs]
        else:
            path = Path(name.removeprefix("file://"))
            candidates = [path if path.is_absolute() else urdf.parent / path]
        for candidate in candidates:
            if os.path.lexists(candidate):
                read_check = open_regular(candidate, f"mesh {name[:200]!r} of {str(urdf)!r}", "mesh file",
                                          MAX_MESH_BYTES, GbPinError)[0]  # fmt: skip
                read_check.close()
                break
