"""Mesa llvmpipe as softgl's speed reference: render a scene description, time it, read it back.

docs/architecture.md, "Tests and references": every performance figure is a ratio softgl/llvmpipe
measured in the same run, on the same scene, with the same shaders and the same thread count. This
module is the llvmpipe half.

How it talks to Mesa: ctypes over EGL (``libEGL.so.1``) and OpenGL ES (``libGLESv2.so.2``), with
the surfaceless platform (``EGL_MESA_platform_surfaceless``) and an **OpenGL ES 3.0 context**, so
softgl's GLSL ES 1.00 and 3.00 shaders are compiled by Mesa exactly as written, with no translation.
The scene renders into an off-screen framebuffer (RGBA8 colour + DEPTH_COMPONENT24 renderbuffers;
multisampled ones plus a resolve blit when ``samples > 0``).

Threads: llvmpipe reads ``LP_NUM_THREADS`` once, when its screen is created (at ``eglInitialize``),
so the thread count is fixed for the life of a process. ``LlvmpipeRenderer`` sets the variable
before it initialises EGL and refuses a second, different count in the same process; to compare
thread counts, run each in its own process with ``LlvmpipeProcess`` / ``run_in_subprocess``.
``LP_NUM_THREADS=N`` gives N rasterizer threads (named ``llvmpipe-0..N-1``) *plus* the calling
thread, which runs vertex shading, setup and binning; ``0`` rasterizes on the calling thread.
The renderer counts the ``llvmpipe-*`` threads that really exist, so a caller can see what Mesa did.

    python benchmarks/reference_gl.py --selftest

prints the renderer, its threads, and a fill-rate timing table at threads=1 and 2.
"""
from __future__ import annotations

import ctypes
import glob
import hashlib
import multiprocessing
import os
import pickle
import platform
import statistics
import sys
import time
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

# ---------------------------------------------------------------------------------------------
# GL enums (OpenGL ES 3.0 values; the same numbers as WebGL's constants).
# Scene descriptions may name them as strings ("SRC_ALPHA") or give the numbers.
GL = {
    # primitives
    "POINTS": 0x0000, "LINES": 0x0001, "LINE_LOOP": 0x0002, "LINE_STRIP": 0x0003,
    "TRIANGLES": 0x0004, "TRIANGLE_STRIP": 0x0005, "TRIANGLE_FAN": 0x0006,
    # blend factors
    "ZERO": 0, "ONE": 1, "SRC_COLOR": 0x0300, "ONE_MINUS_SRC_COLOR": 0x0301,
    "SRC_ALPHA": 0x0302, "ONE_MINUS_SRC_ALPHA": 0x0303, "DST_ALPHA": 0x0304,
    "ONE_MINUS_DST_ALPHA": 0x0305, "DST_COLOR": 0x0306, "ONE_MINUS_DST_COLOR": 0x0307,
    "SRC_ALPHA_SATURATE": 0x0308, "CONSTANT_COLOR": 0x8001, "ONE_MINUS_CONSTANT_COLOR": 0x8002,
    "CONSTANT_ALPHA": 0x8003, "ONE_MINUS_CONSTANT_ALPHA": 0x8004,
    # blend equations
    "FUNC_ADD": 0x8006, "FUNC_SUBTRACT": 0x800A, "FUNC_REVERSE_SUBTRACT": 0x800B,
    "MIN": 0x8007, "MAX": 0x8008,
    # depth functions
    "NEVER": 0x0200, "LESS": 0x0201, "EQUAL": 0x0202, "LEQUAL": 0x0203, "GREATER": 0x0204,
    "NOTEQUAL": 0x0205, "GEQUAL": 0x0206, "ALWAYS": 0x0207,
    # faces
    "FRONT": 0x0404, "BACK": 0x0405, "FRONT_AND_BACK": 0x0408, "CW": 0x0900, "CCW": 0x0901,
    # texture parameters
    "NEAREST": 0x2600, "LINEAR": 0x2601, "NEAREST_MIPMAP_NEAREST": 0x2700,
    "LINEAR_MIPMAP_NEAREST": 0x2701, "NEAREST_MIPMAP_LINEAR": 0x2702,
    "LINEAR_MIPMAP_LINEAR": 0x2703, "REPEAT": 0x2901, "CLAMP_TO_EDGE": 0x812F,
    "MIRRORED_REPEAT": 0x8370,
}


def _enum(value: int | str) -> int:
    return GL[value] if isinstance(value, str) else int(value)


# ---------------------------------------------------------------------------------------------
# Scene description: plain data, picklable, so the same object can go to a worker process.

@dataclass
class Texture:
    """A 2D RGBA8 texture; ``data`` is (h, w, 4) uint8, row 0 = bottom (GL's order)."""
    data: np.ndarray
    min_filter: int | str = "LINEAR"
    mag_filter: int | str = "LINEAR"
    wrap_s: int | str = "REPEAT"
    wrap_t: int | str = "REPEAT"
    mipmap: bool = False  # generateMipmap after upload (needed for *_MIPMAP_* min filters)


@dataclass
class Draw:
    """One draw call. ``uniforms`` are set just before it (e.g. a colour per quad)."""
    first: int = 0
    count: int | None = None  # None: every vertex (or index) of the scene
    uniforms: Mapping[str, Any] = field(default_factory=dict)


@dataclass
class State:
    """Fixed-function state, WebGL's defaults unless given."""
    blend: bool = False
    blend_func: Sequence[int | str] = ("ONE", "ZERO")  # (src, dst) or (srcRGB, dstRGB, srcA, dstA)
    blend_equation: Sequence[int | str] = ("FUNC_ADD",)  # (mode,) or (modeRGB, modeAlpha)
    blend_color: Sequence[float] = (0.0, 0.0, 0.0, 0.0)
    depth_test: bool = False
    depth_func: int | str = "LESS"
    depth_mask: bool = True
    cull_face: int | str | None = None  # None: culling off; else "BACK", "FRONT", ...
    front_face: int | str = "CCW"
    color_mask: Sequence[bool] = (True, True, True, True)
    line_width: float = 1.0
    clear_color: Sequence[float] = (0.0, 0.0, 0.0, 0.0)
    clear_depth: float = 1.0


@dataclass
class Scene:
    """Everything one frame needs: shaders, vertex data, uniforms, textures, state, draw calls.

    ``attributes`` maps attribute names to float arrays of shape (n,) or (n, k) (converted to
    float32). ``indices`` (uint8/16/32) switches to drawElements. ``uniforms`` are set once per
    frame; matrices are flat sequences in GL's column-major order, as WebGL's
    ``uniformMatrix4fv(loc, false, data)`` takes them. ``textures`` maps sampler uniform names to
    textures (units are assigned in order). ``draws`` defaults to one call over everything.
    """
    vertex_shader: str
    fragment_shader: str
    attributes: Mapping[str, np.ndarray] = field(default_factory=dict)
    indices: np.ndarray | None = None
    uniforms: Mapping[str, Any] = field(default_factory=dict)
    textures: Mapping[str, Texture] = field(default_factory=dict)
    mode: int | str = "TRIANGLES"
    count: int | None = None  # vertices (or indices) for the default single draw
    draws: Sequence[Draw] | None = None
    state: State = field(default_factory=State)

    def vertex_count(self) -> int:
        if self.count is not None:
            return self.count
        if self.indices is not None:
            return int(np.asarray(self.indices).size)
        if self.attributes:
            return min(len(np.asarray(a)) for a in self.attributes.values())
        raise ValueError("scene has no attributes and no indices: give count")


# ---------------------------------------------------------------------------------------------
# EGL / GLES through ctypes. Loaded lazily: loading libEGL must wait until LP_NUM_THREADS is set.

class ReferenceUnavailable(RuntimeError):
    """EGL, GLES or the llvmpipe driver is not available on this machine."""


_c = ctypes
_vp, _u, _i, _f = _c.c_void_p, _c.c_uint, _c.c_int, _c.c_float
_iptr = _c.POINTER(_c.c_int)

# name: (restype, argtypes). Only what this module calls.
_EGL_FUNCS = {
    "eglGetPlatformDisplay": (_vp, [_u, _vp, _vp]),
    "eglInitialize": (_u, [_vp, _iptr, _iptr]),
    "eglBindAPI": (_u, [_u]),
    "eglChooseConfig": (_u, [_vp, _vp, _c.POINTER(_vp), _i, _iptr]),
    "eglCreateContext": (_vp, [_vp, _vp, _vp, _vp]),
    "eglMakeCurrent": (_u, [_vp, _vp, _vp, _vp]),
    "eglDestroyContext": (_u, [_vp, _vp]),
    "eglGetError": (_i, []),
}
_GL_FUNCS = {
    "glGetString": (_c.c_char_p, [_u]),
    "glGetError": (_u, []),
    "glGetIntegerv": (None, [_u, _iptr]),
    "glCreateShader": (_u, [_u]),
    "glShaderSource": (None, [_u, _i, _c.POINTER(_c.c_char_p), _iptr]),
    "glCompileShader": (None, [_u]),
    "glGetShaderiv": (None, [_u, _u, _iptr]),
    "glGetShaderInfoLog": (None, [_u, _i, _iptr, _c.c_char_p]),
    "glCreateProgram": (_u, []),
    "glAttachShader": (None, [_u, _u]),
    "glLinkProgram": (None, [_u]),
    "glGetProgramiv": (None, [_u, _u, _iptr]),
    "glGetProgramInfoLog": (None, [_u, _i, _iptr, _c.c_char_p]),
    "glGetActiveUniform": (None, [_u, _u, _i, _iptr, _iptr, _c.POINTER(_u), _c.c_char_p]),
    "glGetUniformLocation": (_i, [_u, _c.c_char_p]),
    "glGetAttribLocation": (_i, [_u, _c.c_char_p]),
    "glUseProgram": (None, [_u]),
    "glGenVertexArrays": (None, [_i, _c.POINTER(_u)]),
    "glBindVertexArray": (None, [_u]),
    "glGenBuffers": (None, [_i, _c.POINTER(_u)]),
    "glBindBuffer": (None, [_u, _u]),
    "glBufferData": (None, [_u, _c.c_ssize_t, _vp, _u]),
    "glEnableVertexAttribArray": (None, [_u]),
    "glVertexAttribPointer": (None, [_u, _i, _u, _c.c_ubyte, _i, _vp]),
    "glGenTextures": (None, [_i, _c.POINTER(_u)]),
    "glBindTexture": (None, [_u, _u]),
    "glActiveTexture": (None, [_u]),
    "glTexImage2D": (None, [_u, _i, _i, _i, _i, _i, _u, _u, _vp]),
    "glTexParameteri": (None, [_u, _u, _i]),
    "glGenerateMipmap": (None, [_u]),
    "glGenFramebuffers": (None, [_i, _c.POINTER(_u)]),
    "glBindFramebuffer": (None, [_u, _u]),
    "glGenRenderbuffers": (None, [_i, _c.POINTER(_u)]),
    "glBindRenderbuffer": (None, [_u, _u]),
    "glRenderbufferStorage": (None, [_u, _u, _i, _i]),
    "glRenderbufferStorageMultisample": (None, [_u, _i, _u, _i, _i]),
    "glFramebufferRenderbuffer": (None, [_u, _u, _u, _u]),
    "glCheckFramebufferStatus": (_u, [_u]),
    "glBlitFramebuffer": (None, [_i, _i, _i, _i, _i, _i, _i, _i, _u, _u]),
    "glViewport": (None, [_i, _i, _i, _i]),
    "glClearColor": (None, [_f, _f, _f, _f]),
    "glClearDepthf": (None, [_f]),
    "glClear": (None, [_u]),
    "glEnable": (None, [_u]),
    "glDisable": (None, [_u]),
    "glBlendFuncSeparate": (None, [_u, _u, _u, _u]),
    "glBlendEquationSeparate": (None, [_u, _u]),
    "glBlendColor": (None, [_f, _f, _f, _f]),
    "glDepthFunc": (None, [_u]),
    "glDepthMask": (None, [_c.c_ubyte]),
    "glCullFace": (None, [_u]),
    "glFrontFace": (None, [_u]),
    "glColorMask": (None, [_c.c_ubyte] * 4),
    "glLineWidth": (None, [_f]),
    "glDrawArrays": (None, [_u, _i, _i]),
    "glDrawElements": (None, [_u, _i, _u, _vp]),
    "glFinish": (None, []),
    "glPixelStorei": (None, [_u, _i]),
    "glReadPixels": (None, [_i, _i, _i, _i, _u, _u, _vp]),
    # Used by the WebGL adapter (webgl_on_gles.py) of the ordinary-content suite.
    "glUniform1i": (None, [_i, _i]),
    "glUniform1f": (None, [_i, _f]),
    "glUniform2f": (None, [_i, _f, _f]),
    "glUniform3f": (None, [_i, _f, _f, _f]),
    "glUniform4f": (None, [_i, _f, _f, _f, _f]),
    "glVertexAttribDivisor": (None, [_u, _u]),
    "glDrawArraysInstanced": (None, [_u, _i, _i, _i]),
    "glFramebufferTexture2D": (None, [_u, _u, _u, _u, _i]),
    "glBlendFunc": (None, [_u, _u]),
}
# Uniform setters: glUniform{1,2,3,4}{f,i,ui}v(loc, count, ptr) and
# glUniformMatrix*fv(loc, count, transpose, ptr).
for _n in "1234":
    _GL_FUNCS[f"glUniform{_n}fv"] = (None, [_i, _i, _vp])
    _GL_FUNCS[f"glUniform{_n}iv"] = (None, [_i, _i, _vp])
    _GL_FUNCS[f"glUniform{_n}uiv"] = (None, [_i, _i, _vp])
for _m in ("2", "3", "4", "2x3", "3x2", "2x4", "4x2", "3x4", "4x3"):
    _GL_FUNCS[f"glUniformMatrix{_m}fv"] = (None, [_i, _i, _c.c_ubyte, _vp])


class _Lib:
    """Typed ctypes functions of one shared library, as attributes without the prefix."""

    def __init__(self, soname: str, funcs: dict):
        try:
            lib = ctypes.CDLL(soname)
        except OSError as e:
            raise ReferenceUnavailable(f"cannot load {soname}: {e} "
                                       "(Debian: apt-get install libegl1 libgles2 libegl-mesa0 "
                                       "libgl1-mesa-dri)") from e
        for name, (restype, argtypes) in funcs.items():
            fn = getattr(lib, name)
            fn.restype, fn.argtypes = restype, argtypes
            setattr(self, name, fn)


# GLSL type enum -> (setter suffix, numpy dtype, components). Booleans and samplers go through
# the integer setters (ES 3.0 §2.12.6).
_F32, _I32, _U32 = np.float32, np.int32, np.uint32
_UNIFORM_TYPES = {
    0x1406: ("1fv", _F32, 1), 0x8B50: ("2fv", _F32, 2), 0x8B51: ("3fv", _F32, 3),
    0x8B52: ("4fv", _F32, 4),
    0x1404: ("1iv", _I32, 1), 0x8B53: ("2iv", _I32, 2), 0x8B54: ("3iv", _I32, 3),
    0x8B55: ("4iv", _I32, 4),
    0x8B56: ("1iv", _I32, 1), 0x8B57: ("2iv", _I32, 2), 0x8B58: ("3iv", _I32, 3),
    0x8B59: ("4iv", _I32, 4),
    0x1405: ("1uiv", _U32, 1), 0x8DC6: ("2uiv", _U32, 2), 0x8DC7: ("3uiv", _U32, 3),
    0x8DC8: ("4uiv", _U32, 4),
    0x8B5A: ("Matrix2fv", _F32, 4), 0x8B5B: ("Matrix3fv", _F32, 9), 0x8B5C: ("Matrix4fv", _F32, 16),
    0x8B65: ("Matrix2x3fv", _F32, 6), 0x8B66: ("Matrix2x4fv", _F32, 8),
    0x8B67: ("Matrix3x2fv", _F32, 6), 0x8B68: ("Matrix3x4fv", _F32, 12),
    0x8B69: ("Matrix4x2fv", _F32, 8), 0x8B6A: ("Matrix4x3fv", _F32, 12),
}
for _sampler in (0x8B5E, 0x8B5F, 0x8B60, 0x8B62, 0x8DC1, 0x8DC4, 0x8DC5, 0x8DCA, 0x8DCB,
                 0x8DCC, 0x8DCF, 0x8DD2, 0x8DD3, 0x8DD4, 0x8DD7):
    _UNIFORM_TYPES[_sampler] = ("1iv", _I32, 1)

_INDEX_TYPES = {np.dtype(np.uint8): 0x1401, np.dtype(np.uint16): 0x1403,
                np.dtype(np.uint32): 0x1405}

# Which thread count this process's llvmpipe screen was created with (None: not yet).
_PROCESS_THREADS: int | None = None


def llvmpipe_thread_names() -> list[str]:
    """Names of this process's llvmpipe rasterizer threads (Mesa names them llvmpipe-<i>)."""
    names = []
    for path in glob.glob("/proc/self/task/*/comm"):
        try:
            with open(path) as f:
                name = f.read().strip()
        except OSError:  # the thread ended while we looked
            continue
        if name.startswith("llvmpipe-"):
            names.append(name)
    return sorted(names)


class _Prepared:
    """A scene compiled and uploaded; its per-frame calls are pre-built, so timing sees GL only."""

    def __init__(self, program: int, vao: int, frame_calls: list, scene: Scene):
        self.program, self.vao, self.frame_calls, self.scene = program, vao, frame_calls, scene


class LlvmpipeRenderer:
    """Mesa llvmpipe through EGL + OpenGL ES 3.0, rendering Scenes into a width x height FBO.

    ``threads`` sets ``LP_NUM_THREADS`` (None keeps the environment's value, or Mesa's default:
    one rasterizer thread per CPU). It must be chosen before the first renderer of the process;
    a different count later raises RuntimeError (use ``LlvmpipeProcess``).
    ``samples`` > 0 renders into multisampled buffers and resolves with a blit at the end of
    every frame (inside the timed region: a frame is not finished until it is resolved).
    """

    def __init__(self, width: int, height: int, threads: int | None = None, samples: int = 0):
        global _PROCESS_THREADS
        self.width, self.height, self.samples = int(width), int(height), int(samples)
        if threads is None:
            threads = int(os.environ.get("LP_NUM_THREADS", os.cpu_count() or 1))
        self.threads = int(threads)
        if _PROCESS_THREADS is not None and _PROCESS_THREADS != self.threads:
            raise RuntimeError(
                f"llvmpipe in this process already runs with LP_NUM_THREADS={_PROCESS_THREADS}; "
                f"Mesa reads it once per process, so threads={self.threads} needs another "
                "process (LlvmpipeProcess / run_in_subprocess)")
        # Mesa reads these at eglInitialize. Force the software rasterizer even where a GPU exists.
        os.environ["LP_NUM_THREADS"] = str(self.threads)
        os.environ["LIBGL_ALWAYS_SOFTWARE"] = "1"
        os.environ["GALLIUM_DRIVER"] = "llvmpipe"

        self.egl = _Lib("libEGL.so.1", _EGL_FUNCS)
        self.gl = _Lib("libGLESv2.so.2", _GL_FUNCS)
        self._create_context()
        _PROCESS_THREADS = self.threads
        gl = self.gl
        self.renderer = gl.glGetString(0x1F01).decode()   # GL_RENDERER
        self.version = gl.glGetString(0x1F02).decode()    # GL_VERSION
        if "llvmpipe" not in self.renderer:
            self.close()
            raise ReferenceUnavailable(f"EGL gave {self.renderer!r}, not llvmpipe")
        self._create_framebuffers()
        self._prepared: dict[bytes, _Prepared] = {}

    # -- context and framebuffer ------------------------------------------------------------
    def _create_context(self) -> None:
        egl = self.egl
        # EGL_PLATFORM_SURFACELESS_MESA: no window system, no pbuffer; we draw into our own FBO.
        self.display = egl.eglGetPlatformDisplay(0x31DD, None, None)
        major, minor = _c.c_int(), _c.c_int()
        if not self.display or not egl.eglInitialize(self.display, major, minor):
            raise ReferenceUnavailable(f"eglInitialize failed (0x{egl.eglGetError():x})")
        if not egl.eglBindAPI(0x30A0):  # EGL_OPENGL_ES_API
            raise ReferenceUnavailable("eglBindAPI(EGL_OPENGL_ES_API) failed")
        # EGL_RENDERABLE_TYPE = EGL_OPENGL_ES3_BIT, EGL_SURFACE_TYPE = 0 (surfaceless), EGL_NONE
        attrs = (_c.c_int * 5)(0x3040, 0x40, 0x3033, 0, 0x3038)
        config, n = _c.c_void_p(), _c.c_int()
        ok = egl.eglChooseConfig(self.display, attrs, _c.byref(config), 1, _c.byref(n))
        if not ok or not n.value:
            raise ReferenceUnavailable("no EGL config with OpenGL ES 3 support")
        # EGL_CONTEXT_MAJOR_VERSION 3, EGL_CONTEXT_MINOR_VERSION 0
        ctx_attrs = (_c.c_int * 5)(0x3098, 3, 0x30FB, 0, 0x3038)
        self.context = egl.eglCreateContext(self.display, config, None, ctx_attrs)
        if not self.context:
            raise ReferenceUnavailable(f"eglCreateContext(ES 3.0) failed (0x{egl.eglGetError():x})")
        if not egl.eglMakeCurrent(self.display, None, None, self.context):
            raise ReferenceUnavailable(f"eglMakeCurrent failed (0x{egl.eglGetError():x})")

    def _gen(self, fn) -> int:
        name = _c.c_uint()
        fn(1, _c.byref(name))
        return name.value

    def _create_framebuffers(self) -> None:
        gl, w, h = self.gl, self.width, self.height
        GL_FRAMEBUFFER, GL_RENDERBUFFER = 0x8D40, 0x8D41
        RGBA8, DEPTH24 = 0x8058, 0x81A6
        COLOR0, DEPTH = 0x8CE0, 0x8D00

        def framebuffer(samples: int) -> int:
            fbo = self._gen(gl.glGenFramebuffers)
            gl.glBindFramebuffer(GL_FRAMEBUFFER, fbo)
            for fmt, attachment in ((RGBA8, COLOR0), (DEPTH24, DEPTH)):
                rb = self._gen(gl.glGenRenderbuffers)
                gl.glBindRenderbuffer(GL_RENDERBUFFER, rb)
                if samples:
                    gl.glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, fmt, w, h)
                else:
                    gl.glRenderbufferStorage(GL_RENDERBUFFER, fmt, w, h)
                gl.glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, rb)
            status = gl.glCheckFramebufferStatus(GL_FRAMEBUFFER)
            if status != 0x8CD5:  # GL_FRAMEBUFFER_COMPLETE
                raise RuntimeError(f"framebuffer incomplete (0x{status:x}), samples={samples}")
            return fbo

        self.resolve_fbo = framebuffer(0)  # single-sampled: readPixels reads this one
        self.draw_fbo = framebuffer(self.samples) if self.samples else self.resolve_fbo
        gl.glBindFramebuffer(GL_FRAMEBUFFER, self.draw_fbo)
        gl.glViewport(0, 0, w, h)
        self._check("framebuffer setup")

    def _check(self, what: str) -> None:
        err = self.gl.glGetError()
        if err:
            raise RuntimeError(f"GL error 0x{err:x} in {what}")

    # -- scene preparation ------------------------------------------------------------------
    def _compile(self, kind: int, source: str) -> int:
        gl = self.gl
        shader = gl.glCreateShader(kind)
        src = _c.c_char_p(source.encode())
        gl.glShaderSource(shader, 1, _c.byref(src), None)
        gl.glCompileShader(shader)
        ok = _c.c_int()
        gl.glGetShaderiv(shader, 0x8B81, ok)  # GL_COMPILE_STATUS
        if not ok.value:
            log = _c.create_string_buffer(8192)
            gl.glGetShaderInfoLog(shader, 8192, None, log)
            stage = "vertex" if kind == 0x8B31 else "fragment"
            raise ValueError(f"llvmpipe: {stage} shader does not compile:\n{log.value.decode()}")
        return shader

    def _link(self, vs_source: str, fs_source: str) -> int:
        gl = self.gl
        program = gl.glCreateProgram()
        gl.glAttachShader(program, self._compile(0x8B31, vs_source))  # GL_VERTEX_SHADER
        gl.glAttachShader(program, self._compile(0x8B30, fs_source))  # GL_FRAGMENT_SHADER
        gl.glLinkProgram(program)
        ok = _c.c_int()
        gl.glGetProgramiv(program, 0x8B82, ok)  # GL_LINK_STATUS
        if not ok.value:
            log = _c.create_string_buffer(8192)
            gl.glGetProgramInfoLog(program, 8192, None, log)
            raise ValueError(f"llvmpipe: program does not link:\n{log.value.decode()}")
        return program

    def _active_uniforms(self, program: int) -> dict[str, tuple[int, int, int]]:
        """name -> (location, type, array size); arrays answer to both "u" and "u[0]"."""
        gl = self.gl
        count = _c.c_int()
        gl.glGetProgramiv(program, 0x8B86, count)  # GL_ACTIVE_UNIFORMS
        out = {}
        for i in range(count.value):
            size, utype, buf = _c.c_int(), _c.c_uint(), _c.create_string_buffer(256)
            gl.glGetActiveUniform(program, i, 256, None, size, utype, buf)
            name = buf.value.decode()
            loc = gl.glGetUniformLocation(program, name.encode())
            if loc < 0:  # uniform block members have no location
                continue
            out[name] = (loc, utype.value, size.value)
            if name.endswith("[0]"):
                out[name[:-3]] = out[name]
        return out

    def _uniform_call(self, uniforms: dict, name: str, value) -> tuple:
        """(function, args, data) setting uniform ``name``; ``data`` keeps the array alive."""
        if name not in uniforms:
            raise KeyError(f"uniform {name!r} is not active in the program "
                           f"(active: {sorted(uniforms)})")
        loc, utype, size = uniforms[name]
        suffix, dtype, comps = _UNIFORM_TYPES[utype]
        data = np.ascontiguousarray(np.asarray(value, dtype=dtype).ravel())
        if data.size % comps or not 0 < data.size // comps <= size:
            raise ValueError(f"uniform {name!r}: {data.size} values do not fit "
                             f"{size} x {comps} components")
        fn = getattr(self.gl, "glUniform" + suffix)
        ptr = data.ctypes.data_as(_c.c_void_p)
        if suffix.startswith("Matrix"):
            return fn, (loc, data.size // comps, 0, ptr), data
        return fn, (loc, data.size // comps, ptr), data

    def prepare(self, scene: Scene) -> _Prepared:
        """Compile, upload and bake the per-frame calls of ``scene``.

        Cached by content, not identity: a worker process receives a new copy of the scene with
        every request, and alternating A/B rounds must not compile and upload it again each time.
        """
        key = hashlib.blake2b(pickle.dumps(scene, protocol=pickle.HIGHEST_PROTOCOL)).digest()
        if key in self._prepared:
            return self._prepared[key]
        gl = self.gl
        program = self._link(scene.vertex_shader, scene.fragment_shader)
        gl.glUseProgram(program)
        uniforms = self._active_uniforms(program)

        vao = self._gen(gl.glGenVertexArrays)
        gl.glBindVertexArray(vao)
        for name, array in scene.attributes.items():
            loc = gl.glGetAttribLocation(program, name.encode())
            if loc < 0:
                # The GLSL compiler removed an unused attribute: uploading it would change nothing.
                continue
            data = np.ascontiguousarray(array, dtype=np.float32)
            comps = 1 if data.ndim == 1 else data.shape[1]
            buf = self._gen(gl.glGenBuffers)
            gl.glBindBuffer(0x8892, buf)  # GL_ARRAY_BUFFER
            gl.glBufferData(0x8892, data.nbytes, data.ctypes.data, 0x88E4)  # GL_STATIC_DRAW
            gl.glEnableVertexAttribArray(loc)
            gl.glVertexAttribPointer(loc, comps, 0x1406, 0, 0, None)  # GL_FLOAT, tightly packed
        index_type = None
        if scene.indices is not None:
            idx = np.ascontiguousarray(scene.indices)
            if idx.dtype not in _INDEX_TYPES:
                idx = idx.astype(np.uint32)
            index_type, index_size = _INDEX_TYPES[idx.dtype], idx.itemsize
            buf = self._gen(gl.glGenBuffers)
            gl.glBindBuffer(0x8893, buf)  # GL_ELEMENT_ARRAY_BUFFER (recorded in the VAO)
            gl.glBufferData(0x8893, idx.nbytes, idx.ctypes.data, 0x88E4)

        # Textures: unit i for the i-th sampler; the sampler uniform is set once, here.
        for unit, (name, tex) in enumerate(scene.textures.items()):
            data = np.ascontiguousarray(tex.data, dtype=np.uint8)
            h, w = data.shape[:2]
            gl.glActiveTexture(0x84C0 + unit)  # GL_TEXTURE0 + unit
            gl.glBindTexture(0x0DE1, self._gen(gl.glGenTextures))  # GL_TEXTURE_2D
            gl.glPixelStorei(0x0CF5, 1)  # GL_UNPACK_ALIGNMENT: rows are tightly packed
            gl.glTexImage2D(0x0DE1, 0, 0x8058, w, h, 0, 0x1908, 0x1401, data.ctypes.data)
            for pname, value in ((0x2801, tex.min_filter), (0x2800, tex.mag_filter),
                                 (0x2802, tex.wrap_s), (0x2803, tex.wrap_t)):
                gl.glTexParameteri(0x0DE1, pname, _enum(value))
            if tex.mipmap:
                gl.glGenerateMipmap(0x0DE1)
            fn, args, keep = self._uniform_call(uniforms, name, unit)
            fn(*args)

        # The frame: clear, then per draw its uniforms and the draw call, all pre-built so the timed
        # loop runs nothing but ctypes calls into Mesa.
        mode = _enum(scene.mode)
        calls = [self._uniform_call(uniforms, n, v) for n, v in scene.uniforms.items()]
        total = scene.vertex_count()
        for d in (scene.draws if scene.draws is not None else [Draw()]):
            calls += [self._uniform_call(uniforms, n, v) for n, v in d.uniforms.items()]
            count = total - d.first if d.count is None else d.count
            if index_type is None:
                calls.append((gl.glDrawArrays, (mode, d.first, count), None))
            else:
                calls.append((gl.glDrawElements, (mode, count, index_type,
                                                  _c.c_void_p(d.first * index_size)), None))
        self._check("scene preparation")
        prepared = _Prepared(program, vao, calls, scene)
        self._prepared[key] = prepared
        return prepared

    def _apply_state(self, s: State) -> None:
        gl = self.gl
        BLEND, DEPTH_TEST, CULL_FACE = 0x0BE2, 0x0B71, 0x0B44
        (gl.glEnable if s.blend else gl.glDisable)(BLEND)
        f = [_enum(x) for x in s.blend_func]
        gl.glBlendFuncSeparate(*(f * 2 if len(f) == 2 else f))
        e = [_enum(x) for x in s.blend_equation]
        gl.glBlendEquationSeparate(*(e * 2 if len(e) == 1 else e))
        gl.glBlendColor(*s.blend_color)
        (gl.glEnable if s.depth_test else gl.glDisable)(DEPTH_TEST)
        gl.glDepthFunc(_enum(s.depth_func))
        gl.glDepthMask(bool(s.depth_mask))
        (gl.glEnable if s.cull_face is not None else gl.glDisable)(CULL_FACE)
        if s.cull_face is not None:
            gl.glCullFace(_enum(s.cull_face))
        gl.glFrontFace(_enum(s.front_face))
        gl.glColorMask(*(bool(m) for m in s.color_mask))
        gl.glLineWidth(s.line_width)
        gl.glClearColor(*s.clear_color)
        gl.glClearDepthf(s.clear_depth)

    # -- frames ------------------------------------------------------------------------------
    def _frame(self, p: _Prepared) -> None:
        """clear + draws (+ MSAA resolve) + glFinish: what one timed sample measures."""
        gl = self.gl
        # The clear must write depth even when a scene turned depthMask off (ES 3.0 §4.2.3: the
        # mask applies to clears), so it is re-enabled for the clear and restored for the draws.
        gl.glDepthMask(1)
        gl.glColorMask(1, 1, 1, 1)
        gl.glClear(0x4000 | 0x0100)  # COLOR_BUFFER_BIT | DEPTH_BUFFER_BIT
        s = p.scene.state
        gl.glDepthMask(bool(s.depth_mask))
        gl.glColorMask(*(bool(m) for m in s.color_mask))
        for fn, args, _keep in p.frame_calls:
            fn(*args)
        if self.samples:
            gl.glBindFramebuffer(0x8CA9, self.resolve_fbo)  # GL_DRAW_FRAMEBUFFER
            w, h = self.width, self.height
            gl.glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, 0x4000, 0x2600)  # COLOR, NEAREST
            gl.glBindFramebuffer(0x8CA9, self.draw_fbo)
        gl.glFinish()

    def _begin(self, scene: Scene) -> _Prepared:
        p = self.prepare(scene)
        gl = self.gl
        gl.glBindFramebuffer(0x8D40, self.draw_fbo)
        gl.glUseProgram(p.program)
        gl.glBindVertexArray(p.vao)
        self._apply_state(scene.state)
        return p

    def read_pixels(self) -> np.ndarray:
        """The resolved colour buffer as (h, w, 4) uint8, row 0 = bottom (as readPixels)."""
        gl = self.gl
        out = np.empty((self.height, self.width, 4), np.uint8)
        gl.glBindFramebuffer(0x8CA8, self.resolve_fbo)  # GL_READ_FRAMEBUFFER
        gl.glPixelStorei(0x0D05, 1)  # GL_PACK_ALIGNMENT
        gl.glReadPixels(0, 0, self.width, self.height, 0x1908, 0x1401, out.ctypes.data)
        gl.glBindFramebuffer(0x8D40, self.draw_fbo)
        self._check("readPixels")
        return out

    def render(self, scene: Scene) -> np.ndarray:
        """Render one frame of ``scene`` and return its pixels (see ``read_pixels``)."""
        p = self._begin(scene)
        self._frame(p)
        self._check("draw")
        return self.read_pixels()

    def time_draws(self, scene: Scene, repeats: int = 10, warmup: int = 1) -> list[float]:
        """Wall-clock seconds of each of ``repeats`` frames (clear + draws + glFinish).

        Setup (compile, upload) and readback are outside the timed region. ``warmup`` frames run
        first, untimed: llvmpipe JIT-compiles its shader/state variants at the first draw that
        needs them, and that compile is not rendering. Callers report the median.
        """
        p = self._begin(scene)
        for _ in range(warmup):
            self._frame(p)
        self._check("draw")
        samples = []
        clock = time.perf_counter
        for _ in range(repeats):
            t0 = clock()
            self._frame(p)
            samples.append(clock() - t0)
        self._check("draw")
        return samples

    def info(self) -> dict:
        return {"renderer": self.renderer, "version": self.version, "threads": self.threads,
                "raster_threads": len(llvmpipe_thread_names()), "samples": self.samples,
                "width": self.width, "height": self.height}

    def close(self) -> None:
        if getattr(self, "context", None):
            self.egl.eglMakeCurrent(self.display, None, None, None)
            self.egl.eglDestroyContext(self.display, self.context)
            self.context = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


# ---------------------------------------------------------------------------------------------
# One process per thread count.

def _worker_main(conn, width: int, height: int, threads: int, samples: int) -> None:
    """Child process: own a renderer and answer (method, args) requests until told to stop."""
    try:
        renderer = LlvmpipeRenderer(width, height, threads=threads, samples=samples)
    except BaseException as e:  # report why, instead of a silent dead child
        conn.send(("error", e))
        return
    conn.send(("ok", renderer.info()))
    while True:
        method, args = conn.recv()
        if method == "close":
            break
        try:
            conn.send(("ok", getattr(renderer, method)(*args)))
        except Exception as e:
            conn.send(("error", e))
    renderer.close()


class WorkerProcess:
    """A Mesa worker in its own "spawn" process (a fresh interpreter that has never loaded Mesa,
    whatever the parent did), answering ``(method, args)`` requests over a pipe with
    ``("ok", value)`` or ``("error", exception)``. Subclasses name the worker's entry point."""

    def __init__(self, target, *args):
        ctx = multiprocessing.get_context("spawn")
        self._conn, child = ctx.Pipe()
        self._proc = ctx.Process(target=target, args=(child, *args), daemon=True)
        self._proc.start()
        child.close()

    def _reply(self):
        try:
            status, value = self._conn.recv()
        except EOFError:
            raise RuntimeError(f"llvmpipe worker died (exit code {self._proc.exitcode})") from None
        if status == "error":
            raise value
        return value

    def _call(self, method: str, *args):
        self._conn.send((method, args))
        return self._reply()

    def close(self) -> None:
        if self._proc.is_alive():
            try:
                self._conn.send(("close", ()))
            except OSError:
                pass
            self._proc.join(timeout=10)
        self._conn.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class LlvmpipeProcess(WorkerProcess):
    """An llvmpipe renderer living in its own process, so each can have its own LP_NUM_THREADS.

    It stays alive between requests, so a benchmark can alternate softgl and llvmpipe runs (A/B)
    without paying process start and shader compiles every time. Methods mirror
    ``LlvmpipeRenderer``: ``render``, ``time_draws``, ``info``.
    """

    def __init__(self, width: int, height: int, threads: int, samples: int = 0):
        super().__init__(_worker_main, width, height, threads, samples)
        self._info = self._reply()

    def info(self) -> dict:
        return dict(self._info)

    def render(self, scene: Scene) -> np.ndarray:
        return self._call("render", scene)

    def time_draws(self, scene: Scene, repeats: int = 10, warmup: int = 1) -> list[float]:
        return self._call("time_draws", scene, repeats, warmup)


def run_in_subprocess(scene: Scene, threads: int, width: int, height: int, samples: int = 0,
                      repeats: int = 10, warmup: int = 1) -> dict:
    """Render and time ``scene`` in a fresh process with LP_NUM_THREADS=threads.

    Returns {"renderer", "version", "threads", "raster_threads", ..., "times": [s, ...],
    "image": (h, w, 4) uint8}. The image is from a frame rendered after the timed ones.
    """
    with LlvmpipeProcess(width, height, threads, samples) as proc:
        result = proc.info()
        result["times"] = proc.time_draws(scene, repeats, warmup) if repeats else []
        result["image"] = proc.render(scene)
    return result


# ---------------------------------------------------------------------------------------------
# The machine's limit.

def measure_memory_bandwidth(size_mb: int = 256, repeats: int = 7, threads: int = 1) -> float:
    """Copy bandwidth in GB/s (1e9 bytes/s), median of ``repeats``, counting read + written bytes.

    A NumPy copy of a buffer much larger than the caches: ``2 * size`` bytes per copy. The copy
    is split across ``threads`` Python threads (NumPy releases the GIL for large copies), because
    one core rarely saturates the memory system. Write-allocate caches may read the destination
    too, so the DRAM traffic can be up to 1.5x the figure: this is what a program can use, which
    is the fair "limit" for a framebuffer that is read and written.
    """
    from concurrent.futures import ThreadPoolExecutor

    n = size_mb * (1 << 20) // 8
    src = np.ones(n, np.float64)
    dst = np.empty_like(src)  # touched by the first copy, so page faults stay out of the timing
    bounds = np.linspace(0, n, threads + 1).astype(np.int64)
    parts = [(dst[a:b], src[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]
    with ThreadPoolExecutor(threads) as pool:
        def copy():
            list(pool.map(lambda p: np.copyto(*p), parts))
        copy()
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            copy()
            times.append(time.perf_counter() - t0)
    return 2 * src.nbytes / statistics.median(times) / 1e9


# ---------------------------------------------------------------------------------------------
# Scenes used by the self-test (benchmarks build their own).

QUAD_VS = """#version 300 es
in vec2 aPos;
void main() { gl_Position = vec4(aPos, 0.0, 1.0); }
"""
COLOR_FS = """#version 300 es
precision mediump float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; }
"""


def fullscreen_quads(layers: int, blend: bool = True, depth: bool = False) -> Scene:
    """``layers`` full-screen quads (two triangles each) of a translucent colour, one draw call."""
    quad = np.array([[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]], np.float32)
    return Scene(QUAD_VS, COLOR_FS, attributes={"aPos": np.tile(quad, (layers, 1))},
                 uniforms={"uColor": (0.2, 0.4, 0.6, 0.25)},
                 state=State(blend=blend, blend_func=("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA"),
                             depth_test=depth, depth_func="LEQUAL"))


def machine_name() -> str:
    """The CPU model, as /proc/cpuinfo names it (results must name their machine)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _selftest() -> None:
    size, layers, repeats = 1024, 100, 15
    # Timings are only as quiet as the machine: print what else was running.
    print(f"machine: {machine_name()}, {os.cpu_count()} CPUs, "
          f"load average {os.getloadavg()[0]:.2f} (1 min)")
    print(f"memory copy bandwidth: {measure_memory_bandwidth():.1f} GB/s (1 thread), "
          f"{measure_memory_bandwidth(threads=os.cpu_count() or 1):.1f} GB/s "
          f"({os.cpu_count()} threads)")
    print(f"scene: {layers} full-screen quads at {size}x{size}, median of {repeats} frames "
          "(clear + draws + glFinish)\n")
    print(f"{'threads':>7}  {'raster thr':>10}  {'blend':>5}  {'depth':>5}  {'median ms':>9}  "
          f"{'min..max ms':>15}  {'Gpix/s':>6}")
    renderer = ""
    for threads in (1, 2):
        with LlvmpipeProcess(size, size, threads) as proc:
            info = proc.info()
            renderer = f"{info['renderer']} / {info['version']}"
            for blend, depth in ((True, False), (False, False), (True, True), (False, True)):
                times = proc.time_draws(fullscreen_quads(layers, blend, depth), repeats)
                t = statistics.median(times)
                span = f"{min(times) * 1e3:.1f}..{max(times) * 1e3:.1f}"
                print(f"{threads:>7}  {info['raster_threads']:>10}  {blend!s:>5}  {depth!s:>5}  "
                      f"{t * 1e3:>9.1f}  {span:>15}  {layers * size * size / t / 1e9:>6.2f}")
    print(f"\nrenderer: {renderer}")


if __name__ == "__main__":
    if "--selftest" in sys.argv[1:]:
        _selftest()
    else:
        print(__doc__)
