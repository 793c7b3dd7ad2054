"""The plant's camera: renders the simulated arm as a webcam would see it, with pixel noise.

:class:`PlantCamera` renders the plant's current state through MuJoCo's offscreen renderer
(:mod:`gb_pin.sim.gl`: EGL without a display) from the scene's camera
(:mod:`gb_pin.sim.scene`), and :meth:`PlantCamera.read` adds Gaussian pixel noise (3 grey levels
by default; a webcam's) drawn from its own seeded generator, so pictures are reproducible.
:meth:`intrinsics` are the rendering's exact pinhole parameters (OpenCV's convention: pixel
centres at integers, so the principal point is at (W - 1) / 2, (H - 1) / 2).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.sim.gl import renderer
from gb_pin.sim.scene import Scene


class PlantCamera:
    """Renders a MuJoCo model's state from its ``view`` camera.

    Args:
        mujoco: the mujoco module.
        model: the MjModel (with the scene).
        scene: the :class:`~gb_pin.sim.scene.Scene` it was built with.
        pixel_noise: standard deviation of the noise added by :meth:`read` [grey levels of 255].
        seed: the noise's seed.

    Raises:
        CameraError: no GL backend (one line).
    """

    def __init__(self, mujoco: Any, model: Any, scene: Scene, pixel_noise: float, seed: int) -> None:
        self._mj = mujoco
        self.scene = scene
        self.pose = scene.camera
        self.pixel_noise = float(pixel_noise)
        self.seed = seed
        self.rng = np.random.default_rng([seed, 0x63616D])  # apart from the sensor's stream
        self._renderer = renderer(mujoco, model, self.pose.width, self.pose.height)
        self._camera = model.camera("view").id
        self.frames = 0

    def render(self, data: Any) -> NDArray[np.uint8]:
        """The picture (H, W, 3) uint8 RGB of the state ``data``, without noise."""
        self._renderer.update_scene(data, camera=self._camera)
        return np.asarray(self._renderer.render())

    def read(self, data: Any) -> NDArray[np.uint8]:
        """A webcam's picture (H, W, 3) uint8 in OpenCV's BGR order, with pixel noise."""
        rgb = self.render(data)
        self.frames += 1
        bgr = rgb[:, :, ::-1]
        if self.pixel_noise <= 0:
            return np.ascontiguousarray(bgr)
        # in place, the same float32 operations in the same order as bgr + s * noise (no temporaries)
        noisy = self.rng.standard_normal(bgr.shape, dtype=np.float32)
        noisy *= np.float32(self.pixel_noise)
        noisy += bgr
        np.rint(noisy, out=noisy)
        np.clip(noisy, 0, 255, out=noisy)
        return noisy.astype(np.uint8)

    def intrinsics(self) -> Any:
        """The rendering's exact :class:`~gb_pin.vision.intrinsics.Intrinsics` (no distortion)."""
        from gb_pin.vision.intrinsics import Intrinsics

        f = self.pose.focal
        w, h = self.pose.width, self.pose.height
        return Intrinsics(f, f, (w - 1) / 2.0, (h - 1) / 2.0, w, h)

    def close(self) -> None:
        """Free the GL context."""
        self._renderer.close()
