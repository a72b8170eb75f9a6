"""Choose the offscreen OpenGL backend before MuJoCo is imported.

``vcage/__init__`` calls :func:`choose_gl_backend` before any module imports
``mujoco``. ``MUJOCO_GL`` set by the user
wins; otherwise EGL is used when its library is present, then OSMesa.
"""

from __future__ import annotations

import ctypes.util
import os


def choose_gl_backend() -> str:
    if os.environ.get("MUJOCO_GL"):
        return os.environ["MUJOCO_GL"]
    for backend, lib in (("egl", "EGL"), ("osmesa", "OSMesa")):
        if ctypes.util.find_library(lib):
            os.environ["MUJOCO_GL"] = backend
            if backend == "osmesa":
                os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
            return backend
    return os.environ.setdefault("MUJOCO_GL", "egl")

