"""Scenes about state, errors and clears, judged by real WebGL (see recorder.py).

Our own re-expression of what these WebGL conformance tests check (KhronosGroup/WebGL
sdk/tests/conformance/): state/gl-get-calls, state/gl-initial-state, state/gl-enable-enum-test,
misc/invalid-passed-params, misc/webgl-specific, limits/gl-line-width, extensions/ext-blend-minmax,
rendering/gl-clear, rendering/gl-scissor-test, plus readPixels/pixelStorei rules they rely on.

Each scene is `def name(gl, version)`; it runs once per version in `versions` on a context made
from its Setup. Scenes only make calls; the reference trace from Chromium says what must happen.
"""
from __future__ import annotations

import numpy as np

from recorder import ENUMS, Setup

SCENES = {}


def scene(versions=(1, 2), width=16, height=16, **attributes):
    """Register a scene; attributes are WebGL context attributes added to the defaults."""
    def register(fn):
        attrs = dict(antialias=False, preserveDrawingBuffer=True) | attributes
        SCENES[fn.__name__] = (fn, tuple(versions), dict(width=width, height=height,
                                                           attributes=attrs))
        return fn
    return register


def scene_cases():
    """[(id, scene_fn, Setup)] for every scene and version: the test ids."""
    return [(f"{name}-v{v}", fn, Setup(version=v, **kw))
            for name, (fn, versions, kw) in SCENES.items() for v in versions]


# Desktop OpenGL constants that WebGL does not have (for "must be rejected" checks).
DESKTOP_GL_CAPS = {
    "ALPHA_TEST": 0x0BC0, "AUTO_NORMAL": 0x0D80, "CLIP_PLANE0": 0x3000, "CLIP_PLANE1": 0x3001,
    "COLOR_LOGIC_OP": 0x0BF2, "COLOR_MATERIAL": 0x0B57, "COLOR_SUM": 0x8458,
    "COLOR_TABLE": 0x80D0, "FOG": 0x0B60, "HISTOGRAM": 0x8024, "INDEX_LOGIC_OP": 0x0BF1,
    "LIGHT0": 0x4000, "LIGHT1": 0x4001, "LIGHTING": 0x0B50, "LINE_SMOOTH": 0x0B20,
    "LINE_STIPPLE": 0x0B24, "MAP1_VERTEX_3": 0x0D97, "MAP2_VERTEX_4": 0x0DB8, "MINMAX": 0x802E,
    "MULTISAMPLE": 0x809D, "NORMALIZE": 0x0BA1, "POINT_SMOOTH": 0x0B10, "POINT_SPRITE": 0x8861,
    "POLYGON_OFFSET_LINE": 0x2A02, "POLYGON_OFFSET_POINT": 0x2A01, "POLYGON_SMOOTH": 0x0B41,
    "POLYGON_STIPPLE": 0x0B42, "RESCALE_NORMAL": 0x803A, "SAMPLE_ALPHA_TO_ONE": 0x809F,
    "TEXTURE_1D": 0x0DE0, "TEXTURE_2D": 0x0DE1, "TEXTURE_3D": 0x806F, "TEXTURE_CUBE_MAP": 0x8513,
    "TEXTURE_GEN_S": 0x0C60, "TEXTURE_GEN_T": 0x0C61, "TEXTURE_GEN_R": 0x0C62,
    "TEXTURE_GEN_Q": 0x0C63, "VERTEX_PROGRAM_POINT_SIZE": 0x8642,
    "VERTEX_PROGRAM_TWO_SIDE": 0x8643, "PRIMITIVE_RESTART_FIXED_INDEX": 0x8D69,
    "DEPTH_CLAMP": 0x864F, "FRAMEBUFFER_SRGB": 0x8DB9, "PROGRAM_POINT_SIZE": 0x8642,
}
CAPS_V1 = ["BLEND", "CULL_FACE", "DEPTH_TEST", "DITHER", "POLYGON_OFFSET_FILL",
           "SAMPLE_ALPHA_TO_COVERAGE", "SAMPLE_COVERAGE", "SCISSOR_TEST", "STENCIL_TEST"]
MIN_EXT, MAX_EXT = 0x8007, 0x8008          # EXT_blend_minmax (== WebGL 2's MIN / MAX)
ACCUM_BUFFER_BIT = 0x0200                   # desktop GL only
FRAGMENT_SHADER_DERIVATIVE_HINT = 0x8B8B    # WebGL 2 core / OES_standard_derivatives


def constants(version):
    """Every non-negative constant of the context (TIMEOUT_IGNORED, -1, is in its own scene)."""
    return sorted({v for v in ENUMS["webgl1" if version == 1 else "webgl2"].values() if v >= 0})


def caps(gl, version):
    return CAPS_V1 + (["RASTERIZER_DISCARD"] if version == 2 else [])


def read_all(gl, w=16, h=16):
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE)


# ---------------------------------------------------------------- gl-get-calls, gl-initial-state

@scene(width=300, height=150)
def initial_every_constant_as_parameter(gl, version):
    # Every constant of the context passed to getParameter: the valid ones give their initial
    # value (limits and strings judged by webgl_rules), the others INVALID_ENUM.
    for value in constants(version):
        gl.getParameter(value)


@scene()
def initial_error_and_lost_state(gl, version):
    gl.getError()
    gl.getError()
    gl.isContextLost()


@scene()
def initial_capabilities(gl, version):
    for name in caps(gl, version):
        gl.isEnabled(getattr(gl, name))
        gl.getParameter(getattr(gl, name))


@scene(width=7, height=3)
def initial_viewport_scissor_and_size(gl, version):
    gl.get_property("drawingBufferWidth")
    gl.get_property("drawingBufferHeight")
    gl.getParameter(gl.VIEWPORT)
    gl.getParameter(gl.SCISSOR_BOX)


@scene()
def initial_strings(gl, version):
    for name in ("VENDOR", "RENDERER", "VERSION", "SHADING_LANGUAGE_VERSION"):
        gl.getParameter(getattr(gl, name))


@scene()
def context_attributes_default(gl, version):
    gl.getContextAttributes()
    for name in ("RED_BITS", "GREEN_BITS", "BLUE_BITS", "ALPHA_BITS", "DEPTH_BITS",
                 "STENCIL_BITS", "SAMPLES", "SAMPLE_BUFFERS"):
        gl.getParameter(getattr(gl, name))


@scene(alpha=False, depth=False, stencil=True, premultipliedAlpha=False)
def context_attributes_no_alpha_no_depth_stencil(gl, version):
    gl.getContextAttributes()
    for name in ("ALPHA_BITS", "DEPTH_BITS", "STENCIL_BITS"):
        gl.getParameter(getattr(gl, name))


@scene(antialias=True)
def context_attributes_antialias(gl, version):
    gl.getContextAttributes()
    gl.getParameter(gl.SAMPLE_BUFFERS)


@scene()
def extensions_query(gl, version):
    gl.getSupportedExtensions()
    gl.getExtension("EXT_blend_minmax")
    gl.getExtension("ext_BLEND_minMAX")     # names match case-insensitively
    gl.getExtension("NOT_A_REAL_extension")
    gl.getExtension("")


@scene(versions=(2,))
def initial_webgl2_pixel_store_and_buffers(gl, version):
    for name in ("PACK_ROW_LENGTH", "PACK_SKIP_PIXELS", "PACK_SKIP_ROWS", "UNPACK_ROW_LENGTH",
                 "UNPACK_IMAGE_HEIGHT", "UNPACK_SKIP_PIXELS", "UNPACK_SKIP_ROWS",
                 "UNPACK_SKIP_IMAGES", "READ_BUFFER", "DRAW_BUFFER0", "DRAW_BUFFER1",
                 "DRAW_BUFFER7", "RASTERIZER_DISCARD", "TRANSFORM_FEEDBACK_ACTIVE",
                 "TRANSFORM_FEEDBACK_PAUSED", "VERTEX_ARRAY_BINDING", "SAMPLER_BINDING"):
        gl.getParameter(getattr(gl, name))


@scene(versions=(1,))
def webgl2_parameters_rejected_in_webgl1(gl, version):
    for value in sorted(set(ENUMS["webgl2"].values()) - set(ENUMS["webgl1"].values())):
        if value >= 0:    # TIMEOUT_IGNORED (-1): see unsigned_arguments_wrap_like_webidl
            gl.getParameter(value)


@scene()
def unsigned_arguments_wrap_like_webidl(gl, version):
    # WebIDL converts GLenum/GLuint/GLbitfield arguments modulo 2^32 (no exception): -1 is
    # 0xFFFFFFFF, so `stencilMask(~0)` sets all bits and `enable(-1)` is INVALID_ENUM.
    gl.stencilMask(-1)
    gl.getParameter(gl.STENCIL_WRITEMASK)
    gl.stencilFunc(gl.ALWAYS, 0, ~0)
    gl.getParameter(gl.STENCIL_VALUE_MASK)
    gl.stencilMaskSeparate(gl.BACK, -256)
    gl.getParameter(gl.STENCIL_BACK_WRITEMASK)
    gl.enable(-1)
    gl.getParameter(-1)
    gl.clear(-1)


@scene()
def nan_arguments(gl, version):
    # ES 3.0 §2.1.1: NaN arguments give unspecified (but harmless) results; record what happens.
    nan = float("nan")
    gl.clearDepth(nan)
    gl.getParameter(gl.DEPTH_CLEAR_VALUE)
    gl.depthRange(nan, 1.0)
    gl.getParameter(gl.DEPTH_RANGE)
    gl.blendColor(nan, 0.5, 0.5, 0.5)
    gl.getParameter(gl.BLEND_COLOR)
    gl.polygonOffset(nan, 1.0)
    gl.getParameter(gl.POLYGON_OFFSET_FACTOR)
    gl.sampleCoverage(nan, False)
    gl.getParameter(gl.SAMPLE_COVERAGE_VALUE)


# ---------------------------------------------------------------- gl-enable-enum-test

@scene()
def enable_every_constant(gl, version):
    # Only the capabilities of this version may be enabled; every other value is INVALID_ENUM
    # for enable, disable and isEnabled alike.
    for value in constants(version):
        gl.enable(value)
        gl.isEnabled(value)
        gl.disable(value)


@scene()
def enable_desktop_gl_capabilities_rejected(gl, version):
    for value in DESKTOP_GL_CAPS.values():
        gl.enable(value)
        gl.isEnabled(value)
        gl.disable(value)
    gl.enable(0)
    gl.enable(0xFFFFFFFF)


@scene()
def enable_disable_roundtrip(gl, version):
    for name in caps(gl, version):
        cap = getattr(gl, name)
        gl.enable(cap)
        gl.isEnabled(cap)
        gl.getParameter(cap)
    for name in caps(gl, version):
        gl.disable(getattr(gl, name))
        gl.isEnabled(getattr(gl, name))
    gl.enable(gl.BLEND)
    gl.enable(gl.BLEND)         # enabling twice is fine
    gl.isEnabled(gl.BLEND)


# ---------------------------------------------------------------- invalid-passed-params

@scene()
def clear_invalid_bits(gl, version):
    gl.clearColor(0, 1, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.clearColor(1, 0, 0, 1)
    gl.clear(ACCUM_BUFFER_BIT)
    gl.clear(ACCUM_BUFFER_BIT | gl.COLOR_BUFFER_BIT)   # must not clear anything
    gl.clear(ACCUM_BUFFER_BIT | gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    gl.clear(0x8000)
    gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE)
    gl.clear(0)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE)


@scene()
def scissor_viewport_negative_sizes(gl, version):
    gl.scissor(0, 0, -2, -2)
    gl.getParameter(gl.SCISSOR_BOX)
    gl.scissor(0, 0, 16, -1)
    gl.scissor(-3, -5, 16, 16)     # negative origin is fine
    gl.getParameter(gl.SCISSOR_BOX)
    gl.viewport(0, 0, -2, -2)
    gl.getParameter(gl.VIEWPORT)
    gl.viewport(0, 0, -1, 4)
    gl.viewport(-3, -5, 8, 9)
    gl.getParameter(gl.VIEWPORT)
    gl.viewport(2, 3, 0, 0)
    gl.getParameter(gl.VIEWPORT)


@scene()
def viewport_scissor_values(gl, version):
    gl.viewport(1, 2, 3, 4)
    gl.scissor(5, 6, 7, 8)
    gl.getParameter(gl.VIEWPORT)
    gl.getParameter(gl.SCISSOR_BOX)
    gl.viewport(100, 200, 1000, 2000)   # beyond the canvas, below every MAX_VIEWPORT_DIMS
    gl.scissor(-100, -200, 3000, 4000)
    gl.getParameter(gl.VIEWPORT)
    gl.getParameter(gl.SCISSOR_BOX)
    gl.viewport(2**31 - 1, -2**31, 4, 4)
    gl.getParameter(gl.VIEWPORT)


# ---------------------------------------------------------------- webgl-specific

@scene()
def blend_func_constant_color_alpha_pairs(gl, version):
    colors = [gl.CONSTANT_COLOR, gl.ONE_MINUS_CONSTANT_COLOR]
    alphas = [gl.CONSTANT_ALPHA, gl.ONE_MINUS_CONSTANT_ALPHA]
    gl.blendFunc(gl.SRC_ALPHA, gl.DST_ALPHA)
    for c in colors:
        for a in alphas:
            gl.blendFunc(c, a)
            gl.blendFunc(a, c)
    gl.getParameter(gl.BLEND_SRC_RGB)      # unchanged by the failed calls
    gl.getParameter(gl.BLEND_DST_RGB)
    for c in colors:                        # same kind twice is allowed
        gl.blendFunc(c, c)
    for a in alphas:
        gl.blendFunc(a, a)
    gl.getParameter(gl.BLEND_SRC_ALPHA)
    gl.getParameter(gl.BLEND_DST_ALPHA)


@scene()
def blend_func_separate_constant_pairs(gl, version):
    colors = [gl.CONSTANT_COLOR, gl.ONE_MINUS_CONSTANT_COLOR]
    alphas = [gl.CONSTANT_ALPHA, gl.ONE_MINUS_CONSTANT_ALPHA]
    for c in colors:
        for a in alphas:
            gl.blendFuncSeparate(c, a, gl.ONE, gl.ZERO)
            gl.blendFuncSeparate(a, c, gl.ONE, gl.ZERO)
            gl.blendFuncSeparate(gl.ONE, gl.ZERO, c, a)    # only the RGB pair is restricted?
            gl.blendFuncSeparate(gl.ONE, gl.ZERO, a, c)
            gl.blendFuncSeparate(c, gl.ONE, gl.ONE, a)
    for name in ("BLEND_SRC_RGB", "BLEND_DST_RGB", "BLEND_SRC_ALPHA", "BLEND_DST_ALPHA"):
        gl.getParameter(getattr(gl, name))


@scene()
def depth_range_rules(gl, version):
    gl.depthRange(20, 10)          # near > far: INVALID_OPERATION in WebGL
    gl.getParameter(gl.DEPTH_RANGE)
    gl.depthRange(0.25, 0.75)
    gl.getParameter(gl.DEPTH_RANGE)
    gl.depthRange(0.5, 0.5)
    gl.getParameter(gl.DEPTH_RANGE)
    gl.depthRange(-1, 2)           # clamped to [0, 1]
    gl.getParameter(gl.DEPTH_RANGE)
    gl.depthRange(0.8, 0.2)
    gl.getParameter(gl.DEPTH_RANGE)
    gl.depthRange(2, 3)            # both clamp to 1
    gl.getParameter(gl.DEPTH_RANGE)


@scene()
def src_alpha_saturate_as_destination(gl, version):
    gl.blendFunc(gl.SRC_ALPHA_SATURATE, gl.ONE)      # valid source factor everywhere
    gl.getParameter(gl.BLEND_SRC_RGB)
    gl.blendFunc(gl.ONE, gl.SRC_ALPHA_SATURATE)      # destination: ES 2.0 no, ES 3.0 yes
    gl.getParameter(gl.BLEND_DST_RGB)
    gl.blendFuncSeparate(gl.ONE, gl.ONE, gl.ONE, gl.SRC_ALPHA_SATURATE)
    gl.getParameter(gl.BLEND_DST_ALPHA)
    gl.blendFuncSeparate(gl.ONE, gl.SRC_ALPHA_SATURATE, gl.ONE, gl.ONE)
    gl.getParameter(gl.BLEND_DST_RGB)


@scene(stencil=True)
def stencil_ref_and_masks(gl, version):
    gl.stencilFunc(gl.ALWAYS, 300, 0xFF)     # ref beyond 8 bits
    gl.getParameter(gl.STENCIL_REF)
    gl.getParameter(gl.STENCIL_BACK_REF)
    gl.stencilFunc(gl.LESS, -5, 0xFFFFFFFF)
    gl.getParameter(gl.STENCIL_REF)
    gl.getParameter(gl.STENCIL_VALUE_MASK)
    gl.getParameter(gl.STENCIL_BACK_VALUE_MASK)
    gl.stencilMask(0xFFFFFFFF)
    gl.getParameter(gl.STENCIL_WRITEMASK)
    gl.stencilMask(0x1F0)
    gl.getParameter(gl.STENCIL_WRITEMASK)
    gl.getParameter(gl.STENCIL_BACK_WRITEMASK)
    gl.stencilMask(2**32 - 2)
    gl.getParameter(gl.STENCIL_BACK_WRITEMASK)


@scene()
def stencil_ref_without_stencil_buffer(gl, version):
    gl.stencilFunc(gl.EQUAL, 7, 0x3)
    gl.getParameter(gl.STENCIL_REF)
    gl.getParameter(gl.STENCIL_FUNC)
    gl.getParameter(gl.STENCIL_BITS)


@scene()
def stencil_separate_faces(gl, version):
    gl.stencilFuncSeparate(gl.BACK, gl.GEQUAL, 3, 0x0F)
    gl.stencilMaskSeparate(gl.FRONT, 0x11)
    gl.stencilOpSeparate(gl.FRONT, gl.INCR, gl.DECR_WRAP, gl.INVERT)
    gl.stencilOpSeparate(gl.FRONT_AND_BACK, gl.ZERO, gl.KEEP, gl.REPLACE)
    gl.stencilOpSeparate(gl.BACK, gl.INCR_WRAP, gl.DECR, gl.ZERO)
    for name in ("STENCIL_FUNC", "STENCIL_REF", "STENCIL_VALUE_MASK", "STENCIL_WRITEMASK",
                 "STENCIL_FAIL", "STENCIL_PASS_DEPTH_FAIL", "STENCIL_PASS_DEPTH_PASS",
                 "STENCIL_BACK_FUNC", "STENCIL_BACK_REF", "STENCIL_BACK_VALUE_MASK",
                 "STENCIL_BACK_WRITEMASK", "STENCIL_BACK_FAIL", "STENCIL_BACK_PASS_DEPTH_FAIL",
                 "STENCIL_BACK_PASS_DEPTH_PASS"):
        gl.getParameter(getattr(gl, name))


@scene()
def stencil_invalid_arguments(gl, version):
    gl.stencilFunc(gl.KEEP, 0, 0xFF)                   # not a comparison
    gl.stencilFuncSeparate(gl.FRONT_FACE, gl.ALWAYS, 0, 0xFF)
    gl.stencilFuncSeparate(gl.FRONT, gl.NEVER - 1, 0, 0xFF)
    gl.stencilOp(gl.KEEP, gl.KEEP, gl.LESS)
    gl.stencilOp(gl.INCR, 0x1E04, gl.KEEP)             # 0x1E04 is not an op
    gl.stencilOpSeparate(gl.CW, gl.KEEP, gl.KEEP, gl.KEEP)
    gl.stencilMaskSeparate(gl.BACK + 1, 0)
    gl.getParameter(gl.STENCIL_FUNC)
    gl.getParameter(gl.STENCIL_PASS_DEPTH_PASS)
    gl.getParameter(gl.STENCIL_BACK_WRITEMASK)


@scene()
def unpack_colorspace_and_flags(gl, version):
    gl.getParameter(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL)
    gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE)
    gl.getParameter(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL)
    gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, 0x1234)
    gl.getParameter(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL)
    gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.BROWSER_DEFAULT_WEBGL)
    gl.getParameter(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL)
    gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, 5)          # any non-zero is true
    gl.getParameter(gl.UNPACK_FLIP_Y_WEBGL)
    gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, 1)
    gl.getParameter(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL)
    gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, 0)
    gl.getParameter(gl.UNPACK_FLIP_Y_WEBGL)


@scene()
def implementation_color_read_format(gl, version):
    gl.getParameter(gl.IMPLEMENTATION_COLOR_READ_FORMAT)
    gl.getParameter(gl.IMPLEMENTATION_COLOR_READ_TYPE)


# ---------------------------------------------------------------- gl-line-width

@scene()
def line_width_values(gl, version):
    gl.getParameter(gl.ALIASED_LINE_WIDTH_RANGE)
    for width in (0.0, -1.0, float("nan"), 0.5, 2.5, 1000.0, float("inf"), 1e-30, 1.0):
        gl.lineWidth(width)
        gl.getParameter(gl.LINE_WIDTH)   # the value as set; clamping only happens when drawing


# ---------------------------------------------------------------- ext-blend-minmax

@scene()
def blend_minmax_extension(gl, version):
    # WebGL 1: MIN/MAX only after getExtension('EXT_blend_minmax'); WebGL 2: always.
    gl.blendEquation(MIN_EXT)
    gl.blendEquation(MAX_EXT)
    gl.blendEquationSeparate(MIN_EXT, gl.FUNC_ADD)
    gl.blendEquationSeparate(gl.FUNC_ADD, MAX_EXT)
    gl.getParameter(gl.BLEND_EQUATION_RGB)
    gl.getExtension("EXT_blend_minmax")
    gl.blendEquation(MIN_EXT)
    gl.getParameter(gl.BLEND_EQUATION_RGB)
    gl.getParameter(gl.BLEND_EQUATION_ALPHA)
    gl.blendEquation(MAX_EXT)
    gl.getParameter(gl.BLEND_EQUATION)
    gl.blendEquationSeparate(MIN_EXT, MAX_EXT)
    gl.getParameter(gl.BLEND_EQUATION_RGB)
    gl.getParameter(gl.BLEND_EQUATION_ALPHA)


@scene()
def blend_equation_values(gl, version):
    for mode in (gl.FUNC_ADD, gl.FUNC_SUBTRACT, gl.FUNC_REVERSE_SUBTRACT, 0, gl.BLEND,
                 0x800B, 0x8009, 0x0BF1, gl.FUNC_ADD + 1):
        gl.blendEquation(mode)
        gl.getParameter(gl.BLEND_EQUATION_RGB)
    gl.blendEquationSeparate(gl.FUNC_SUBTRACT, gl.FUNC_REVERSE_SUBTRACT)
    gl.getParameter(gl.BLEND_EQUATION_RGB)
    gl.getParameter(gl.BLEND_EQUATION_ALPHA)
    gl.blendEquationSeparate(gl.FUNC_ADD, 0x1234)
    gl.getParameter(gl.BLEND_EQUATION_RGB)


@scene()
def blend_func_every_factor(gl, version):
    factors = [gl.ZERO, gl.ONE, gl.SRC_COLOR, gl.ONE_MINUS_SRC_COLOR, gl.DST_COLOR,
               gl.ONE_MINUS_DST_COLOR, gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.DST_ALPHA,
               gl.ONE_MINUS_DST_ALPHA, gl.CONSTANT_COLOR, gl.ONE_MINUS_CONSTANT_COLOR,
               gl.CONSTANT_ALPHA, gl.ONE_MINUS_CONSTANT_ALPHA, gl.SRC_ALPHA_SATURATE,
               2, 0x0309, 0x8000, 0x8005, gl.BLEND]
    for f in factors:
        gl.blendFunc(f, gl.ZERO)
        gl.getParameter(gl.BLEND_SRC_RGB)
        gl.blendFunc(gl.ONE, f)
        gl.getParameter(gl.BLEND_DST_ALPHA)


@scene()
def blend_color_values(gl, version):
    gl.blendColor(0.25, 0.5, 0.75, 1.0)
    gl.getParameter(gl.BLEND_COLOR)
    gl.blendColor(-1.0, 2.0, 0.5, 100.0)   # ES 2.0 clamps when specified; ES 3.0 keeps
    gl.getParameter(gl.BLEND_COLOR)
    gl.blendColor(1 / 3, 1e-8, 0.1, 0.9)
    gl.getParameter(gl.BLEND_COLOR)


# ---------------------------------------------------------------- state setters with enums

@scene()
def depth_func_and_mask(gl, version):
    for func in (gl.NEVER, gl.LESS, gl.EQUAL, gl.LEQUAL, gl.GREATER, gl.NOTEQUAL, gl.GEQUAL,
                 gl.ALWAYS, gl.NEVER - 1, gl.ALWAYS + 1, 0):
        gl.depthFunc(func)
        gl.getParameter(gl.DEPTH_FUNC)
    gl.depthMask(False)
    gl.getParameter(gl.DEPTH_WRITEMASK)
    gl.depthMask(True)
    gl.getParameter(gl.DEPTH_WRITEMASK)


@scene()
def cull_face_and_front_face(gl, version):
    for mode in (gl.FRONT, gl.BACK, gl.FRONT_AND_BACK, gl.CW, 0):
        gl.cullFace(mode)
        gl.getParameter(gl.CULL_FACE_MODE)
    for mode in (gl.CW, gl.CCW, gl.FRONT, gl.CCW + 1):
        gl.frontFace(mode)
        gl.getParameter(gl.FRONT_FACE)


@scene()
def hints(gl, version):
    for mode in (gl.FASTEST, gl.NICEST, gl.DONT_CARE, gl.FASTEST - 1, 0):
        gl.hint(gl.GENERATE_MIPMAP_HINT, mode)
        gl.getParameter(gl.GENERATE_MIPMAP_HINT)
    gl.hint(FRAGMENT_SHADER_DERIVATIVE_HINT, gl.NICEST)   # WebGL 2 only (v1: extension)
    gl.getParameter(FRAGMENT_SHADER_DERIVATIVE_HINT)
    gl.hint(0x0C50, gl.NICEST)                             # PERSPECTIVE_CORRECTION_HINT: desktop
    gl.hint(gl.BLEND, gl.FASTEST)


@scene()
def polygon_offset_and_sample_coverage(gl, version):
    gl.polygonOffset(1.5, -2.25)
    gl.getParameter(gl.POLYGON_OFFSET_FACTOR)
    gl.getParameter(gl.POLYGON_OFFSET_UNITS)
    gl.sampleCoverage(0.3, True)
    gl.getParameter(gl.SAMPLE_COVERAGE_VALUE)
    gl.getParameter(gl.SAMPLE_COVERAGE_INVERT)
    gl.sampleCoverage(2.0, False)       # clamped to [0, 1]
    gl.getParameter(gl.SAMPLE_COVERAGE_VALUE)
    gl.sampleCoverage(-1.0, False)
    gl.getParameter(gl.SAMPLE_COVERAGE_VALUE)


@scene()
def active_texture_units(gl, version):
    for unit in (gl.TEXTURE0 + 1, gl.TEXTURE0 + 7, gl.TEXTURE0 - 1, gl.TEXTURE0 + 200, 0):
        gl.activeTexture(unit)
        gl.getParameter(gl.ACTIVE_TEXTURE)


@scene()
def color_mask_queries(gl, version):
    gl.colorMask(True, False, True, False)
    gl.getParameter(gl.COLOR_WRITEMASK)
    gl.colorMask(False, False, False, False)
    gl.getParameter(gl.COLOR_WRITEMASK)
    gl.colorMask(True, True, True, True)
    gl.getParameter(gl.COLOR_WRITEMASK)


@scene()
def depth_and_stencil_clear_values(gl, version):
    for d in (0.5, 2.0, -1.0, 0.3):
        gl.clearDepth(d)
        gl.getParameter(gl.DEPTH_CLEAR_VALUE)
    for s in (1, 300, -1, 255):
        gl.clearStencil(s)
        gl.getParameter(gl.STENCIL_CLEAR_VALUE)


@scene()
def pixel_store_alignment_rules(gl, version):
    for a in (1, 2, 4, 8, 3, 0, 16, -4):
        gl.pixelStorei(gl.PACK_ALIGNMENT, a)
        gl.getParameter(gl.PACK_ALIGNMENT)
        gl.pixelStorei(gl.UNPACK_ALIGNMENT, a)
        gl.getParameter(gl.UNPACK_ALIGNMENT)
    gl.pixelStorei(0x0D05 + 100, 1)      # not a pixel store parameter
    gl.pixelStorei(gl.BLEND, 1)


@scene(versions=(2,))
def pixel_store_webgl2_parameters(gl, version):
    for name in ("PACK_ROW_LENGTH", "PACK_SKIP_PIXELS", "PACK_SKIP_ROWS", "UNPACK_ROW_LENGTH",
                 "UNPACK_IMAGE_HEIGHT", "UNPACK_SKIP_PIXELS", "UNPACK_SKIP_ROWS",
                 "UNPACK_SKIP_IMAGES"):
        gl.pixelStorei(getattr(gl, name), 3)
        gl.getParameter(getattr(gl, name))
        gl.pixelStorei(getattr(gl, name), -1)
        gl.getParameter(getattr(gl, name))


@scene(versions=(1,))
def pixel_store_webgl2_parameters_rejected(gl, version):
    for value in (0x0D02, 0x0D03, 0x0D04, 0x0CF2, 0x806E, 0x0CF3, 0x0CF4, 0x806D):
        gl.pixelStorei(value, 1)
        gl.getParameter(value)


# ---------------------------------------------------------------- gl-clear

@scene()
def clear_white_then_black(gl, version):
    read_all(gl)                        # the initial buffer is transparent black
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    read_all(gl)
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    read_all(gl)


@scene()
def clear_with_color_masks(gl, version):
    gl.clearColor(0.2, 0.4, 0.6, 0.8)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.colorMask(False, False, False, True)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)
    gl.colorMask(True, False, True, False)
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)
    gl.colorMask(False, False, False, False)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)


@scene()
def clear_color_out_of_range(gl, version):
    gl.clearColor(-1.0, 2.0, 0.5, 1.5)
    gl.getParameter(gl.COLOR_CLEAR_VALUE)   # ES 2.0 clamps when specified; ES 3.0 keeps
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)
    gl.clearColor(float("inf"), float("-inf"), 0.0, 1.0)
    gl.getParameter(gl.COLOR_CLEAR_VALUE)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)


@scene()
def clear_color_nan(gl, version):
    gl.clearColor(float("nan"), 0.5, 0.5, 1.0)
    gl.getParameter(gl.COLOR_CLEAR_VALUE)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)


@scene(width=64, height=4)
def clear_color_rounding(gl, version):
    # float -> unorm8 rounds to nearest: sweep values around the half steps
    for i, v in enumerate([0.5 / 255, 0.499 / 255, 0.501 / 255, 127.5 / 255, 0.5, 1 / 3,
                           2 / 3, 254.5 / 255, 0.999, 1e-7]):
        gl.scissor(i * 4, 0, 4, 4)
        gl.enable(gl.SCISSOR_TEST)
        gl.clearColor(v, 1 - v, v, 1)
        gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 64, 1, gl.RGBA, gl.UNSIGNED_BYTE)


@scene(width=1, height=1)
def clear_one_pixel_canvas(gl, version):
    read_all(gl, 1, 1)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    read_all(gl, 1, 1)
    gl.colorMask(False, False, False, True)
    gl.clearColor(0.5, 0.5, 0.5, 0.5)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)


@scene(alpha=False)
def clear_without_alpha_channel(gl, version):
    gl.clearColor(1, 0, 0, 0.25)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)   # alpha reads as 1
    gl.colorMask(False, False, False, True)
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)


@scene(depth=False, stencil=True)
def clear_depth_stencil_only(gl, version):
    gl.clearColor(0, 1, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.clearColor(1, 0, 0, 1)
    gl.clear(gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)   # color untouched
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)


# ---------------------------------------------------------------- gl-scissor-test

@scene()
def scissor_diagonal_clears(gl, version):
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.clearColor(0, 1, 0, 1)
    for i in range(16):
        gl.scissor(i, i, 1, 1)
        gl.clear(gl.COLOR_BUFFER_BIT)
    read_all(gl)


@scene(antialias=True)
def scissor_diagonal_clears_antialias(gl, version):
    scissor_diagonal_clears(gl, version)


@scene()
def scissor_box_ignored_when_disabled(gl, version):
    gl.scissor(2, 2, 4, 4)
    gl.clearColor(0, 0, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    read_all(gl)
    gl.enable(gl.SCISSOR_TEST)
    gl.clearColor(1, 1, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.disable(gl.SCISSOR_TEST)
    read_all(gl)


@scene()
def scissor_partly_outside_and_empty(gl, version):
    gl.enable(gl.SCISSOR_TEST)
    gl.clearColor(1, 0, 0, 1)
    gl.scissor(-4, -4, 8, 8)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.clearColor(0, 0, 1, 1)
    gl.scissor(12, 10, 10, 100)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.clearColor(1, 1, 1, 1)
    gl.scissor(6, 6, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.scissor(20, 20, 5, 5)          # entirely outside
    gl.clear(gl.COLOR_BUFFER_BIT)
    read_all(gl)


@scene()
def scissor_with_color_mask(gl, version):
    gl.clearColor(0.5, 0.5, 0.5, 0.5)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(4, 0, 8, 16)
    gl.colorMask(True, False, False, True)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    read_all(gl)


# ---------------------------------------------------------------- readPixels

@scene()
def read_pixels_partly_outside_into_preset(gl, version):
    # Destination values of pixels outside the drawing buffer stay as they were.
    gl.clearColor(0.1, 0.2, 0.3, 0.4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    for x, y in ((-2, -2), (14, 13), (-3, 10), (10, -1)):
        gl.readPixels(x, y, 5, 4, gl.RGBA, gl.UNSIGNED_BYTE, np.full(5 * 4 * 4, 0x55, np.uint8))
    gl.readPixels(20, 20, 3, 3, gl.RGBA, gl.UNSIGNED_BYTE, np.full(36, 0x55, np.uint8))
    gl.readPixels(-10, 0, 40, 2, gl.RGBA, gl.UNSIGNED_BYTE, np.full(320, 0x55, np.uint8))


@scene()
def read_pixels_partly_outside_new_array(gl, version):
    gl.clearColor(0.9, 0.8, 0.7, 0.6)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(-2, -2, 5, 4, gl.RGBA, gl.UNSIGNED_BYTE)
    gl.readPixels(0, 0, 0, 0, gl.RGBA, gl.UNSIGNED_BYTE)
    gl.readPixels(0, 0, -1, 2, gl.RGBA, gl.UNSIGNED_BYTE)


@scene()
def read_pixels_pack_alignment(gl, version):
    gl.clearColor(1, 0.5, 0.25, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(1, 1, 1, 1)
    gl.clearColor(0, 0, 1, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    for align in (1, 2, 4, 8):
        gl.pixelStorei(gl.PACK_ALIGNMENT, align)
        # 3 pixels of 4 bytes = 12 bytes a row; rows padded to `align`; last row not padded
        stride = -(-12 // align) * align
        size = 2 * stride + 12
        gl.readPixels(0, 0, 3, 3, gl.RGBA, gl.UNSIGNED_BYTE, np.full(size, 0xAA, np.uint8))
        gl.readPixels(0, 0, 3, 3, gl.RGBA, gl.UNSIGNED_BYTE, np.full(size - 1, 0xAA, np.uint8))
    gl.pixelStorei(gl.PACK_ALIGNMENT, 8)
    gl.readPixels(0, 0, 1, 3, gl.RGBA, gl.UNSIGNED_BYTE, np.full(2 * 8 + 4, 0xAA, np.uint8))
    gl.readPixels(0, 0, 1, 3, gl.RGBA, gl.UNSIGNED_BYTE, np.full(3 * 8, 0xAA, np.uint8))


@scene(versions=(2,))
def read_pixels_pack_row_length_and_skips(gl, version):
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(0, 1, 2, 1)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.pixelStorei(gl.PACK_ROW_LENGTH, 5)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, np.full(5 * 4 * 2, 9, np.uint8))
    gl.pixelStorei(gl.PACK_SKIP_PIXELS, 2)
    gl.pixelStorei(gl.PACK_SKIP_ROWS, 1)
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, np.full(5 * 4 * 3, 9, np.uint8))
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, np.full(5 * 4 * 3 - 1, 9, np.uint8))
    gl.pixelStorei(gl.PACK_SKIP_PIXELS, 4)     # skip + width > row length
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, np.full(5 * 4 * 4, 9, np.uint8))


@scene()
def read_pixels_formats_and_types(gl, version):
    gl.clearColor(0.25, 0.5, 0.75, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    u8 = lambda n: np.zeros(n, np.uint8)     # noqa: E731
    gl.readPixels(0, 0, 1, 1, gl.RGB, gl.UNSIGNED_BYTE, u8(4))
    gl.readPixels(0, 0, 1, 1, gl.ALPHA, gl.UNSIGNED_BYTE, u8(4))
    gl.readPixels(0, 0, 1, 1, gl.LUMINANCE, gl.UNSIGNED_BYTE, u8(4))
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.FLOAT, np.zeros(4, np.float32))
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_SHORT_4_4_4_4, np.zeros(4, np.uint16))
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_SHORT_5_6_5, np.zeros(4, np.uint16))
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.BYTE, np.zeros(4, np.int8))
    gl.readPixels(0, 0, 1, 1, 0x1234, gl.UNSIGNED_BYTE, u8(4))
    gl.readPixels(0, 0, 1, 1, gl.RGBA, 0x1234, u8(4))
    gl.readPixels(0, 0, 1, 1, gl.DEPTH_COMPONENT, gl.UNSIGNED_SHORT, np.zeros(4, np.uint16))
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, u8(4))
    if version == 2:
        gl.readPixels(0, 0, 1, 1, gl.RGBA_INTEGER, gl.UNSIGNED_BYTE, u8(4))
        gl.readPixels(0, 0, 1, 1, gl.RGBA_INTEGER, gl.INT, np.zeros(4, np.int32))
        gl.readPixels(0, 0, 1, 1, gl.RG, gl.UNSIGNED_BYTE, u8(4))
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_INT_2_10_10_10_REV, np.zeros(1, np.uint32))


@scene()
def read_pixels_wrong_array_type(gl, version):
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(4, np.float32))
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(4, np.uint16))
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(4, np.int8))
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(3, np.uint8))
    gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros(16, np.uint8))


@scene(width=5, height=3)
def read_pixels_orientation(gl, version):
    # row 0 of the result is the bottom row of the drawing buffer
    gl.enable(gl.SCISSOR_TEST)
    for row, color in enumerate([(1, 0, 0, 1), (0, 1, 0, 1), (0, 0, 1, 1)]):
        gl.scissor(0, row, 5, 1)
        gl.clearColor(*color)
        gl.clear(gl.COLOR_BUFFER_BIT)
    gl.scissor(4, 0, 1, 3)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.readPixels(0, 0, 5, 3, gl.RGBA, gl.UNSIGNED_BYTE)
    gl.readPixels(0, 0, 5, 3, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros((3, 5, 4), np.uint8))
