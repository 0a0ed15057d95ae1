"""Headless camera rendering: which OpenGL MuJoCo uses, and the pinhole intrinsics.

MuJoCo renders offscreen through EGL (a GPU's driver where one is installed,
else Mesa's software EGL) or OSMesa (software only). ``choose_gl_backend``
keeps a ``MUJOCO_GL`` the user set; otherwise it takes EGL when its library
loads *and* makes an OpenGL context (a container without a render device, or
a broken vendor library, loads libEGL and then fails), else OSMesa when that
loads: ``make setup`` installs both (``make render``). It must run before
``mujoco`` is first imported, which reads ``MUJOCO_GL`` once.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import math
import os
from collections.abc import Callable
from typing import Any

import numpy as np

# EGL constants (Khronos egl.h, EGL_EXT_platform_device)
_EGL_SUCCESS = 0x3000
_EGL_NONE = 0x3038
_EGL_PLATFORM_DEVICE_EXT = 0x313F
_EGL_OPENGL_API = 0x30A2
_EGL_CONFIG = (
    0x3024, 8, 0x3023, 8, 0x3022, 8, 0x3021, 8,  # red, green, blue, alpha sizes
    0x3025, 24, 0x3026, 8,  # depth, stencil sizes
    0x3033, 0x0001,  # surface type: pbuffer
    0x3040, 0x0008,  # renderable type: desktop OpenGL
    _EGL_NONE,
)  # fmt: skip
MAX_DEVICES = 16


def egl_context_works() -> bool:
    """True when EGL makes an OpenGL context on a device, as MuJoCo's EGL backend asks it to.

    Plain ctypes, in this process, before MuJoCo or PyOpenGL are imported:
    each EGL device's display is initialised, a desktop-OpenGL context made
    current without a surface, then everything is released again.
    """
    name = ctypes.util.find_library("EGL")
    if name is None:
        return False
    try:
        egl = ctypes.CDLL(name)
    except OSError:
        return False
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]

    def extension(symbol: bytes, restype: Any, *argtypes: Any) -> Callable[..., Any] | None:
        address = egl.eglGetProcAddress(symbol)
        if not address:
            return None
        return ctypes.CFUNCTYPE(restype, *argtypes)(address)

    query_devices = extension(
        b"eglQueryDevicesEXT",
        ctypes.c_uint,
        ctypes.c_int,
        ctypes.POINTER(ctypes.c_void_p),
        ctypes.POINTER(ctypes.c_int),
    )
    pointer = ctypes.c_void_p
    platform_display = extension(
        b"eglGetPlatformDisplayEXT", pointer, ctypes.c_uint, pointer, pointer
    )
    if query_devices is None or platform_display is None:
        return False
    for fn, restype, argtypes in (
        ("eglInitialize", ctypes.c_uint, [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p]),
        (
            "eglChooseConfig",
            ctypes.c_uint,
            [
                ctypes.c_void_p,
                ctypes.POINTER(ctypes.c_int),
                ctypes.POINTER(ctypes.c_void_p),
                ctypes.c_int,
                ctypes.POINTER(ctypes.c_int),
            ],
        ),  # fmt: skip
        ("eglBindAPI", ctypes.c_uint, [ctypes.c_uint]),
        (
            "eglCreateContext",
            ctypes.c_void_p,
            [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p],
        ),
        (
            "eglMakeCurrent",
            ctypes.c_uint,
            [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p],
        ),
        ("eglDestroyContext", ctypes.c_uint, [ctypes.c_void_p, ctypes.c_void_p]),
        ("eglTerminate", ctypes.c_uint, [ctypes.c_void_p]),
        ("eglGetError", ctypes.c_int, []),
    ):
        getattr(egl, fn).restype = restype
        getattr(egl, fn).argtypes = argtypes
    devices = (ctypes.c_void_p * MAX_DEVICES)()
    count = ctypes.c_int(0)
    if not query_devices(MAX_DEVICES, devices, ctypes.byref(count)):
        return False
    attributes = (ctypes.c_int * len(_EGL_CONFIG))(*_EGL_CONFIG)
    for device in devices[: count.value]:
        display = platform_display(_EGL_PLATFORM_DEVICE_EXT, device, None)
        if not display or not egl.eglInitialize(display, None, None):
            egl.eglGetError()  # clear the error for the next device
            continue
        try:
            config = ctypes.c_void_p()
            found = ctypes.c_int(0)
            if not egl.eglChooseConfig(display, attributes, ctypes.byref(config), 1, found):
                continue
            if found.value < 1 or not egl.eglBindAPI(_EGL_OPENGL_API):
                continue
            context = egl.eglCreateContext(display, config, None, None)
            if not context:
                continue
            current = egl.eglMakeCurrent(display, None, None, context)
            egl.eglMakeCurrent(display, None, None, None)
            egl.eglDestroyContext(display, context)
            if current:
                return True
        finally:
            egl.eglTerminate(display)
    return False


def choose_gl_backend(
    environ: dict[str, str] | None = None, egl_works: Callable[[], bool] = egl_context_works
) -> str:
    """Set MUJOCO_GL (egl, osmesa) unless already set; return the backend in use."""
    env = os.environ if environ is None else environ
    if env.get("MUJOCO_GL"):
        return env["MUJOCO_GL"]
    if ctypes.util.find_library("EGL") and egl_works():
        env["MUJOCO_GL"] = "egl"
        env.setdefault("PYOPENGL_PLATFORM", "egl")
        return "egl"
    if ctypes.util.find_library("OSMesa"):
        env["MUJOCO_GL"] = "osmesa"
        env.setdefault("PYOPENGL_PLATFORM", "osmesa")
        return "osmesa"
    return ""  # nothing works: rendering will fail with MuJoCo's own message


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
