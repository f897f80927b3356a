"""The sampler's 2D fast path (one 2D / 2D array texture of a float-sampled colour format,
resolved once per query) must give the same bits as the general per-lane path: every filter
and wrap, mipmap levels, LOD bias / explicit LOD / gradients / offsets, odd and NPOT sizes,
and coordinates that are negative, huge, infinite or NaN. Each image is drawn into an
RGBA32F target by the general path, the fast path without SIMD, with AVX2 blocks of 8 lanes and
with the best SIMD (AVX-512 blocks of 16 lanes where the CPU has it; the context's tuning), and
compared as uint32 bits (NaNs as NaNs); gl.stats() shows whether the fast path served the lookups."""
import numpy as np
import pytest

import softgl
from softgl import _core
from helpers import VS3, draw_quad, float_target

WRAPS = ["REPEAT", "CLAMP_TO_EDGE", "MIRRORED_REPEAT"]
MIN_FILTERS = ["NEAREST", "LINEAR", "NEAREST_MIPMAP_NEAREST", "LINEAR_MIPMAP_NEAREST",
               "NEAREST_MIPMAP_LINEAR", "LINEAR_MIPMAP_LINEAR"]
LOOKUPS = {
    "implicit": "texture(tex, p.xy)",
    "bias": "texture(tex, p.xy, lod)",
    "explicit": "textureLod(tex, p.xy, lod)",
    "gradient": "textureGrad(tex, p.xy, vec2(0.02 * lod, 0.011), vec2(-0.003, 0.05 * lod))",
    "offset": "textureOffset(tex, p.xy, ivec2(-3, 2))",
    "projective": "textureProj(tex, vec3(p.xy, 1.75))",
}
# (c0, cx, cy, special): texture coordinates over the viewport; `special` scales p.x on the two
# bottom rows and is added to p.y on the two left columns (inf, NaN: derivatives go non-finite).
MAPS = {
    "magnified": ((-1.37, -0.83, 0), (0.71, 0.05, 0), (0.0, 0.93, 0), (1.0, 0.0)),
    "minified-rotated": ((0.31, -2.2, 0), (9.3, 1.1, 0), (-0.7, 7.9, 0), (1.0, 0.0)),
    "beyond-last-level": ((-5.0, 3.0, 0), (310.0, 0.0, 0), (0.0, -170.0, 0), (1.0, 0.0)),
    "huge": ((1.5e8, -2.2e8, 0), (3.0e3, 0.0, 0), (0.0, 7.0e2, 0), (1.0, 0.0)),
    "non-finite": ((0.2, 0.1, 0), (2.3, 0.0, 0), (0.0, 1.9, 0), (float("inf"), float("nan"))),
}
W, H = 23, 19   # odd: the last column and row of quads are partly helper lanes
RNG = np.random.default_rng(71)


def fs(lookup, sampler="sampler2D"):
    return f"""#version 300 es
precision highp float;
precision highp sampler2D;
precision highp sampler2DArray;
uniform highp {sampler} tex;
uniform float lod;
uniform vec2 special;
in vec3 uvw;
out vec4 color;
void main() {{
    vec3 p = uvw;
    if (gl_FragCoord.y < 2.0) p.x *= special.x;
    if (gl_FragCoord.x < 2.0) p.y += special.y;
    color = {lookup};
}}
"""


def assert_same_bits(fast, general):
    """Equal bits, except that a NaN equals any NaN: which NaN an operation on two NaNs returns
    (sign, payload) is not specified (IEEE 754-2008 §6.2.3) and depends on the operand order the
    compiler picks, e.g. for (1 - a) * (1 - b) with a = inf - inf and b from a NaN coordinate."""
    both_nan = np.isnan(fast) & np.isnan(general)
    np.testing.assert_array_equal(np.where(both_nan, 0, fast.view(np.uint32)),
                                  np.where(both_nan, 0, general.view(np.uint32)))


# The context's tuning (core/tuning.h SamplerPath): general, fast scalar, fast with the best SIMD
# (AVX-512 blocks of 16 lanes where the CPU has it), fast with AVX2 blocks of 8 at most.
GENERAL, SCALAR, BEST, AVX2 = "general", "scalar", "best", "avx2"
PATHS = (GENERAL, SCALAR, AVX2, BEST)


def use_path(gl, path):
    """Sets the context's sampler path and zeroes its counters."""
    _core.testing.set_tuning(gl, sampler_path=path)
    gl.stats(reset=True)


def fast_queries(gl):
    """The lookups the fast path served since use_path (one per shader instruction and batch)."""
    return gl.stats()["texture_queries_fast"]


class Renderer:
    """One WebGL 2 context with a float target and cached programs."""

    def __init__(self, w=W, h=H, threads=1):
        self.gl = softgl.Context(8, 8, antialias=False, threads=threads)
        self.w, self.h = w, h
        float_target(self.gl, w, h)
        self.programs = {}

    def draw(self, source, c0, cx, cy, special=(1.0, 0.0), lod=0.0):
        gl = self.gl
        if source not in self.programs:
            self.programs[source] = softgl.program(gl, VS3, source)
        prog = self.programs[source]
        gl.useProgram(prog)
        gl.uniform1f(gl.getUniformLocation(prog, "lod"), lod)
        gl.uniform2f(gl.getUniformLocation(prog, "special"), *special)
        draw_quad(gl, prog, c0, cx, cy)
        assert gl.getError() == gl.NO_ERROR
        return gl.readPixels(0, 0, self.w, self.h, gl.RGBA, gl.FLOAT)

    def compare(self, *args, expect_fast=True, **kw):
        """Draws with the general path, the fast path without SIMD, with AVX2 and with the best SIMD;
        asserts equal bits; returns the image."""
        images, served = [], []
        for path in PATHS:
            use_path(self.gl, path)
            images.append(self.draw(*args, **kw))
            served.append(fast_queries(self.gl))
        # Every fast path serves the same queries; the general path none.
        assert served[0] == 0 and served[1] == served[2] == served[3] and (served[1] > 0) == expect_fast, served
        for img in images[1:]:
            assert_same_bits(img, images[0])
        return images[0]


def random_levels(gl, target, w, h, internal=None, fmt=None, type_=None, layers=0, dtype=np.uint8):
    """A full mip chain of independent random levels (a wrong level or texel shows)."""
    internal = gl.RGBA8 if internal is None else internal
    fmt = gl.RGBA if fmt is None else fmt
    type_ = gl.UNSIGNED_BYTE if type_ is None else type_
    comps = {gl.RGBA: 4, gl.RGB: 3, gl.LUMINANCE_ALPHA: 2, gl.LUMINANCE: 1, gl.ALPHA: 1}[fmt]
    tex = gl.createTexture()
    gl.bindTexture(target, tex)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    level = 0
    while True:
        shape = ((layers,) if layers else ()) + (h, w, comps)
        if dtype == np.uint8:
            data = RNG.integers(0, 256, shape, dtype=np.uint8)
        else:   # float texels well outside [0, 1], as half floats hold them
            data = RNG.uniform(-300, 300, shape).astype(np.float16).astype(dtype)
        if layers:
            gl.texImage3D(target, level, internal, w, h, layers, 0, fmt, type_, data)
        else:
            gl.texImage2D(target, level, internal, w, h, 0, fmt, type_, data)
        if w == 1 and h == 1:
            break
        w, h, level = max(1, w // 2), max(1, h // 2), level + 1
    return tex


def set_params(gl, target, min_filter, mag_filter, wrap_s="REPEAT", wrap_t="REPEAT"):
    for pname, value in ((gl.TEXTURE_MIN_FILTER, min_filter), (gl.TEXTURE_MAG_FILTER, mag_filter),
                         (gl.TEXTURE_WRAP_S, wrap_s), (gl.TEXTURE_WRAP_T, wrap_t)):
        gl.texParameteri(target, pname, getattr(gl, value))


@pytest.mark.parametrize("size", [(16, 16), (13, 7)], ids=["pot", "npot"])
@pytest.mark.parametrize("mag_filter", ["NEAREST", "LINEAR"])
@pytest.mark.parametrize("min_filter", MIN_FILTERS)
def test_fast_path_equals_general_path(min_filter, mag_filter, size):
    r = Renderer()
    gl = r.gl
    random_levels(gl, gl.TEXTURE_2D, *size)
    for wrap_s in WRAPS:
        for wrap_t in WRAPS:
            set_params(gl, gl.TEXTURE_2D, min_filter, mag_filter, wrap_s, wrap_t)
            for name, lookup in LOOKUPS.items():
                for c0, cx, cy, special in MAPS.values():
                    for lod in ((-0.7, 1.3, 2.6) if name in ("bias", "explicit", "gradient") else (0.0,)):
                        r.compare(fs(lookup), c0, cx, cy, special, lod)


@pytest.mark.parametrize("fmt", ["RGBA8", "RGB8", "LUMINANCE_ALPHA", "LUMINANCE", "ALPHA", "SRGB8_ALPHA8",
                                 "RGBA16F", "RGBA4"])
def test_fast_path_formats(fmt):
    r = Renderer()
    gl = r.gl
    args = {"RGBA8": (gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE), "RGB8": (gl.RGB8, gl.RGB, gl.UNSIGNED_BYTE),
            "LUMINANCE_ALPHA": (gl.LUMINANCE_ALPHA, gl.LUMINANCE_ALPHA, gl.UNSIGNED_BYTE),
            "LUMINANCE": (gl.LUMINANCE, gl.LUMINANCE, gl.UNSIGNED_BYTE),
            "ALPHA": (gl.ALPHA, gl.ALPHA, gl.UNSIGNED_BYTE),
            "SRGB8_ALPHA8": (gl.SRGB8_ALPHA8, gl.RGBA, gl.UNSIGNED_BYTE),
            "RGBA16F": (gl.RGBA16F, gl.RGBA, gl.FLOAT), "RGBA4": (gl.RGBA4, gl.RGBA, gl.UNSIGNED_BYTE)}[fmt]
    random_levels(gl, gl.TEXTURE_2D, 11, 9, *args, dtype=np.float32 if fmt == "RGBA16F" else np.uint8)
    for min_filter in ("NEAREST", "LINEAR_MIPMAP_NEAREST", "LINEAR_MIPMAP_LINEAR"):
        for mag_filter in ("NEAREST", "LINEAR"):
            set_params(gl, gl.TEXTURE_2D, min_filter, mag_filter, "MIRRORED_REPEAT", "REPEAT")
            for c0, cx, cy, special in MAPS.values():
                img = r.compare(fs(LOOKUPS["bias"]), c0, cx, cy, special, 0.4)
    assert np.isfinite(img[2:, 2:]).all()


def test_fast_path_base_level_max_level_and_lod_range():
    r = Renderer()
    gl = r.gl
    random_levels(gl, gl.TEXTURE_2D, 32, 20)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_BASE_LEVEL, 1)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAX_LEVEL, 3)
    for min_lod, max_lod in ((-1000.0, 1000.0), (0.5, 1.25), (1.5, 1.5), (-2.0, 0.0)):
        gl.texParameterf(gl.TEXTURE_2D, gl.TEXTURE_MIN_LOD, min_lod)
        gl.texParameterf(gl.TEXTURE_2D, gl.TEXTURE_MAX_LOD, max_lod)
        for min_filter in MIN_FILTERS:
            for mag_filter in ("NEAREST", "LINEAR"):
                set_params(gl, gl.TEXTURE_2D, min_filter, mag_filter)
                for lookup in ("implicit", "bias", "explicit"):
                    for c0, cx, cy, special in MAPS.values():
                        r.compare(fs(LOOKUPS[lookup]), c0, cx, cy, special, 0.8)


def test_fast_path_sampler_object_and_second_unit():
    # A sampler object's parameters replace the texture's; a texture on unit 3 is resolved by unit.
    r = Renderer()
    gl = r.gl
    gl.activeTexture(gl.TEXTURE3)
    random_levels(gl, gl.TEXTURE_2D, 9, 14)
    set_params(gl, gl.TEXTURE_2D, "NEAREST", "NEAREST")
    sampler = gl.createSampler()
    gl.bindSampler(3, sampler)
    for pname, value in ((gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR), (gl.TEXTURE_MAG_FILTER, gl.LINEAR),
                         (gl.TEXTURE_WRAP_S, gl.MIRRORED_REPEAT), (gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE)):
        gl.samplerParameteri(sampler, pname, value)
    gl.activeTexture(gl.TEXTURE0)
    source = fs(LOOKUPS["implicit"])
    prog = softgl.program(gl, VS3, source)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "tex"), 3)
    r.programs[source] = prog
    for c0, cx, cy, special in MAPS.values():
        r.compare(source, c0, cx, cy, special)


def test_fast_path_lookups_under_branches_on_two_units():
    # Each lookup runs with part of its lanes inactive (the branch), on its own unit: the fast
    # path takes the unit of the active lanes only, and inactive lanes give (0, 0, 0, 1).
    r = Renderer()
    gl = r.gl
    for unit, (w, h, min_filter) in ((1, (9, 14, "LINEAR_MIPMAP_LINEAR")), (2, (16, 8, "NEAREST"))):
        gl.activeTexture(gl.TEXTURE0 + unit)
        random_levels(gl, gl.TEXTURE_2D, w, h)
        set_params(gl, gl.TEXTURE_2D, min_filter, "LINEAR")
    gl.activeTexture(gl.TEXTURE0)
    source = fs(LOOKUPS["implicit"]).replace("uniform highp sampler2D tex;", "uniform highp sampler2D tex, tex2;").replace(
        "color = texture(tex, p.xy);",
        "color = vec4(0.0);\n"
        "    if (int(gl_FragCoord.x) % 3 == 1) color = texture(tex, p.xy);\n"
        "    if (int(gl_FragCoord.x + gl_FragCoord.y) % 2 == 0) color += texture(tex2, p.yx);")
    assert "tex2, p.yx" in source
    prog = softgl.program(gl, VS3, source)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "tex"), 1)
    gl.uniform1i(gl.getUniformLocation(prog, "tex2"), 2)
    r.programs[source] = prog
    for c0, cx, cy, special in MAPS.values():
        r.compare(source, c0, cx, cy, special)


def test_fast_path_2d_array_layers():
    r = Renderer()
    gl = r.gl
    random_levels(gl, gl.TEXTURE_2D_ARRAY, 12, 10, layers=5)
    for min_filter in MIN_FILTERS:
        for mag_filter in ("NEAREST", "LINEAR"):
            set_params(gl, gl.TEXTURE_2D_ARRAY, min_filter, mag_filter, "REPEAT", "MIRRORED_REPEAT")
            for lookup in ("texture(tex, p)", "texture(tex, p, lod)", "textureLod(tex, p, lod)",
                           "textureOffset(tex, p, ivec2(1, -2))"):
                for c0, cx, cy, special in MAPS.values():
                    # The layer runs from below 0 to beyond the last layer across the viewport.
                    c0, cx, cy = c0[:2] + (-2.3,), cx[:2] + (4.1,), cy[:2] + (5.2,)
                    r.compare(fs(lookup, "sampler2DArray"), c0, cx, cy, special, 1.1)


def test_general_path_keeps_what_the_fast_path_does_not_take():
    r = Renderer()
    gl = r.gl
    random_levels(gl, gl.TEXTURE_2D, 8, 8)
    c0, cx, cy, special = MAPS["minified-rotated"]
    # Incomplete (mipmapped filter, one level missing): (0, 0, 0, 1) from the general path.
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 4, 4, 0, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros((4, 4, 4), np.uint8))
    img = r.compare(fs(LOOKUPS["implicit"]), c0, cx, cy, special, expect_fast=False)
    assert (img == [0, 0, 0, 1]).all()
    # Cube maps take the fast path (lanes at a face edge the general one): see test_sampling_shadow_cube.py.
    cube = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, cube)
    for f in range(6):
        gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, 0, gl.RGBA8, 2, 2, 0, gl.RGBA, gl.UNSIGNED_BYTE,
                      RNG.integers(0, 256, (2, 2, 4), dtype=np.uint8))
    set_params(gl, gl.TEXTURE_CUBE_MAP, "LINEAR", "LINEAR")
    r.compare(fs("texture(tex, vec3(p.xy, 0.5))", "samplerCube"), c0, cx, cy, special)


def test_fast_path_with_threads():
    # A bigger target split over threads: the fast path keeps no state between queries.
    r = Renderer(97, 83, threads=3)
    gl = r.gl
    random_levels(gl, gl.TEXTURE_2D, 64, 48)
    set_params(gl, gl.TEXTURE_2D, "LINEAR_MIPMAP_LINEAR", "LINEAR")
    c0, cx, cy, special = MAPS["minified-rotated"]
    r.compare(fs(LOOKUPS["implicit"]), c0, (60.0, 3.0, 0), (-5.0, 40.0, 0), special)


def test_sampler_path_is_the_drawing_contexts_at_each_draw():
    # Two contexts with different paths draw in turn, then swap paths between draws of the same
    # programs (whose stages and executors are reused): each draw takes its own context's path.
    a, b = Renderer(threads=2), Renderer(threads=1)
    for r in (a, b):
        random_levels(r.gl, r.gl.TEXTURE_2D, 32, 32)
        set_params(r.gl, r.gl.TEXTURE_2D, "LINEAR_MIPMAP_LINEAR", "LINEAR")
    c0, cx, cy, special = MAPS["minified-rotated"]
    for first, second in ((GENERAL, BEST), (SCALAR, GENERAL), (GENERAL, AVX2)):
        use_path(a.gl, first)
        use_path(b.gl, second)
        for _ in range(2):
            for r in (a, b):
                r.draw(fs(LOOKUPS["implicit"]), c0, cx, cy, special)
        assert (fast_queries(a.gl) > 0) == (first != GENERAL), (first, fast_queries(a.gl))
        assert (fast_queries(b.gl) > 0) == (second != GENERAL), (second, fast_queries(b.gl))


def test_fast_path_webgl1_npot_clamped():
    # WebGL 1 (ES 2.0 + WebGL 1.0 §5.13.8): NPOT textures are complete with CLAMP_TO_EDGE and no
    # mipmaps only; drawn into the RGBA8 default framebuffer.
    gl = softgl.Context(W, H, version=1, antialias=False)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 13, 7, 0, gl.RGBA, gl.UNSIGNED_BYTE,
                  RNG.integers(0, 256, (7, 13, 4), dtype=np.uint8))
    vs = """attribute vec2 pos; uniform vec3 c0, cx, cy; varying vec2 uv;
    void main() { vec2 f = pos * 0.5 + 0.5; uv = (c0 + f.x * cx + f.y * cy).xy; gl_Position = vec4(pos, 0.0, 1.0); }"""
    fs1 = "precision highp float; uniform sampler2D tex; varying vec2 uv; void main() { gl_FragColor = texture2D(tex, uv); }"
    prog = softgl.program(gl, vs, fs1)
    for wrap, expect_fast in (("CLAMP_TO_EDGE", True), ("REPEAT", False)):
        set_params(gl, gl.TEXTURE_2D, "LINEAR", "LINEAR", wrap, wrap)
        images = []
        for path in PATHS:
            use_path(gl, path)
            draw_quad(gl, prog, *MAPS["minified-rotated"][:3])
            images.append(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE))
            assert (fast_queries(gl) > 0) == (expect_fast and path != GENERAL)
        for img in images[1:]:
            np.testing.assert_array_equal(img, images[0])


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("key", ["tex_nearest", "tex_bilinear", "tex_trilinear", "exec_tex2", "spot_mesh_tex"])
def test_benchmark_scenes_same_bytes_on_every_path(key, threads):
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    import scenes
    spec = {s.key: s for s in scenes.SUITE + scenes.EXECUTOR + scenes.TEXTURED}[key]
    size = 72
    images = []
    for path in PATHS:
        r = scenes.SoftglRenderer(size, size, threads=threads)
        use_path(r.gl, path)
        images.append(r.render(spec.build(size)))
        assert (fast_queries(r.gl) > 0) == (path != GENERAL)
    assert images[0].any()
    for img in images[1:]:
        np.testing.assert_array_equal(img, images[0])
