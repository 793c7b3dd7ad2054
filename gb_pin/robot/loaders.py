"""A target from a file: ``KinematicTarget.from_urdf`` and ``KinematicTarget.from_example_robot_data``.

:class:`ModelLoaders` gives :class:`~gb_pin.robot.target.KinematicTarget` its two constructors from
files. Both onboard by default (``onboard=True``, :mod:`gb_pin.robot.onboarding`): a robot you did not
build gets the joints, home, goal grid and radius you leave out chosen by measurement.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from numpy.typing import ArrayLike

from gb_pin.robot.description_checks import SrdfStates, check_used_states

if TYPE_CHECKING:
    from typing import Self

    from gb_pin.robot.targets_auto import TargetSpec
    from gb_pin.robot.task_spec import TaskSpec


class ModelLoaders:
    """The constructors of a target from a URDF file or an example-robot-data robot."""

    _urdf: str | None
    _package_dirs: list[str] | None
    joints: Sequence[str]

    if TYPE_CHECKING:  # KinematicTarget's constructor

        def __init__(self, model: Any, frame: str, *args: Any, **kwargs: Any) -> None: ...

    @classmethod
    def from_urdf(
        cls,
        path: str | os.PathLike[str],
        frame: str,
        joints: Sequence[str] | None = None,
        home: ArrayLike | str | None = None,
        axes: str | None = None,
        package_dirs: Sequence[str | os.PathLike[str]] | None = None,
        *,
        srdf: str | os.PathLike[str] | None = None,
        floating_base: bool = False,
        targets: TargetSpec = None,
        name: str | None = None,
        task: TaskSpec = None,
        orientation_scale: float | None = None,
        pointing_axis: str | ArrayLike | None = None,
        onboard: bool = True,
    ) -> Self:
        """A target from a URDF file (kinematics only: no mesh is loaded).

        Args:
            path: the URDF file.
            frame: operational frame (a link name or any frame of the model).
            joints: joints the learner moves (see the class); default the joints that move ``frame``
                (``onboard``), else every joint.
            home: home posture over ``joints`` or a reference configuration name; default chosen by
                measurement (``onboard``), else the reference posture.
            axes: task axes, default ``"xyz"``.
            package_dirs: where ``package://`` mesh paths resolve; used only by
                :meth:`visual_model`.
            srdf: SRDF file whose group states become reference configurations
                (e.g. ``half_sitting``).
            floating_base: add a free-flyer root joint (a mobile robot); it is locked at the
                reference posture.
            targets: default target set (see the class); default the onboarding's goal grid.
            name: label; default the file's stem.
            task: what x is (see the class).
            orientation_scale: s [m/rad] of ``"pose"`` and ``"pointing"`` (see the class).
            pointing_axis: the frame axis of ``"pointing"`` (see the class).
            onboard: choose what is not given by measurement (:mod:`gb_pin.robot.onboarding`).

        Raises:
            InvalidArgumentError: missing or malformed URDF/SRDF, or any constructor error.
        """
        from gb_pin.robot.models import load_urdf_states

        model, states = load_urdf_states(path, srdf=srdf, floating_base=floating_base)
        _check_states(model, states, frame, joints, home)  # before onboarding, for the joints given
        target = cls(
            model,
            frame,
            joints,
            home,
            axes,
            targets=targets,
            name=name if name is not None else Path(os.fspath(path)).stem,
            task=task,
            orientation_scale=orientation_scale,
            pointing_axis=pointing_axis,
            onboard=onboard,
        )
        target._urdf = os.fspath(path)
        target._package_dirs = None if package_dirs is None else [os.fspath(p) for p in package_dirs]
        _check_states(model, states, frame, target.joints, home)  # the chain chosen
        return target

    @classmethod
    def from_example_robot_data(
        cls,
        name: str,
        frame: str,
        joints: Sequence[str] | None = None,
        home: ArrayLike | str | None = None,
        axes: str | None = None,
        *,
        targets: TargetSpec = None,
        label: str | None = None,
        task: TaskSpec = None,
        orientation_scale: float | None = None,
        pointing_axis: str | ArrayLike | None = None,
        onboard: bool = True,
    ) -> Self:
        """A target from a robot of the example-robot-data package (e.g. ``"talos"``, ``"panda"``).

        Mobile robots (humanoids, quadrupeds) get a free-flyer root joint, as in
        example-robot-data's own loaders, and their SRDF reference configurations
        (``half_sitting``); the base, and every joint not moved, is locked at the reference posture.

        Args:
            name: the robot's name, see :data:`gb_pin.robot.models.DESCRIPTIONS`.
            frame: operational frame.
            joints: joints the learner moves; default the joints that move ``frame`` (``onboard``).
            home: home posture over ``joints`` or a reference configuration name; default chosen by
                measurement (``onboard``), else the reference posture.
            axes: task axes, default ``"xyz"``.
            targets: default target set (see the class); default the onboarding's goal grid.
            label: the target's name for messages; default ``name``.
            task: what x is (see the class).
            orientation_scale: s [m/rad] of ``"pose"`` and ``"pointing"`` (see the class).
            pointing_axis: the frame axis of ``"pointing"`` (see the class).
            onboard: choose what is not given by measurement (:mod:`gb_pin.robot.onboarding`).

        Raises:
            UnknownRobotError: unknown robot, frame or joint (closest names listed).
            InvalidArgumentError: any other constructor error.
        """
        from gb_pin.robot.models import load_example_robot_states

        model, _, urdf, states = load_example_robot_states(name)
        _check_states(model, states, frame, joints, home)  # before onboarding, for the joints given
        target = cls(
            model,
            frame,
            joints,
            home,
            axes,
            targets=targets,
            name=label if label is not None else name,
            task=task,
            orientation_scale=orientation_scale,
            pointing_axis=pointing_axis,
            onboard=onboard,
        )
        target._urdf = str(urdf)
        _check_states(model, states, frame, target.joints, home)  # the chain chosen
        return target


def _check_states(
    model: Any, states: SrdfStates | None, frame: str, joints: Sequence[str] | None, home: Any
) -> None:
    """Refuse an SRDF state the target uses that names a missing joint and leaves a chain joint unset.

    The states used: the home given by name, and the reference posture (``half_sitting``, or the
    only state), which gives the home where none is given and locks the joints not moved. Joints
    the URDF lacks in states the target does not use, or that leave no joint of the chain unset,
    are ignored (a debug note).
    """
    if states is None or not states.missing or joints is None:
        return
    from gb_pin.robot.postures import reference_name

    used = [home] if isinstance(home, str) else []
    reference = reference_name(model)
    if reference is not None:
        used.append(reference)
    check_used_states(states, used, list(joints), frame)
