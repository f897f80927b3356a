"""The rendering context: WebGLRenderingContext (version=1) and WebGL2RenderingContext (version=2)."""
from __future__ import annotations

import sys
import warnings
import weakref

import numpy as np

from . import _blendlab_ext, _core
from .errors import Float64Warning, GLError, GLWarning

_ATTRIBUTE_DEFAULTS = dict(alpha=True, depth=True, stencil=False, antialias=True,
                           premultipliedAlpha=True, preserveDrawingBuffer=False,
                           powerPreference="default", failIfMajorPerformanceCaveat=False,
                           desynchronized=False)


def _check_argument(name: str, value, kind: type):
    """Context()'s arguments by the rules of the methods' (cpp/bindings/arguments.h): an int is
    an int (not a float, not a bool), a bool is True/False or a number by its truth value (as JS's
    ToBoolean, but never a string), a str is a str. A TypeError names the parameter."""
    if kind is int:
        ok = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
        what = "an int"
    elif kind is bool:
        ok = value is None or isinstance(value, (bool, int, float, np.bool_, np.integer, np.floating))
        what = "a bool"
    else:
        ok = isinstance(value, str)
        what = "a str"
    if not ok:
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        raise TypeError(f"Context: {name} must be {what}; got {type(value).__name__} {shown}")


def _caller_level() -> int:
    # The warning points at the user's line: past the listener and this module's wrappers
    # (bufferData, texImage2D, ... below), so it shows once per call site.
    level, frame = 2, sys._getframe(2)
    while frame is not None and frame.f_code.co_filename == __file__:
        level, frame = level + 1, frame.f_back
    return level


def _error_listener(strict: bool):
    # Holds no reference to the context, so contexts are freed as soon as they are unused.
    if strict:
        def listener(code, call, reason):
            raise GLError(code, call, reason)
    else:
        def listener(code, call, reason):
            warnings.warn(GLWarning(code, call, reason), stacklevel=_caller_level())
    return listener


def _float64_array(values) -> bool:
    return any(type(v) is np.ndarray and v.dtype.char == "d" for v in values)


def _float64_met(gl, call: str, texture_type=None):
    # stacklevel 3: the user's line that called gl.<call>, so the warning shows once per call site.
    if texture_type is None or texture_type == gl.FLOAT:
        message = (f"{call}: a float64 NumPy array is taken as its 8-byte doubles (WebGL takes "
                   f"the bytes as they are), but WebGL reads 32-bit floats: pass "
                   f"np.asarray(data, np.float32)")
    else:
        message = (f"{call}: a float64 NumPy array is not a WebGL pixel array: pass the array "
                   f"type of `type` (np.uint8 for UNSIGNED_BYTE, np.float32 for FLOAT)")
    if gl._strict:
        raise TypeError(message)
    warnings.warn(message, Float64Warning, stacklevel=3)


def _column_major(value):
    """A matrix in math layout M[row, col] (2-D, or an array of them) -> WebGL's column-major
    floats; anything else (flat sequences) is passed as it is."""
    if type(value) is np.ndarray and value.ndim >= 2 and value.dtype.kind in "biuf":
        return np.ascontiguousarray(np.swapaxes(value, -1, -2), np.float32).reshape(-1)
    return value   # the array intake refuses what is not numbers (docs/reliability.md, "Array intake")


def _matrix_setter(name: str):
    core_setter = getattr(_core.Context, name)

    def setter(self, location, transpose, data, *args, **kwargs):
        return core_setter(self, location, transpose, _column_major(data), *args, **kwargs)

    setter.__name__ = setter.__qualname__ = name
    setter.__doc__ = (core_setter.__doc__ + "\n"
                      "A flat sequence of floats is column-major, as in WebGL. A 2-D NumPy array "
                      "(or an array of matrices, shape (..., rows, columns)) is taken in math "
                      "layout ``M[row, col]``, as softgl.transforms returns it: it is sent as "
                      "``M.T.ravel()``. ``transpose`` (WebGL 2 only) then applies as in WebGL.")
    return setter


def _float64_checked(name: str):
    """The C++ method `name` (positional or keyword arguments, its WebGL signatures in the
    docstring), warning first when a float64 array is among its arguments (_float64_met)."""
    core_method = getattr(_core.Context, name)
    textures = name.startswith("tex")

    def method(self, *args, **kwargs):
        if _float64_array(args) or _float64_array(kwargs.values()):
            texture_type = (args[7] if len(args) >= 9 else kwargs.get("type")) if textures else None
            _float64_met(self, name, texture_type)
        return core_method(self, *args, **kwargs)

    method.__name__ = method.__qualname__ = name
    method.__doc__ = (core_method.__doc__ + "\nA float64 NumPy array warns (softgl.Float64Warning; "
                      "strict=True raises): WebGL takes its bytes as they are, so write np.float32.")
    return method


class Canvas:
    """``gl.canvas``: the canvas's ``width`` and ``height``. Setting either one makes a new
    drawing buffer of that size with its initial contents, as a browser does; the viewport and
    scissor stay as they were (WebGL 1.0 §2.2)."""

    def __init__(self, gl):
        self._gl = weakref.ref(gl)   # no cycle: the context keeps its canvas

    def _context(self):
        gl = self._gl()
        if gl is None:
            raise ReferenceError("this canvas's context no longer exists")
        return gl

    @property
    def width(self) -> int:
        return self._context().drawingBufferWidth

    @width.setter
    def width(self, value: int):
        gl = self._context()
        gl._resize(int(value), gl.drawingBufferHeight)

    @property
    def height(self) -> int:
        return self._context().drawingBufferHeight

    @height.setter
    def height(self, value: int):
        gl = self._context()
        gl._resize(gl.drawingBufferWidth, int(value))

    def __repr__(self):
        return f"<softgl canvas {self.width}x{self.height}>"


class Extension:
    """An object returned by getExtension: its constants (e.g. MIN_EXT) and functions."""

    def __init__(self, name: str, constants: dict):
        self.name = name
        self.__dict__.update(constants)

    def __repr__(self):
        return f"<softgl extension {self.name}>"


_EXTENSION_CONSTANTS = {
    "EXT_blend_minmax": {"MIN_EXT": 0x8007, "MAX_EXT": 0x8008},
    "OES_vertex_array_object": {"VERTEX_ARRAY_BINDING_OES": 0x85B5},
    "ANGLE_instanced_arrays": {"VERTEX_ATTRIB_ARRAY_DIVISOR_ANGLE": 0x88FE},
    # softgl's fog: OpenGL 1.x enum values (docs/architecture.md, "The blend lab").
    "SOFTGL_fog": {"FOG": 0x0B60, "FOG_DENSITY": 0x0B62, "FOG_START": 0x0B63, "FOG_END": 0x0B64,
                   "FOG_MODE": 0x0B65, "FOG_COLOR": 0x0B66, "LINEAR": 0x2601, "EXP": 0x0800,
                   "EXP2": 0x0801, "FOG_COORDINATE_SOURCE": 0x8450, "FRAGMENT_DEPTH": 0x8452,
                   "WINDOW_DEPTH_SOFTGL": 0x1D000, "FOG_BLEND_AWARE_SOFTGL": 0x1D001},
    # softgl's area-averaged antialiasing: OpenGL 1.x smoothing enums.
    "SOFTGL_smooth": {"POINT_SMOOTH": 0x0B10, "LINE_SMOOTH": 0x0B20, "POLYGON_SMOOTH": 0x0B41,
                      "POINT_SMOOTH_HINT": 0x0C51, "LINE_SMOOTH_HINT": 0x0C52,
                      "POLYGON_SMOOTH_HINT": 0x0C53, "SMOOTH_LINE_WIDTH_RANGE": 0x0B22},
    **_blendlab_ext.CONSTANTS,   # SOFTGL_exact_transparency, SOFTGL_introspection
    # Textures and framebuffers
    "OES_texture_half_float": {"HALF_FLOAT_OES": 0x8D61},
    # Shaders and filtering (values from the WebGL extension registry's IDL)
    "OES_standard_derivatives": {"FRAGMENT_SHADER_DERIVATIVE_HINT_OES": 0x8B8B},
    "EXT_texture_filter_anisotropic": {"TEXTURE_MAX_ANISOTROPY_EXT": 0x84FE, "MAX_TEXTURE_MAX_ANISOTROPY_EXT": 0x84FF},
    "WEBGL_depth_texture": {"UNSIGNED_INT_24_8_WEBGL": 0x84FA},
    "WEBGL_color_buffer_float": {"RGBA32F_EXT": 0x8814, "FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE_EXT": 0x8211,
                                 "UNSIGNED_NORMALIZED_EXT": 0x8C17},
    # WEBGL_draw_buffers: the WebGL 2 values (COLOR_ATTACHMENTi, DRAW_BUFFERi, MAX_*).
    "WEBGL_draw_buffers": {**{f"COLOR_ATTACHMENT{i}_WEBGL": 0x8CE0 + i for i in range(16)},
                           **{f"DRAW_BUFFER{i}_WEBGL": 0x8825 + i for i in range(16)},
                           "MAX_COLOR_ATTACHMENTS_WEBGL": 0x8CDF, "MAX_DRAW_BUFFERS_WEBGL": 0x8824},
    "EXT_color_buffer_half_float": {"RGBA16F_EXT": 0x881A, "RGB16F_EXT": 0x881B,
                                    "FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE_EXT": 0x8211,
                                    "UNSIGNED_NORMALIZED_EXT": 0x8C17},
}


def _extension_functions(name: str, gl) -> dict:
    """The functions of an extension object; they hold the context weakly (no cycles)."""
    ref = weakref.ref(gl)
    core = _core.Context
    if name == "OES_vertex_array_object":
        return {"createVertexArrayOES": lambda: core.createVertexArray(ref()),
                "bindVertexArrayOES": lambda vao: core.bindVertexArray(ref(), vao),
                "deleteVertexArrayOES": lambda vao: core.deleteVertexArray(ref(), vao),
                "isVertexArrayOES": lambda vao: core.isVertexArray(ref(), vao)}
    if name == "SOFTGL_fog":
        def fogfv(pname, values):
            core._fog(ref(), "fogfv", pname, values)
        return {"fogf": lambda pname, value: core._fog(ref(), "fogf", pname, [float(value)]),
                "fogi": lambda pname, value: core._fog(ref(), "fogi", pname, [float(value)]),
                "fogfv": fogfv}
    if name in _blendlab_ext.CONSTANTS:
        return _blendlab_ext.functions(name, gl)
    if name == "WEBGL_draw_buffers":
        return {"drawBuffersWEBGL": lambda buffers: core._drawBuffersWEBGL(ref(), buffers)}
    if name == "ANGLE_instanced_arrays":
        return {"drawArraysInstancedANGLE":
                lambda mode, first, count, n: core.drawArraysInstanced(ref(), mode, first, count, n),
                "drawElementsInstancedANGLE":
                lambda mode, count, type, offset, n: core.drawElementsInstanced(ref(), mode, count, type, offset, n),
                "vertexAttribDivisorANGLE":
                lambda index, divisor: core.vertexAttribDivisor(ref(), index, divisor)}
    return {}


# softgl's extensions that only an RGBA8 drawing buffer offers (lower case, as getExtension matches).
_BLEND_LAB_EXTENSIONS = {n.lower() for n in _blendlab_ext.CONSTANTS}

# Entry points that exist only on WebGL2RenderingContext.
WEBGL2_ONLY = ["copyBufferSubData", "getBufferSubData", "vertexAttribIPointer", "vertexAttribI4i",
               "vertexAttribI4ui", "vertexAttribI4iv", "vertexAttribI4uiv", "vertexAttribDivisor",
               "createVertexArray", "bindVertexArray", "deleteVertexArray", "isVertexArray",
               "drawArraysInstanced", "drawElementsInstanced", "drawRangeElements",
               "uniform1ui", "uniform2ui", "uniform3ui", "uniform4ui",
               "uniform1uiv", "uniform2uiv", "uniform3uiv", "uniform4uiv",
               "uniformMatrix2x3fv", "uniformMatrix2x4fv", "uniformMatrix3x2fv",
               "uniformMatrix3x4fv", "uniformMatrix4x2fv", "uniformMatrix4x3fv",
               # Textures and framebuffers
               "texImage3D", "texSubImage3D", "texStorage2D", "texStorage3D", "copyTexSubImage3D",
               "createSampler", "deleteSampler", "isSampler", "bindSampler", "samplerParameteri",
               "samplerParameterf", "getSamplerParameter", "framebufferTextureLayer",
               "renderbufferStorageMultisample", "readBuffer", "blitFramebuffer", "clearBufferfv",
               "clearBufferiv", "clearBufferuiv", "clearBufferfi", "drawBuffers", "invalidateFramebuffer",
               "invalidateSubFramebuffer"]


class Context(_core.Context):
    """A WebGL rendering context drawing into a software drawing buffer.

    ``Context(width=300, height=150, **attributes)`` takes WebGL's context attributes with
    WebGL's defaults (alpha, depth, stencil, antialias, premultipliedAlpha,
    preserveDrawingBuffer, powerPreference, failIfMajorPerformanceCaveat, desynchronized) and
    softgl's own options: ``version`` (1 or 2, default 2), ``samples`` (2, 4, 8 or 16 with
    antialias; default 4), ``threads`` (drawing threads, default one per core; the bytes drawn
    never depend on it), ``color_format`` (the drawing buffer's colour format: ``'rgba8'``, as
    WebGL, or ``'rgba16f'`` / ``'rgba32f'``: float blending without clamping, read with
    ``readPixels(..., RGBA, FLOAT)``) and ``strict`` (raise GLError instead of warning GLWarning).

    The methods are WebGL's, with WebGL's parameter names (``help(gl.drawArrays)``); README.md
    says what softgl chooses where WebGL leaves a choice, docs/ how it works.
    """

    _version = None   # fixed by the subclasses

    def __new__(cls, *args, version: int | None = None, **kwargs):
        if cls is Context:
            cls = WebGLRenderingContext if version == 1 else WebGL2RenderingContext
        return _core.Context.__new__(cls)

    def __init__(self, width: int = 300, height: int = 150, *, version: int | None = None,
                 samples: int | None = None, threads: int | None = None, strict: bool = False,
                 color_format: str = "rgba8", **attributes):
        if version is None:
            version = self._version
        elif version != self._version and version in (1, 2):
            raise ValueError(f"{type(self).__name__} is WebGL {self._version}, not version={version}")
        unknown = set(attributes) - set(_ATTRIBUTE_DEFAULTS)
        if unknown:
            raise TypeError(f"Context() got unexpected keyword argument(s): {', '.join(sorted(unknown))}")
        for name in ("width", "height"):
            _check_argument(name, locals()[name], int)
        for name, value in (("version", version), ("samples", samples), ("threads", threads)):
            if value is not None:
                _check_argument(name, value, int)
        _check_argument("strict", strict, bool)
        _check_argument("color_format", color_format, str)
        attrs = _core.ContextAttributes()
        for name, default in _ATTRIBUTE_DEFAULTS.items():
            value = attributes.get(name, default)
            _check_argument(name, value, type(default))
            setattr(attrs, name, bool(value) if type(default) is bool else value)
        attrs.version = version
        attrs.samples = 0 if samples is None else samples
        attrs.threads = 0 if threads is None else threads
        attrs.color_format = color_format
        if not (-2**31 <= width < 2**31 and -2**31 <= height < 2**31):
            raise ValueError(f"drawing buffer size {width}x{height} is out of range")
        reason = _core.check_context(width, height, attrs)
        if reason:
            raise ValueError(f"softgl.Context: {reason}")
        super().__init__(width, height, attrs)
        self._strict = bool(strict)
        self._extensions = {}
        self._set_error_listener(_error_listener(self._strict))

    # -- WebGL API implemented in Python (no per-pixel work) ---------------------------------

    def getContextAttributes(self) -> dict:
        """The attributes the context was made with, as WebGL's dictionary."""
        a = self._attributes()
        attributes = {name: getattr(a, name) for name in _ATTRIBUTE_DEFAULTS} | {"xrCompatible": False}
        # softgl's float drawing buffers are reported; the default (rgba8) is not, so that pure
        # WebGL code sees exactly WebGL's dictionary.
        if a.color_format != "rgba8":
            attributes["color_format"] = a.color_format
        return attributes

    def getExtension(self, name: str):
        """The extension object (always the same one), or None if softgl does not support it."""
        if not isinstance(name, str):
            raise TypeError(f"getExtension: name must be a str; got {type(name).__name__} {name!r:.40}")
        if name in self._extensions:
            return self._extensions[name]
        supported = {n.lower(): n for n in self.getSupportedExtensions()}
        canonical = supported.get(name.lower())   # extension names match case-insensitively
        if canonical is None and name.lower() in _BLEND_LAB_EXTENSIONS:
            # WebGL answers null; say why, since the name is one softgl offers elsewhere.
            fmt = self._attributes().color_format
            warnings.warn(f"getExtension({name!r}): None on a color_format={fmt!r} context: the blend "
                          "lab records and resolves RGBA8 drawing-buffer colours; create the context "
                          "with color_format='rgba8' (the default) to use it", UserWarning, stacklevel=2)
        if canonical is None or not self._enable_extension(canonical):
            return None
        ext = Extension(canonical, _EXTENSION_CONSTANTS.get(canonical, {}) |
                        _extension_functions(canonical, self))
        self._extensions[name] = self._extensions[canonical] = ext
        return ext

    def set_work_budget(self, draw: int | None = None, compile: int | None = None) -> None:
        """Sets the work budget of each draw and of each compile or link, in units of about one
        GLSL instruction on one vertex or fragment (docs/reliability.md, "Work budget and
        Ctrl-C"). A call that exceeds it stops, changes nothing and records OUT_OF_MEMORY."""
        for name, value in (("draw", draw), ("compile", compile)):
            if value is not None and (not isinstance(value, int) or isinstance(value, bool) or not 1 <= value < 2**64):
                raise ValueError(f"set_work_budget: {name} must be an int from 1 to 2**64 - 1, got {value!r}")
        self._set_work_budget(draw or 0, compile or 0)

    def work_budget(self) -> dict:
        """The work budgets (set_work_budget) and the units the last draw, compile or link used."""
        draw, compile, used = self._work_budget()
        return {"draw": draw, "compile": compile, "last_call_used": used}

    def set_memory_budget(self, bytes: int | None) -> None:
        """Sets the bytes this context's buffers, textures, renderbuffers and drawing buffer may
        hold together (None: the default, half of the machine's memory). A call that would pass
        it, or the process-wide limit (``softgl._core.set_memory_limit``), records OUT_OF_MEMORY
        and changes nothing (docs/reliability.md, "Memory"). Lowering it frees nothing."""
        if bytes is not None and (not isinstance(bytes, int) or isinstance(bytes, bool) or not 1 <= bytes < 2**64):
            raise ValueError(f"set_memory_budget: bytes must be None or an int from 1 to 2**64 - 1, got {bytes!r}")
        self._set_memory_budget(bytes or 0)

    def memory_budget(self) -> dict:
        """This context's memory limit and the bytes its objects hold now, and the same for the
        whole process (all contexts)."""
        limit, in_use, process_limit, process_in_use = self._memory_budget()
        return {"limit": limit, "in_use": in_use, "process_limit": process_limit, "process_in_use": process_in_use}

    def stats(self, reset: bool = False) -> dict:
        """softgl's counters since the context was made (or last reset): what the draws did and
        what they skipped (docs/architecture.md, "Fast paths"), with seconds per stage.

        A draw runs in batches of 65,536 primitives (bounded memory). ``tiles_touched`` counts
        the tiles a draw has work in once per draw, however many of its batches reach a tile.
        ``vertices_shaded`` counts vertex shader runs: each distinct vertex once per instance
        and batch, so in a draw of more batches than one, a vertex whose primitives fall in two
        batches (a strip's two vertices at a boundary, a fan's centre, an index reused far
        apart) counts in each.

        ``fragments_hidden`` counts fragments that passed the tests but were not shaded, because
        a later primitive of the same draw covers their pixel and nothing blends (hidden-surface
        removal, single-sampled targets, in tiles where primitives pile up): the bytes are the
        same as when every fragment is shaded. Hidden fragments are not charged to the draw's work
        budget (set_work_budget).
        ``tiles_hidden_surface`` counts the (tile, batch) pairs where that removal's first pass ran
        (where the pixels a draw's primitives may cover add up to twice the tile or more).

        ``primitives_depth_hidden`` counts (primitive, tile) pairs that were neither rasterized
        nor tested, because the tile's stored depth words show that every fragment of the
        primitive there fails the early depth test (single-sampled LESS, LEQUAL, GREATER or
        GEQUAL on the drawing buffer without smoothing, primitives whose bounding box covers at
        least 256 pixels of the tile): their fragments are in no other counter (not in
        ``fragments_killed_early`` nor ``quads``); the bytes are the same as when they are
        tested.

        ``texture_queries_fast`` counts texture lookups served by the sampler's 2D fast path
        (filtered lookups of one 2D or 2D array texture of a float-sampled colour format), one per
        shader instruction and batch of lanes, not per lane; the other lookups take the general
        path, with the same bits.

        The ``draws_*`` counters count draws by kind, once per draw (see ``last_draw_plan``):
        ``draws_skipped_no_output`` (nothing writable), ``draws_plain_write`` (no destination
        read), ``draws_early_depth`` and ``draws_late_tests`` (depth/stencil before or after
        the shader), ``draws_per_lane_color`` (colour blended lane by lane: blend lab, fog,
        coverage operations, smoothing, framebuffer objects, late tests), and, for draws that
        reached their first tile pass, ``draws_constant_color`` (a uniform-only shader run once,
        its colour straight to the colour kernels), ``draws_blend_table`` (that colour blended by
        table lookup), ``draws_copied_varying`` (a shader that only copies varyings or
        constants to its colours, not run) and ``draws_flat_primitives`` (a shader that can run
        once for a primitive whose varyings are equal at every vertex; ``fragments_flat`` counts
        the fragments, of ``fragments_shaded``, that got such a primitive's one colour), and
        ``draws_texture_copy`` (a shader that is one texture lookup, served by the sampler without
        the executor; ``draws_texel_words`` those whose NEAREST texels' bytes went to the pixels
        as they are, or a LINEAR level's bytes from its integer sums). ``blocks_depth_in_place`` counts the 8x8 blocks a depth-only draw's
        primitives cover whole, depth-tested without quads; ``quads_blended_in_place`` the quads
        whose pixels the colour kernels blended straight in the buffer. ``draws_with_rollback`` counts draws that kept a copy
        of each tile they wrote, to put it back if stopped (docs/reliability.md, "Work budget
        and Ctrl-C": draws in several batches, with a fragment loop of unknown length, or with
        much fragment work)."""
        if not isinstance(reset, (bool, np.bool_, int)):
            raise TypeError(f"stats: reset must be a bool; got {type(reset).__name__} {reset!r:.40}")
        return self._stats(reset)

    def last_draw_plan(self) -> dict | None:
        """The plan of this context's last draw call (docs/architecture.md, "The draw plan"):
        which kernels and fast paths it took, and for each fast path it did not take, why not.
        None before the first draw.

        A dict of field -> value. Yes/no fields are bools, counts ints, kinds strings
        (``primitives``: 'points', 'lines' or 'triangles'; ``skip``: 'no',
        'rasterizer_discard' or 'no_output'; ``target``; ``simd``; ``kernel``: 'plain',
        'alpha_over', 'additive' or 'generic'). Each fast path (``tests_before_shading``,
        ``quad_depth``, ``depth_bounds``, ``hidden_surface_removal``, ``fragment_copies``,
        ``fused_copy``, ``constant_color``, ``blend_table``, ``whole_rect_blend``,
        ``fragment_batches``, ``no_helper_lanes``, ``depth_only``,
        ``color_kernels``) is True when taken, and ``<path>_why_not`` names the first reason it
        was not (e.g. 'stencil_test', 'blend_lab', 'tuning_off'), or is None. The fields under
        ``shaded`` (``uniform_only``, ``constant_color``, ``blend_table``, ``whole_rect_blend``)
        are decided when the draw's first tile pass starts, as the shader runs once; a draw that
        rasterized nothing leaves them 'not_rasterized' or 'not_shaded'. ``hash`` is the plan's
        hash (equal plans, equal hashes) and ``text`` the plan printed, one line per stage
        (``print(gl.last_draw_plan()["text"])``)."""
        return self._last_draw_plan()

    # -- float64 arrays: WebGL's byte semantics stay, with a warning (softgl.Float64Warning) ----

    bufferData = _float64_checked("bufferData")
    bufferSubData = _float64_checked("bufferSubData")
    texImage2D = _float64_checked("texImage2D")
    texSubImage2D = _float64_checked("texSubImage2D")

    # Matrices: 2-D arrays in math layout, flat sequences column-major (see _matrix_setter).
    uniformMatrix2fv = _matrix_setter("uniformMatrix2fv")
    uniformMatrix3fv = _matrix_setter("uniformMatrix3fv")
    uniformMatrix4fv = _matrix_setter("uniformMatrix4fv")
    uniformMatrix2x3fv = _matrix_setter("uniformMatrix2x3fv")
    uniformMatrix2x4fv = _matrix_setter("uniformMatrix2x4fv")
    uniformMatrix3x2fv = _matrix_setter("uniformMatrix3x2fv")
    uniformMatrix3x4fv = _matrix_setter("uniformMatrix3x4fv")
    uniformMatrix4x2fv = _matrix_setter("uniformMatrix4x2fv")
    uniformMatrix4x3fv = _matrix_setter("uniformMatrix4x3fv")

    @property
    def canvas(self) -> Canvas:
        """The canvas: set ``gl.canvas.width`` / ``height`` to resize the drawing buffer."""
        canvas = self.__dict__.get("_canvas")
        if canvas is None:
            canvas = self._canvas = Canvas(self)
        return canvas

    @property
    def version(self) -> int:
        return self._attributes().version

    # -- display -------------------------------------------------------------------------------

    def _repr_png_(self):
        # Showing the canvas never clears it (display.present(gl) does, as a browser frame).
        from .display import canvas_png
        return canvas_png(self)

    def __repr__(self):
        return (f"<softgl.{type(self).__name__} {self.drawingBufferWidth}x"
                f"{self.drawingBufferHeight}>")


def _install_constants():
    v1, v2 = {}, {}
    for name, value, version in _core.ENUMS:
        (v1 if version == 1 else v2)[name] = value
    for name, value in v1.items():
        setattr(WebGLRenderingContext, name, value)
    for name, value in v1.items() | v2.items():
        setattr(WebGL2RenderingContext, name, value)


def _missing_in_webgl1(name):
    def fail(self):
        raise AttributeError(f"'{type(self).__name__}' has no attribute '{name}' (WebGL 2 only)")
    return property(fail)


class WebGLRenderingContext(Context):
    """WebGL 1 (``Context(..., version=1)``)."""
    _version = 1
    locals().update({name: _missing_in_webgl1(name) for name in WEBGL2_ONLY})


class WebGL2RenderingContext(Context):
    """WebGL 2 (the default)."""
    _version = 2


_install_constants()
