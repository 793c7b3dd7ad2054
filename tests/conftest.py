"""The test session's setup: MUJOCO_GL=egl without a display, before any test module imports MuJoCo.

MuJoCo chooses its GL backend once, at its import; gb_pin sets it when it imports MuJoCo itself
(:mod:`gb_pin.sim.gl`), but a test module may import MuJoCo first.
"""

from gb_pin.sim.gl import configure

configure()
