"""Headless OpenGL contexts through EGL, and keeping another GL user's context current.

Our renderer draws in its own EGL context; Helios's Visualizer, in the same process, expects its
context to stay current between its calls. So every draw of ours saves the current context
(:func:`egl_current`) and makes it current again afterwards (:func:`egl_restore`).
"""

from __future__ import annotations

import functools


@functools.cache
def _egl_library():
    """libEGL through ctypes, or None; looked up once (``find_library`` runs ``ldconfig``)."""
    import ctypes
    import ctypes.util

    try:
        egl = ctypes.CDLL(ctypes.util.find_library("EGL") or "libEGL.so.1")
    except OSError:
        return None
    for name in ("eglGetCurrentDisplay", "eglGetCurrentContext", "eglGetCurrentSurface"):
        getattr(egl, name).restype = ctypes.c_void_p
    egl.eglGetCurrentSurface.argtypes = [ctypes.c_int]
    egl.eglMakeCurrent.argtypes = [ctypes.c_void_p] * 4
    return egl


def egl_current() -> tuple | None:
    """The EGL context current on this thread (display, draw, read, context), or None."""
    egl = _egl_library()
    if egl is None:
        return None
    display = egl.eglGetCurrentDisplay()
    if not display:
        return None
    draw_surface, read_surface = 0x3059, 0x305A  # EGL_DRAW, EGL_READ
    return (
        egl,
        display,
        egl.eglGetCurrentSurface(draw_surface),
        egl.eglGetCurrentSurface(read_surface),
        egl.eglGetCurrentContext(),
    )


def egl_restore(state: tuple | None) -> None:
    """Make a context saved by :func:`egl_current` current again (another GL user's, such as
    Helios's Visualizer, which expects its context to stay current between its calls)."""
    if state is not None:
        egl, display, draw, read, context = state
        egl.eglMakeCurrent(display, draw, read, context)


#: Environment variable naming the EGL device to draw on (an index into EGL's device list).
EGL_DEVICE_VARIABLE = "DAVIS_AG_EGL_DEVICE"


def create_context():
    """A headless OpenGL 3.3+ context through EGL: the default EGL display (a GPU's driver where one
    is installed and chosen by libglvnd, else Mesa's llvmpipe), or EGL device number
    ``$DAVIS_AG_EGL_DEVICE`` where that is set (docs/rendering.md)."""
    import os

    import moderngl

    from davis_ag.errors import UserError

    device = os.environ.get(EGL_DEVICE_VARIABLE, "").strip()
    if device and not (device.isascii() and device.isdigit()):
        raise UserError(f"{EGL_DEVICE_VARIABLE}={device!r}: give the number of an EGL device (0, 1, ...)")
    options = {"device_index": int(device)} if device else {}
    try:
        return moderngl.create_standalone_context(backend="egl", require=330, **options)
    except Exception as error:
        raise UserError(
            f"cannot open a headless OpenGL context through EGL ({error}): install the "
            "system's EGL and GL libraries (Debian: libegl1 libgl1 libgl1-mesa-dri)"
            + (f", or choose another {EGL_DEVICE_VARIABLE}" if device else "")
        ) from None


#: Words of ``GL_RENDERER`` that name a rasteriser running on the CPU (Mesa's llvmpipe and softpipe,
#: Google's SwiftShader); any other renderer draws on a GPU.
SOFTWARE_RASTERISERS = ("llvmpipe", "softpipe", "swiftshader")


def renderer_name() -> str:
    """``GL_RENDERER`` of the context our renderer draws in: ``llvmpipe (LLVM 15.0.6, 256 bits)`` on a
    machine without a GPU, ``NVIDIA H200/PCIe/SSE2`` on one with NVIDIA's EGL driver (asked once per
    ``$DAVIS_AG_EGL_DEVICE``, which chooses the device).

    Raises:
        UserError: when no context can be opened (see :func:`create_context`).
    """
    import os

    return _renderer_name(os.environ.get(EGL_DEVICE_VARIABLE, "").strip())


@functools.cache
def _renderer_name(device: str) -> str:
    """:func:`renderer_name` for one value of ``$DAVIS_AG_EGL_DEVICE`` (read by :func:`create_context`)."""
    state = egl_current()  # another GL user's context (Helios's Visualizer) stays current
    context = create_context()
    try:
        return str(context.info["GL_RENDERER"])
    finally:
        context.release()
        egl_restore(state)


def draws_on_gpu(renderer: str) -> bool:
    """Whether a ``GL_RENDERER`` name is a GPU's (not one of :data:`SOFTWARE_RASTERISERS`)."""
    return not any(word in renderer.lower() for word in SOFTWARE_RASTERISERS)
