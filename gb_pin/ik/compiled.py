"""How the IK's kernels are compiled: numba's ``njit`` options shared by geometry, solver, search and clock.

``NO_REFCOUNT`` compiles a kernel without numba's reference counting of arrays (``_nrt=False``).
The IK's kernels allocate nothing (their buffers come from Python), and with counting every
array read from the robot and work structures was counted in and out at each use: an
evaluation of the Panda's pose errors and Jacobian took 1.5 us with it and 0.3 us without (min
of 15 runs of 2 x 10^4 evaluations on the 2-core development machine). A kernel compiled so
cannot allocate (numba refuses to compile one that does), which keeps the hot loop honest.
"""

from __future__ import annotations

from gb_pin._jit import NO_REFCOUNT

__all__ = ["NO_REFCOUNT"]
