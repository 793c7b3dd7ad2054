"""The Pinocchio side of a target: its models and data, built when first asked for.

:class:`~gb_pin.robot.target.KinematicTarget` keeps its reduced model, full model and
operational frame here. A target read from a ``pin.Model`` has them from the start; one whose
learner arrays were written directly (the planar chains, :func:`gb_pin.robot.planar.planar_target`)
builds them from its ``model_source`` on first use, so that a run that never asks for them
never imports pinocchio.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from gb_pin.robot.reduction import find_frame

if TYPE_CHECKING:
    import pinocchio as pin


class PinocchioModels:
    """The reduced model, the full model, the frame id and the data of a target, built lazily."""

    name: str
    frame: str
    _model: pin.Model | None
    _full_model: pin.Model | None
    _frame_id: int | None
    _data: pin.Data | None
    _model_source: Callable[[], pin.Model] | None

    @property
    def model(self) -> pin.Model:
        """The reduced Pinocchio model: the joints the learner moves, the others locked at the reference."""
        if self._model is None:
            self._build_model()
        assert self._model is not None
        return self._model

    @property
    def full_model(self) -> pin.Model:
        """The full Pinocchio model (every joint; a viewer displays it)."""
        if self._full_model is None:
            self._build_model()
        assert self._full_model is not None
        return self._full_model

    @property
    def frame_id(self) -> int:
        """The operational frame's id in :attr:`model`."""
        if self._frame_id is None:
            self._build_model()
        assert self._frame_id is not None
        return self._frame_id

    def _build_model(self) -> None:
        """Build the models of a target made from arrays: the full one by ``_model_source``, none locked."""
        import pinocchio as pin

        assert self._model_source is not None
        full = self._model_source()
        self._full_model = full
        self._model = pin.Model(full)
        self._frame_id = find_frame(self._model, self.frame, self.name)

    @property
    def data(self) -> pin.Data:
        """The Pinocchio data of the reduced model, created on first use.

        ``pin.Model.createData`` costs O(nv^3) time and memory (4 s at 300 joints, gigabytes at
        2000), and the learner never needs it: it runs on the chain's arrays.
        """
        if self._data is None:
            self._data = self.model.createData()
        return self._data
