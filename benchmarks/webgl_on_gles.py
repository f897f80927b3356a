"""WebGL 2 calls on Mesa llvmpipe: a scene written once with WebGL calls runs on softgl and llvmpipe.

``WebGLOnGLES(width, height, threads, samples)`` is a context object with WebGL's method names,
argument lists and enum names (``gl.createBuffer()``, ``gl.bufferData(gl.ARRAY_BUFFER, array,
gl.STATIC_DRAW)``, ``gl.uniformMatrix4fv(loc, False, flat)``, ``gl.TRIANGLES``), each one mapped to
its OpenGL ES 3.0 function (WebGL 2 is ES 3.0; WebGL 2.0 §1.1). Underneath is reference_gl's
``LlvmpipeRenderer``: its EGL + GLES loading, its ``LP_NUM_THREADS`` handling and its off-screen
framebuffer, which plays the canvas: binding ``None`` to ``FRAMEBUFFER`` binds it, as WebGL's null
framebuffer is the drawing buffer. With ``samples`` > 0 the canvas is multisampled (WebGL's
``antialias: true``) and ``readPixels`` from it reads the resolved colours, as in WebGL.

Only the calls benchmarks/ordinary.py makes are here, and each one does what WebGL's does (no
call is accepted and ignored). WebGL's objects (``WebGLBuffer``, ...) are ``GLName``s holding the
GL name; a uniform location is an int, and ``None`` where WebGL returns null (setting a uniform at
``None`` does nothing, as in WebGL). Errors are GL's: ``getError()``.

``GlesProcess(threads)`` runs such a context in a worker process (llvmpipe reads ``LP_NUM_THREADS``
once per process) and runs a scene there: ``setup(scene_setup, width, height, samples)`` calls
``scene_setup(gl, width, height)`` (a picklable function, e.g. from ordinary.py) which returns the
frame callable; ``time_frames(n)`` times ``frame(); gl.finish()`` n times; ``read_pixels()`` reads
the canvas.
"""
from __future__ import annotations

import ctypes as _c
import time

import numpy as np

try:  # as a script's sibling (python benchmarks/ordinary.py) or as a package module (tests)
    from reference_gl import GL, LlvmpipeRenderer, WorkerProcess
except ImportError:  # pragma: no cover
    from .reference_gl import GL, LlvmpipeRenderer, WorkerProcess

# WebGL's constants used by the scenes (the same numbers as OpenGL ES 3.0's; WebGL 2.0 §3.7).
ENUMS = {name: value for name, value in GL.items()} | {
    "NO_ERROR": 0, "NONE": 0,
    "DEPTH_BUFFER_BIT": 0x0100, "STENCIL_BUFFER_BIT": 0x0400, "COLOR_BUFFER_BIT": 0x4000,
    # capabilities
    "BLEND": 0x0BE2, "DEPTH_TEST": 0x0B71, "CULL_FACE": 0x0B44,
    # buffers
    "ARRAY_BUFFER": 0x8892, "ELEMENT_ARRAY_BUFFER": 0x8893, "STATIC_DRAW": 0x88E4,
    # types
    "BYTE": 0x1400, "UNSIGNED_BYTE": 0x1401, "SHORT": 0x1402, "UNSIGNED_SHORT": 0x1403,
    "INT": 0x1404, "UNSIGNED_INT": 0x1405, "FLOAT": 0x1406,
    # shaders and programs
    "VERTEX_SHADER": 0x8B31, "FRAGMENT_SHADER": 0x8B30, "COMPILE_STATUS": 0x8B81,
    "LINK_STATUS": 0x8B82,
    # textures
    "TEXTURE_2D": 0x0DE1, "TEXTURE_CUBE_MAP": 0x8513, "TEXTURE0": 0x84C0,
    "TEXTURE_CUBE_MAP_POSITIVE_X": 0x8515, "TEXTURE_CUBE_MAP_NEGATIVE_X": 0x8516,
    "TEXTURE_CUBE_MAP_POSITIVE_Y": 0x8517, "TEXTURE_CUBE_MAP_NEGATIVE_Y": 0x8518,
    "TEXTURE_CUBE_MAP_POSITIVE_Z": 0x8519, "TEXTURE_CUBE_MAP_NEGATIVE_Z": 0x851A,
    "TEXTURE_MAG_FILTER": 0x2800, "TEXTURE_MIN_FILTER": 0x2801, "TEXTURE_WRAP_S": 0x2802,
    "TEXTURE_WRAP_T": 0x2803, "TEXTURE_WRAP_R": 0x8072,
    "TEXTURE_COMPARE_MODE": 0x884C, "TEXTURE_COMPARE_FUNC": 0x884D,
    "COMPARE_REF_TO_TEXTURE": 0x884E,
    "PACK_ALIGNMENT": 0x0D05,
    # formats
    "RGB": 0x1907, "RGBA": 0x1908, "RGBA8": 0x8058, "DEPTH_COMPONENT": 0x1902,
    "DEPTH_COMPONENT16": 0x81A5, "DEPTH_COMPONENT24": 0x81A6, "DEPTH_COMPONENT32F": 0x8CAC,
    # framebuffers
    "FRAMEBUFFER": 0x8D40, "READ_FRAMEBUFFER": 0x8CA8, "DRAW_FRAMEBUFFER": 0x8CA9,
    "RENDERBUFFER": 0x8D41, "COLOR_ATTACHMENT0": 0x8CE0, "DEPTH_ATTACHMENT": 0x8D00,
    "FRAMEBUFFER_COMPLETE": 0x8CD5,
}


class GLName:
    """A WebGL object (WebGLBuffer, WebGLTexture, ...): the GL object name it stands for."""
    __slots__ = ("kind", "name")

    def __init__(self, kind: str, name: int):
        self.kind, self.name = kind, name

    def __repr__(self):
        return f"<{self.kind} {self.name}>"


def _name(obj: GLName | None) -> int:
    return 0 if obj is None else obj.name


def _pointer(data) -> tuple[np.ndarray, int]:
    """A NumPy array's bytes as GL reads them (the array, kept alive by the caller, and its address)."""
    if not isinstance(data, np.ndarray):
        raise TypeError(f"expected a NumPy array (an ArrayBufferView), got {type(data).__name__}")
    data = np.ascontiguousarray(data)
    return data, data.ctypes.data


def _floats(data) -> tuple[np.ndarray, int]:
    """Uniform values: a float32 array (WebGL's Float32Array or a sequence of numbers)."""
    arr = np.ascontiguousarray(data, dtype=np.float32).reshape(-1)
    return arr, arr.ctypes.data


class WebGLOnGLES:
    """A WebGL 2 context on llvmpipe (see the module docstring)."""

    def __init__(self, width: int, height: int, threads: int | None = None, samples: int = 0):
        self._renderer = LlvmpipeRenderer(width, height, threads=threads, samples=samples)
        self._gl = self._renderer.gl
        self.drawingBufferWidth, self.drawingBufferHeight = int(width), int(height)
        self.samples = int(samples)
        self._canvas = self._renderer.draw_fbo
        self._read_fb = self._draw_fb = self._canvas   # what READ/DRAW_FRAMEBUFFER hold
        self._gl.glBindFramebuffer(ENUMS["FRAMEBUFFER"], self._canvas)
        self._gl.glViewport(0, 0, width, height)

    def __getattr__(self, name):
        try:
            return ENUMS[name]
        except KeyError:
            raise AttributeError(f"WebGLOnGLES has no {name!r} (the adapter implements only "
                                 "what benchmarks/ordinary.py uses)") from None

    def info(self) -> dict:
        return self._renderer.info()

    def close(self) -> None:
        self._renderer.close()

    def _gen(self, fn, kind: str) -> GLName:
        name = _c.c_uint()
        fn(1, _c.byref(name))
        return GLName(kind, name.value)

    # -- errors and sync ---------------------------------------------------------------------
    def getError(self) -> int:
        return self._gl.glGetError()

    def finish(self) -> None:
        self._gl.glFinish()

    # -- shaders and programs ----------------------------------------------------------------
    def createShader(self, kind: int) -> GLName:
        return GLName("WebGLShader", self._gl.glCreateShader(kind))

    def shaderSource(self, shader: GLName, source: str) -> None:
        src = _c.c_char_p(source.encode())
        self._gl.glShaderSource(shader.name, 1, _c.byref(src), None)

    def compileShader(self, shader: GLName) -> None:
        self._gl.glCompileShader(shader.name)

    def getShaderParameter(self, shader: GLName, pname: int):
        value = _c.c_int()
        self._gl.glGetShaderiv(shader.name, pname, value)
        return bool(value.value) if pname == ENUMS["COMPILE_STATUS"] else value.value

    def getShaderInfoLog(self, shader: GLName) -> str:
        log = _c.create_string_buffer(16384)
        self._gl.glGetShaderInfoLog(shader.name, len(log), None, log)
        return log.value.decode(errors="replace")

    def createProgram(self) -> GLName:
        return GLName("WebGLProgram", self._gl.glCreateProgram())

    def attachShader(self, program: GLName, shader: GLName) -> None:
        self._gl.glAttachShader(program.name, shader.name)

    def linkProgram(self, program: GLName) -> None:
        self._gl.glLinkProgram(program.name)

    def getProgramParameter(self, program: GLName, pname: int):
        value = _c.c_int()
        self._gl.glGetProgramiv(program.name, pname, value)
        return bool(value.value) if pname == ENUMS["LINK_STATUS"] else value.value

    def getProgramInfoLog(self, program: GLName) -> str:
        log = _c.create_string_buffer(16384)
        self._gl.glGetProgramInfoLog(program.name, len(log), None, log)
        return log.value.decode(errors="replace")

    def useProgram(self, program: GLName | None) -> None:
        self._gl.glUseProgram(_name(program))

    def getAttribLocation(self, program: GLName, name: str) -> int:
        return self._gl.glGetAttribLocation(program.name, name.encode())

    def getUniformLocation(self, program: GLName, name: str) -> int | None:
        loc = self._gl.glGetUniformLocation(program.name, name.encode())
        return None if loc < 0 else loc

    # -- uniforms (a None location is ignored, as WebGL's null location) ----------------------
    def uniform1i(self, loc, x) -> None:
        if loc is not None:
            self._gl.glUniform1i(loc, int(x))

    def uniform1f(self, loc, x) -> None:
        if loc is not None:
            self._gl.glUniform1f(loc, x)

    def uniform2f(self, loc, x, y) -> None:
        if loc is not None:
            self._gl.glUniform2f(loc, x, y)

    def uniform3f(self, loc, x, y, z) -> None:
        if loc is not None:
            self._gl.glUniform3f(loc, x, y, z)

    def uniform4f(self, loc, x, y, z, w) -> None:
        if loc is not None:
            self._gl.glUniform4f(loc, x, y, z, w)

    def _uniform_fv(self, fn, comps: int, loc, data) -> None:
        if loc is not None:
            arr, ptr = _floats(data)
            fn(loc, arr.size // comps, ptr)

    def uniform3fv(self, loc, data) -> None:
        self._uniform_fv(self._gl.glUniform3fv, 3, loc, data)

    def uniformMatrix3fv(self, loc, transpose: bool, data) -> None:
        if loc is not None:
            arr, ptr = _floats(data)
            self._gl.glUniformMatrix3fv(loc, arr.size // 9, bool(transpose), ptr)

    def uniformMatrix4fv(self, loc, transpose: bool, data) -> None:
        if loc is not None:
            arr, ptr = _floats(data)
            self._gl.glUniformMatrix4fv(loc, arr.size // 16, bool(transpose), ptr)

    # -- buffers and vertex arrays -----------------------------------------------------------
    def createBuffer(self) -> GLName:
        return self._gen(self._gl.glGenBuffers, "WebGLBuffer")

    def bindBuffer(self, target: int, buffer: GLName | None) -> None:
        self._gl.glBindBuffer(target, _name(buffer))

    def bufferData(self, target: int, data, usage: int) -> None:
        arr, ptr = _pointer(data)
        self._gl.glBufferData(target, arr.nbytes, ptr, usage)

    def createVertexArray(self) -> GLName:
        return self._gen(self._gl.glGenVertexArrays, "WebGLVertexArrayObject")

    def bindVertexArray(self, vao: GLName | None) -> None:
        self._gl.glBindVertexArray(_name(vao))

    def enableVertexAttribArray(self, index: int) -> None:
        self._gl.glEnableVertexAttribArray(index)

    def vertexAttribPointer(self, index: int, size: int, type: int, normalized: bool,
                            stride: int, offset: int) -> None:
        self._gl.glVertexAttribPointer(index, size, type, bool(normalized), stride,
                                       _c.c_void_p(offset))

    def vertexAttribDivisor(self, index: int, divisor: int) -> None:
        self._gl.glVertexAttribDivisor(index, divisor)

    # -- textures ----------------------------------------------------------------------------
    def createTexture(self) -> GLName:
        return self._gen(self._gl.glGenTextures, "WebGLTexture")

    def activeTexture(self, unit: int) -> None:
        self._gl.glActiveTexture(unit)

    def bindTexture(self, target: int, texture: GLName | None) -> None:
        self._gl.glBindTexture(target, _name(texture))

    def texImage2D(self, target: int, level: int, internalformat: int, width: int, height: int,
                   border: int, format: int, type: int, pixels) -> None:
        """WebGL 2's (..., width, height, border, format, type, pixels): pixels a NumPy array
        (rows from the bottom, as GL reads them) or None (storage only)."""
        if pixels is None:
            arr, ptr = None, None
        else:
            arr, ptr = _pointer(pixels)
        self._gl.glTexImage2D(target, level, internalformat, width, height, border, format, type,
                              ptr)

    def texParameteri(self, target: int, pname: int, param: int) -> None:
        self._gl.glTexParameteri(target, pname, param)

    def generateMipmap(self, target: int) -> None:
        self._gl.glGenerateMipmap(target)

    # -- framebuffers and renderbuffers ------------------------------------------------------
    def createFramebuffer(self) -> GLName:
        return self._gen(self._gl.glGenFramebuffers, "WebGLFramebuffer")

    def bindFramebuffer(self, target: int, framebuffer: GLName | None) -> None:
        fbo = self._canvas if framebuffer is None else framebuffer.name
        self._gl.glBindFramebuffer(target, fbo)
        if target in (ENUMS["FRAMEBUFFER"], ENUMS["READ_FRAMEBUFFER"]):
            self._read_fb = fbo
        if target in (ENUMS["FRAMEBUFFER"], ENUMS["DRAW_FRAMEBUFFER"]):
            self._draw_fb = fbo

    def framebufferTexture2D(self, target: int, attachment: int, textarget: int,
                             texture: GLName | None, level: int) -> None:
        self._gl.glFramebufferTexture2D(target, attachment, textarget, _name(texture), level)

    def createRenderbuffer(self) -> GLName:
        return self._gen(self._gl.glGenRenderbuffers, "WebGLRenderbuffer")

    def bindRenderbuffer(self, target: int, renderbuffer: GLName | None) -> None:
        self._gl.glBindRenderbuffer(target, _name(renderbuffer))

    def renderbufferStorage(self, target: int, internalformat: int, width: int, height: int) -> None:
        self._gl.glRenderbufferStorage(target, internalformat, width, height)

    def renderbufferStorageMultisample(self, target: int, samples: int, internalformat: int,
                                       width: int, height: int) -> None:
        self._gl.glRenderbufferStorageMultisample(target, samples, internalformat, width, height)

    def framebufferRenderbuffer(self, target: int, attachment: int, rbtarget: int,
                                renderbuffer: GLName | None) -> None:
        self._gl.glFramebufferRenderbuffer(target, attachment, rbtarget, _name(renderbuffer))

    def checkFramebufferStatus(self, target: int) -> int:
        return self._gl.glCheckFramebufferStatus(target)

    def blitFramebuffer(self, srcX0, srcY0, srcX1, srcY1, dstX0, dstY0, dstX1, dstY1,
                        mask: int, filter: int) -> None:
        self._gl.glBlitFramebuffer(srcX0, srcY0, srcX1, srcY1, dstX0, dstY0, dstX1, dstY1,
                                   mask, filter)

    def readPixels(self, x: int, y: int, width: int, height: int, format: int, type: int,
                   pixels: np.ndarray | None = None):
        """RGBA / UNSIGNED_BYTE into ``pixels`` or a new (height, width, 4) uint8 array, row 0 at
        the bottom. From a multisampled canvas, the resolved colours (as WebGL reads them)."""
        if (format, type) != (ENUMS["RGBA"], ENUMS["UNSIGNED_BYTE"]):
            raise ValueError("the adapter reads RGBA / UNSIGNED_BYTE only")
        out = np.empty((height, width, 4), np.uint8) if pixels is None else pixels
        if out.dtype != np.uint8 or out.size < width * height * 4 or not out.flags.c_contiguous:
            raise ValueError("pixels must be a contiguous uint8 array of width * height * 4")
        gl, r = self._gl, self._renderer
        source = self._read_fb
        if source == self._canvas and self.samples:
            # The multisampled canvas: resolve into the renderer's single-sampled buffer first.
            gl.glBindFramebuffer(ENUMS["READ_FRAMEBUFFER"], self._canvas)
            gl.glBindFramebuffer(ENUMS["DRAW_FRAMEBUFFER"], r.resolve_fbo)
            w, h = self.drawingBufferWidth, self.drawingBufferHeight
            gl.glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, ENUMS["COLOR_BUFFER_BIT"], ENUMS["NEAREST"])
            source = r.resolve_fbo
        gl.glBindFramebuffer(ENUMS["READ_FRAMEBUFFER"], source)
        gl.glPixelStorei(ENUMS["PACK_ALIGNMENT"], 1)
        gl.glReadPixels(x, y, width, height, format, type, out.ctypes.data)
        gl.glPixelStorei(ENUMS["PACK_ALIGNMENT"], 4)   # WebGL's default, restored
        gl.glBindFramebuffer(ENUMS["READ_FRAMEBUFFER"], self._read_fb)
        gl.glBindFramebuffer(ENUMS["DRAW_FRAMEBUFFER"], self._draw_fb)
        return out if pixels is None else None

    # -- state -------------------------------------------------------------------------------
    def viewport(self, x: int, y: int, width: int, height: int) -> None:
        self._gl.glViewport(x, y, width, height)

    def enable(self, cap: int) -> None:
        self._gl.glEnable(cap)

    def disable(self, cap: int) -> None:
        self._gl.glDisable(cap)

    def clearColor(self, r, g, b, a) -> None:
        self._gl.glClearColor(r, g, b, a)

    def clear(self, mask: int) -> None:
        self._gl.glClear(mask)

    def blendFunc(self, sfactor: int, dfactor: int) -> None:
        self._gl.glBlendFunc(sfactor, dfactor)

    # -- drawing -----------------------------------------------------------------------------
    def drawArrays(self, mode: int, first: int, count: int) -> None:
        self._gl.glDrawArrays(mode, first, count)

    def drawElements(self, mode: int, count: int, type: int, offset: int) -> None:
        self._gl.glDrawElements(mode, count, type, _c.c_void_p(offset))

    def drawArraysInstanced(self, mode: int, first: int, count: int, instanceCount: int) -> None:
        self._gl.glDrawArraysInstanced(mode, first, count, instanceCount)



# ---------------------------------------------------------------------------------------------
# One process per thread count (llvmpipe reads LP_NUM_THREADS once per process).

def _worker_main(conn, threads: int) -> None:
    """Child process: hold one scene at a time and answer requests until told to stop."""
    gl = frame = None
    while True:
        method, args = conn.recv()
        if method == "close":
            break
        try:
            if method == "setup":
                scene_setup, width, height, samples = args
                if gl is not None:
                    gl.close()
                    gl = frame = None
                gl = WebGLOnGLES(width, height, threads=threads, samples=samples)
                frame = scene_setup(gl, width, height)
                _check(gl, "setup")
                result = gl.info()
            elif method == "time_frames":
                (n,) = args
                result, clock = [], time.perf_counter
                for _ in range(n):
                    t0 = clock()
                    frame()
                    gl.finish()
                    result.append(clock() - t0)
                _check(gl, "frame")
            elif method == "render":
                frame()
                _check(gl, "frame")
                gl.bindFramebuffer(gl.FRAMEBUFFER, None)
                result = gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight,
                                       gl.RGBA, gl.UNSIGNED_BYTE)
                _check(gl, "readPixels")
            else:
                raise ValueError(f"unknown request {method!r}")
            conn.send(("ok", result))
        except BaseException as e:  # report why, instead of a silent dead child
            conn.send(("error", e))
    if gl is not None:
        gl.close()


def _check(gl: WebGLOnGLES, what: str) -> None:
    err = gl.getError()
    if err:
        raise RuntimeError(f"llvmpipe: GL error 0x{err:x} in {what}")


class GlesProcess(WorkerProcess):
    """A WebGLOnGLES context in its own process with LP_NUM_THREADS=threads; one scene at a time.

    ``setup(scene_setup, width, height, samples=0)`` makes a new context of that canvas size and
    runs ``scene_setup(gl, width, height)`` there (it must be picklable: a module-level function);
    it returns the renderer's ``info()``. ``time_frames(n)``: the wall time of each of n frames
    (``frame(); gl.finish()``). ``render()``: one frame, then the canvas as (h, w, 4) uint8.
    A GL error in the child raises RuntimeError here.
    """

    def __init__(self, threads: int):
        super().__init__(_worker_main, threads)
        self.threads = threads

    def setup(self, scene_setup, width: int, height: int, samples: int = 0) -> dict:
        return self._call("setup", scene_setup, width, height, samples)

    def time_frames(self, n: int) -> list[float]:
        return self._call("time_frames", n)

    def render(self) -> np.ndarray:
        return self._call("render")
