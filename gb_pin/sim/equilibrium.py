"""Where a simulated arm comes to rest under a command: the static equilibrium of its servos.

At rest (no speed, no acceleration) each servo's torque kp (q_cmd - q) balances the gravity
torque tau_g(q) of the links it carries (MuJoCo's bias force at zero speed), so the resting
posture solves

    q = q_cmd - tau_g(q) / kp,

which :func:`static_posture` iterates from q_cmd: a contraction while the servos are stiffer
than the gravity torque's change with the posture (every servo that holds its arm up), to
1e-12 rad in 5-15 iterations on the SO-101. Where it is not (a servo too soft, or a force limit
that cannot hold the arm), the arm is simulated from rest at q_cmd until it stops instead.

This is the "true" body of a simulated plant: the reach errors and E^X of docs/SIMULATION.md are
measured at these postures (no sensor noise, no lag).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.sim import health
from gb_pin.sim.servos import Servos
from gb_pin.sim.settling import Settling

TOLERANCE = 1e-12
"""Largest change of the iterate at convergence [rad]."""
ITERATIONS = 200
"""Iterations before the arm is simulated instead."""
REST = Settling(time=20.0, tolerance=1e-7)
"""The simulated fallback: until at rest to 1e-7 rad/s, at most 20 s."""


def static_posture(
    mujoco: Any,
    model: Any,
    data: Any,
    dofs: NDArray[np.int64],
    command: NDArray[np.float64],
    servos: Servos,
    budget: health.StepBudget | None = None,
) -> NDArray[np.float64]:
    """The posture (m,) at which the arm rests under ``command`` (m,), in the order of q.

    Args:
        mujoco: the mujoco module.
        model: the plant's ``MjModel``.
        data: an ``MjData`` of ``model`` used as scratch (its state is overwritten).
        dofs: (m,) the qpos (= dof) address of each entry of q.
        command: the commanded posture q_cmd.
        servos: the servos (kp, force limits).
        budget: the MuJoCo steps the simulated fallback may take (None: one evaluation's own).

    Raises:
        SimulationError: the simulated fallback went unstable or ran beyond its budget.
    """
    q = command.copy()
    data.qvel[:] = 0.0
    tau = np.empty(model.nv)
    for _ in range(ITERATIONS):
        data.qpos[dofs] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_rne(model, data, 0, tau)  # the bias force at zero speed: gravity
        new = command - tau[dofs] / servos.kp
        change = np.abs(new - q).max()
        q = new
        if change <= TOLERANCE:
            if np.all(np.abs(servos.kp * (command - q)) <= servos.force_limit):
                return q
            break  # the servos cannot give that torque: the arm sinks further
        if not change < np.inf:  # diverged (inf or NaN)
            break
    return _simulated(mujoco, model, data, dofs, command, budget or health.StepBudget(servos.describe()))


def _simulated(
    mujoco: Any,
    model: Any,
    data: Any,
    dofs: NDArray[np.int64],
    command: NDArray[np.float64],
    budget: health.StepBudget,
) -> NDArray[np.float64]:
    """The posture after holding ``command`` from rest at it until the arm stops (or 20 s, or the budget)."""
    mujoco.mj_resetData(model, data)
    data.qpos[dofs] = command
    data.ctrl[:] = command  # actuator a drives entry a of q
    mujoco.mj_forward(model, data)
    most = REST.steps(float(model.opt.timestep))[0]
    steps = REST.hold(mujoco, model, data, limit=budget.left)
    health.check_state(mujoco, data, 0, budget.settings, "the simulated resting posture")
    at_rest = steps < most and steps < budget.left
    budget.spend(steps, at_rest or steps >= most)
    return np.array(data.qpos[dofs])
