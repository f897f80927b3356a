"""Render the fog reference scene with Mesa's fixed-function fog (llvmpipe, OpenGL compatibility
profile through EGL) and store it as tests/pipeline/reference/mesa_fog.npz.

    python tools/regen_mesa_fog_reference.py     (needs libegl1 libopengl0 libgl1-mesa-dri)

The scene: a floor quad receding from z_eye = -1 to -40 under a 60° perspective projection, one
flat color, drawn once per fog mode (LINEAR start 2 end 30, EXP density 0.08, EXP2 density 0.06)
with fog color (0.7, 0.75, 0.8). tests/pipeline/test_fog.py draws the same scene with softgl's
SOFTGL_fog and compares the bytes.
"""
import ctypes as c
import math
import os
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "tests" / "pipeline" / "reference" / "mesa_fog.npz"
W, H = 64, 48
COLOR = (0.9, 0.3, 0.2, 1.0)
FOG_COLOR = (0.7, 0.75, 0.8, 1.0)
MODES = {"LINEAR": dict(start=2.0, end=30.0), "EXP": dict(density=0.08), "EXP2": dict(density=0.06)}
FLOOR = [(-8.0, -1.0, -1.0), (8.0, -1.0, -1.0), (8.0, -1.0, -40.0), (-8.0, -1.0, -40.0)]


def perspective(fovy, aspect, near, far):
    f = 1.0 / math.tan(fovy / 2)
    return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                     [0, 0, -1, 0]], np.float64)


PROJECTION = perspective(math.radians(60), W / H, 0.5, 100.0)


def render():
    os.environ["LIBGL_ALWAYS_SOFTWARE"] = "1"
    egl = c.CDLL("libEGL.so.1")
    gl = c.CDLL("libOpenGL.so.0")
    egl.eglGetPlatformDisplay.restype = c.c_void_p
    egl.eglGetPlatformDisplay.argtypes = [c.c_uint, c.c_void_p, c.c_void_p]
    egl.eglInitialize.argtypes = [c.c_void_p, c.c_void_p, c.c_void_p]
    egl.eglChooseConfig.argtypes = [c.c_void_p, c.c_void_p, c.c_void_p, c.c_int, c.c_void_p]
    egl.eglCreateContext.restype = c.c_void_p
    egl.eglCreateContext.argtypes = [c.c_void_p, c.c_void_p, c.c_void_p, c.c_void_p]
    egl.eglMakeCurrent.argtypes = [c.c_void_p, c.c_void_p, c.c_void_p, c.c_void_p]
    display = egl.eglGetPlatformDisplay(0x31DD, None, None)        # EGL_PLATFORM_SURFACELESS_MESA
    assert display and egl.eglInitialize(display, None, None)
    assert egl.eglBindAPI(0x30A2)                                   # EGL_OPENGL_API
    attrs = (c.c_int * 5)(0x3040, 0x8, 0x3033, 0, 0x3038)           # EGL_OPENGL_BIT, surfaceless
    config, n = c.c_void_p(), c.c_int()
    assert egl.eglChooseConfig(display, attrs, c.byref(config), 1, c.byref(n)) and n.value
    # A compatibility-profile context (EGL_CONTEXT_OPENGL_PROFILE_MASK = COMPATIBILITY_BIT).
    ctx_attrs = (c.c_int * 3)(0x30FD, 0x2, 0x3038)
    context = egl.eglCreateContext(display, config, None, ctx_attrs)
    assert context and egl.eglMakeCurrent(display, None, None, context)
    gl.glGetString.restype = c.c_char_p
    renderer = gl.glGetString(0x1F01).decode()
    version = gl.glGetString(0x1F02).decode()
    assert "llvmpipe" in renderer, renderer

    fbo, rb_color, rb_depth = c.c_uint(), c.c_uint(), c.c_uint()
    gl.glGenFramebuffers(1, c.byref(fbo))
    gl.glBindFramebuffer(0x8D40, fbo)
    gl.glGenRenderbuffers(1, c.byref(rb_color))
    gl.glBindRenderbuffer(0x8D41, rb_color)
    gl.glRenderbufferStorage(0x8D41, 0x8058, W, H)                   # RGBA8
    gl.glFramebufferRenderbuffer(0x8D40, 0x8CE0, 0x8D41, rb_color)
    assert gl.glCheckFramebufferStatus(0x8D40) == 0x8CD5
    gl.glViewport(0, 0, W, H)
    gl.glMatrixMode(0x1701)                                         # GL_PROJECTION
    gl.glLoadMatrixd((c.c_double * 16)(*PROJECTION.T.ravel()))
    gl.glMatrixMode(0x1700)                                         # GL_MODELVIEW
    gl.glLoadIdentity()
    gl.glEnable(0x0B60)                                             # GL_FOG
    gl.glFogfv(0x0B66, (c.c_float * 4)(*FOG_COLOR))
    gl.glHint(0x0C54, 0x1102)                                       # FOG_HINT NICEST: per fragment
    images = {}
    for mode, params in MODES.items():
        gl.glClearColor(c.c_float(0), c.c_float(0), c.c_float(0), c.c_float(1))
        gl.glClear(0x4000)
        gl.glFogi(0x0B65, {"LINEAR": 0x2601, "EXP": 0x0800, "EXP2": 0x0801}[mode])
        for name, value in params.items():
            gl.glFogf({"start": 0x0B63, "end": 0x0B64, "density": 0x0B62}[name], c.c_float(value))
        gl.glColor4f(*(c.c_float(v) for v in COLOR))
        gl.glBegin(0x0007)                                           # GL_QUADS
        for x, y, z in FLOOR:
            gl.glVertex3f(c.c_float(x), c.c_float(y), c.c_float(z))
        gl.glEnd()
        pixels = np.zeros((H, W, 4), np.uint8)
        gl.glReadPixels(0, 0, W, H, 0x1908, 0x1401, pixels.ctypes.data_as(c.c_void_p))
        images[mode] = pixels
    assert gl.glGetError() == 0
    return images, renderer, version


def main():
    images, renderer, version = render()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(OUT, renderer=f"{renderer} / {version}", **images)
    print(f"wrote {OUT} ({renderer}, {version})")


if __name__ == "__main__":
    sys.exit(main())
