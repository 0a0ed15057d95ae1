"""Headless camera rendering: which OpenGL MuJoCo uses, and the pinhole intrinsics.

MuJoCo renders offscreen through EGL (a GPU's driver where one is installed,
else Mesa's software EGL) or OSMesa (software only). ``choose_gl_backend``
keeps a ``MUJOCO_GL`` the user set, and otherwise picks EGL when its library
loads, OSMesa when that loads: ``make setup`` installs both (``make render``).
It must run before ``mujoco`` creates its first rendering context.
"""

from __future__ import annotations

import ctypes.util
import math
import os

import numpy as np


def choose_gl_backend(environ: dict[str, str] | None = None) -> str:
    """Set MUJOCO_GL (egl, osmesa) unless already set; return the backend in use."""
    env = os.environ if environ is None else environ
    if env.get("MUJOCO_GL"):
        return env["MUJOCO_GL"]
    for backend, library in (("egl", "EGL"), ("osmesa", "OSMesa")):
        if ctypes.util.find_library(library):
            env["MUJOCO_GL"] = backend
            if backend == "egl":
                env.setdefault("PYOPENGL_PLATFORM", "egl")
            return backend
    return ""  # nothing found: rendering will fail with MuJoCo's own message


def intrinsics(width: int, height: int, fovy_deg: float) -> np.ndarray:
    """3x3 camera matrix K of a MuJoCo camera (square pixels, vertical field of view)."""
    focal = (height / 2.0) / math.tan(math.radians(fovy_deg) / 2.0)
    return np.array([[focal, 0.0, width / 2.0], [0.0, focal, height / 2.0], [0.0, 0.0, 1.0]])


class SnapshotCamera:
    """Renders a MuJoCo camera from copies of the physics state, off the physics thread.

    Make it in the thread that renders (an OpenGL context belongs to its thread),
    and give it ``qpos`` copies taken under the physics lock: the physics steps on
    while a frame renders.
    """

    def __init__(self, model, camera: str, width: int, height: int) -> None:
        import mujoco

        self._mujoco = mujoco
        self.model = model
        self.camera = camera
        self.data = mujoco.MjData(model)
        self.renderer = mujoco.Renderer(model, height=height, width=width)
        # Shadows and reflections cost 15x the rest of a frame in software OpenGL
        # (measured: 64 vs 4 ms of CPU a 320x240 frame through Mesa's EGL).
        flags = self.renderer.scene.flags
        for flag in (mujoco.mjtRndFlag.mjRND_SHADOW, mujoco.mjtRndFlag.mjRND_REFLECTION):
            flags[flag] = 0

    def render(self, qpos: np.ndarray) -> np.ndarray:
        """An RGB image (height, width, 3) of the world in the state ``qpos``."""
        self.data.qpos[:] = qpos
        self._mujoco.mj_kinematics(self.model, self.data)
        self._mujoco.mj_camlight(self.model, self.data)
        self.renderer.update_scene(self.data, camera=self.camera)
        return self.renderer.render()

    def close(self) -> None:
        self.renderer.close()
