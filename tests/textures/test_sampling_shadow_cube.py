"""The sampler's fast path for depth textures (sampler2DShadow / sampler2DArrayShadow:
ES 3.0 §3.8.16; softgl has no depth cube maps yet, and depth textures read without the comparison) and cube
maps (face selection ES 3.0 §3.8.10 table 3.21, seamless filtering §3.8.9.1 in WebGL 2, per-face
clamping in WebGL 1) must give the same bits as the general per-lane path: every depth format and
compare function, NEAREST / LINEAR / mipmapped filters, references below 0, above 1, infinite and
NaN, directions on every face, across edges and corners, magnified and minified. Each image is
drawn by the general path, the fast path without SIMD, with AVX2 blocks and with the best SIMD
(test_sampling_fast_path.Renderer) and compared as uint32 bits (NaNs as NaNs); gl.stats() shows
that the fast path served the lookups."""
import itertools

import numpy as np
import pytest

import softgl
from helpers import draw_quad
from test_sampling_fast_path import MAPS, PATHS, GENERAL, Renderer, fast_queries, fs, set_params, use_path

RNG = np.random.default_rng(1807)
COMPARE_FUNCS = ["LEQUAL", "GEQUAL", "LESS", "GREATER", "EQUAL", "NOTEQUAL", "ALWAYS", "NEVER"]
FILTERS = [("NEAREST", "NEAREST"), ("LINEAR", "LINEAR"), ("NEAREST_MIPMAP_NEAREST", "LINEAR"),
           ("LINEAR_MIPMAP_LINEAR", "LINEAR"), ("LINEAR_MIPMAP_NEAREST", "NEAREST")]


def depth_levels(gl, target, fmt, w, h, layers=0, quantized=False):
    """A full mip chain of random depths; quantized: few distinct values, so that EQUAL passes."""
    internal, type_, dtype, scale = {
        "DEPTH_COMPONENT16": (gl.DEPTH_COMPONENT16, gl.UNSIGNED_SHORT, np.uint16, 65535),
        "DEPTH_COMPONENT24": (gl.DEPTH_COMPONENT24, gl.UNSIGNED_INT, np.uint32, 2 ** 32 - 1),
        "DEPTH_COMPONENT32F": (gl.DEPTH_COMPONENT32F, gl.FLOAT, np.float32, 1.0)}[fmt]
    tex = gl.createTexture()
    gl.bindTexture(target, tex)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    level = 0
    while True:
        shape = ((layers,) if layers else ()) + (h, w)
        d = RNG.integers(0, 5, shape) / 4.0 if quantized else RNG.uniform(0, 1, shape)
        data = (d * scale).astype(dtype) if dtype != np.float32 else d.astype(np.float32)
        if layers:
            gl.texImage3D(target, level, internal, w, h, layers, 0, gl.DEPTH_COMPONENT, type_, data)
        else:
            gl.texImage2D(target, level, internal, w, h, 0, gl.DEPTH_COMPONENT, type_, data)
        if w == 1 and h == 1:
            break
        w, h, level = max(1, w // 2), max(1, h // 2), level + 1
    return tex


SHADOW_LOOKUPS = {
    "implicit": "vec4(texture(tex, vec3(p.xy, ref)))",
    "bias": "vec4(texture(tex, vec3(p.xy, ref), lod))",
    "explicit": "vec4(textureLod(tex, vec3(p.xy, ref), lod))",
    "offset": "vec4(textureOffset(tex, vec3(p.xy, ref), ivec2(2, -1)))",
}


def shadow_fs(lookup, sampler="sampler2DShadow"):
    # The reference runs from -0.2 to 1.2 across the viewport, and is infinite or NaN (0 * inf)
    # on the three left columns of the "non-finite" map.
    return fs(lookup, sampler).replace("    color = ", "    float ref = gl_FragCoord.x < 3.0 ? p.z * special.x : p.z;\n    color = ")


@pytest.mark.parametrize("fmt", ["DEPTH_COMPONENT16", "DEPTH_COMPONENT24", "DEPTH_COMPONENT32F"])
def test_shadow_2d_fast_equals_general(fmt):
    r = Renderer()
    gl = r.gl
    depth_levels(gl, gl.TEXTURE_2D, fmt, 16, 12)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE)
    for func in COMPARE_FUNCS:
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_FUNC, getattr(gl, func))
        for min_filter, mag_filter in FILTERS:
            set_params(gl, gl.TEXTURE_2D, min_filter, mag_filter, "CLAMP_TO_EDGE", "MIRRORED_REPEAT")
            for name, lookup in SHADOW_LOOKUPS.items():
                for c0, cx, cy, special in MAPS.values():
                    img = r.compare(shadow_fs(lookup), c0[:2] + (-0.2,), cx[:2] + (1.4,), cy, special, 0.6)
                    # (c, c, c, 1) filtered: red = green = blue.
                    assert np.array_equal(img[..., 0].view(np.uint32), img[..., 2].view(np.uint32))


@pytest.mark.parametrize("fmt", ["DEPTH_COMPONENT16", "DEPTH_COMPONENT24", "DEPTH_COMPONENT32F"])
@pytest.mark.parametrize("size", [(16, 16), (13, 7)], ids=["pot", "npot"])
def test_shadow_fixed_filter_blocks_equal_general(fmt, size):
    # One filter, no mipmaps, both axes CLAMP_TO_EDGE or both REPEAT: at AVX-512 the blocks of 16
    # lanes (depth_block16; REPEAT of other sizes keeps the blocks of 8), with and without texel
    # offsets, and the depth read without the comparison.
    r = Renderer()
    gl = r.gl
    depth_levels(gl, gl.TEXTURE_2D, fmt, *size)
    for wrap in ("CLAMP_TO_EDGE", "REPEAT"):
        for filt in ("NEAREST", "LINEAR"):
            set_params(gl, gl.TEXTURE_2D, filt, filt, wrap, wrap)
            gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE)
            for func in COMPARE_FUNCS:
                gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_FUNC, getattr(gl, func))
                for name in ("implicit", "offset"):
                    for c0, cx, cy, special in list(MAPS.values())[:2]:
                        r.compare(shadow_fs(SHADOW_LOOKUPS[name]), c0[:2] + (-0.2,), cx[:2] + (1.4,), cy, special, 0.0)
            gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, gl.NONE)
            if filt == "NEAREST":   # (depth is not filterable without the comparison)
                for c0, cx, cy, special in MAPS.values():
                    img = r.compare(fs("texture(tex, p.xy)"), c0, cx, cy, special)
                    assert (img[..., 3] == 1).all()


def test_shadow_equal_compare_and_wraps():
    # Depths of a few values and references on them, so that EQUAL and NOTEQUAL both pass and fail.
    r = Renderer()
    gl = r.gl
    depth_levels(gl, gl.TEXTURE_2D, "DEPTH_COMPONENT32F", 8, 8, quantized=True)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE)
    source = fs("vec4(texture(tex, vec3(p.xy, floor(p.z * 4.0) / 4.0)))", "sampler2DShadow")
    for func in ("EQUAL", "NOTEQUAL"):
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_FUNC, getattr(gl, func))
        for wrap in ("REPEAT", "CLAMP_TO_EDGE", "MIRRORED_REPEAT"):
            set_params(gl, gl.TEXTURE_2D, "LINEAR", "LINEAR", wrap, wrap)
            img = r.compare(source, (-0.6, -0.3, 0.0), (2.1, 0.2, 0.0), (0.1, 1.7, 4.9))
            assert 0.0 < img[..., 0].mean() < 1.0


def test_shadow_2d_array_and_depth_without_compare():
    r = Renderer()
    gl = r.gl
    depth_levels(gl, gl.TEXTURE_2D_ARRAY, "DEPTH_COMPONENT24", 12, 10, layers=4)
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE)
    for min_filter, mag_filter in FILTERS:
        set_params(gl, gl.TEXTURE_2D_ARRAY, min_filter, mag_filter, "REPEAT", "CLAMP_TO_EDGE")
        for c0, cx, cy, special in MAPS.values():
            # The layer runs from below 0 to beyond the last layer, the reference with gl_FragCoord.x.
            src = fs("vec4(texture(tex, vec4(p, gl_FragCoord.x / 20.0 - 0.1)))", "sampler2DArrayShadow")
            r.compare(src, c0[:2] + (-1.3,), cx[:2] + (3.1,), cy[:2] + (4.2,), special)
    # A depth texture read as a plain sampler2D (NEAREST: depth is not filterable without the
    # comparison): (d, 0, 0, 1).
    depth_levels(gl, gl.TEXTURE_2D, "DEPTH_COMPONENT16", 16, 16)
    set_params(gl, gl.TEXTURE_2D, "NEAREST_MIPMAP_NEAREST", "NEAREST", "REPEAT", "REPEAT")
    for c0, cx, cy, special in MAPS.values():
        img = r.compare(fs("texture(tex, p.xy, lod)"), c0, cx, cy, special, 0.3)
    assert (img[..., 1] == 0).all() and (img[..., 3] == 1).all()


# Directions over the viewport (c0, cx, cy of the xyz direction): across several faces and their
# edges and corners, magnified (a few texels over the viewport) and minified (many turns).
CUBE_MAPS = {
    "faces-and-edges": ((-1.3, -1.1, 0.9), (2.6, 0.3, -1.5), (0.2, 2.4, -0.6)),
    "corner": ((0.7, 0.8, 0.9), (0.6, -0.2, 0.1), (-0.1, 0.5, 0.2)),
    "minified": ((-5.0, 3.0, -1.0), (31.0, -7.0, 2.0), (5.0, 26.0, -9.0)),
    "axis-ties": ((-1.0, -1.0, 1.0), (2.0, 0.0, 0.0), (0.0, 2.0, 0.0)),
}
CUBE_LOOKUPS = {
    "implicit": "texture(tex, p)",
    "bias": "texture(tex, p, lod)",
    "explicit": "textureLod(tex, p, lod)",
    "gradient": "textureGrad(tex, p, vec3(0.05 * lod, 0.01, 0.0), vec3(0.0, 0.07, -0.02 * lod))",
}


def cube_levels(gl, size, internal=None, type_=None, dtype=np.uint8):
    internal = gl.RGBA8 if internal is None else internal
    type_ = gl.UNSIGNED_BYTE if type_ is None else type_
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, tex)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    level = 0
    while size >= 1:
        for face in range(6):
            if dtype == np.uint8:
                data = RNG.integers(0, 256, (size, size, 4), dtype=np.uint8)
            else:
                data = RNG.uniform(-300, 300, (size, size, 4)).astype(np.float16).astype(dtype)
            gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, level, internal, size, size, 0, gl.RGBA, type_, data)
        size, level = size // 2, level + 1
    return tex


@pytest.mark.parametrize("fmt", ["RGBA8", "RGBA16F"])
@pytest.mark.parametrize("min_filter,mag_filter", FILTERS + [("NEAREST_MIPMAP_LINEAR", "NEAREST")])
def test_cube_fast_equals_general(min_filter, mag_filter, fmt):
    r = Renderer()
    gl = r.gl
    if fmt == "RGBA8":
        cube_levels(gl, 8)
    else:
        cube_levels(gl, 8, gl.RGBA16F, gl.FLOAT, np.float32)
    set_params(gl, gl.TEXTURE_CUBE_MAP, min_filter, mag_filter)
    for name, lookup in CUBE_LOOKUPS.items():
        for c0, cx, cy in CUBE_MAPS.values():
            for lod in ((-0.4, 1.7) if name != "implicit" else (0.0,)):
                r.compare(fs(lookup, "samplerCube"), c0, cx, cy, (1.0, 0.0), lod)
    # Non-finite directions and derivatives.
    c0, cx, cy, special = MAPS["non-finite"]
    r.compare(fs("texture(tex, vec3(p.xy, 0.6))", "samplerCube"), c0, cx, cy, special)


def test_cube_webgl1_clamps_per_face():
    # WebGL 1 (ES 2.0 §3.7.5): no seamless filtering, each face is clamped to its edge; drawn into
    # the RGBA8 default framebuffer.
    W, H = 29, 23
    gl = softgl.Context(W, H, version=1, antialias=False)
    cube_levels(gl, 8, gl.RGBA)
    vs = """attribute vec2 pos; uniform vec3 c0, cx, cy; varying vec3 d;
    void main() { vec2 f = pos * 0.5 + 0.5; d = c0 + f.x * cx + f.y * cy; gl_Position = vec4(pos, 0.0, 1.0); }"""
    fs1 = "precision highp float; uniform samplerCube tex; varying vec3 d; void main() { gl_FragColor = textureCube(tex, d); }"
    prog = softgl.program(gl, vs, fs1)
    for min_filter, mag_filter in FILTERS:
        set_params(gl, gl.TEXTURE_CUBE_MAP, min_filter, mag_filter, "CLAMP_TO_EDGE", "CLAMP_TO_EDGE")
        for c0, cx, cy in CUBE_MAPS.values():
            images = []
            for path in PATHS:
                use_path(gl, path)
                draw_quad(gl, prog, c0, cx, cy)
                images.append(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE))
                assert (fast_queries(gl) > 0) == (path != GENERAL)
            assert images[0][..., :3].any()   # a texture was sampled, not (0, 0, 0, 1)
            for img in images[1:]:
                np.testing.assert_array_equal(img, images[0])


def test_large_shadow_and_cube_with_threads():
    # A bigger target over threads, where whole SIMD blocks and batches form.
    r = Renderer(97, 83, threads=3)
    gl = r.gl
    depth_levels(gl, gl.TEXTURE_2D, "DEPTH_COMPONENT24", 64, 48)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE)
    set_params(gl, gl.TEXTURE_2D, "LINEAR_MIPMAP_LINEAR", "LINEAR")
    r.compare(shadow_fs(SHADOW_LOOKUPS["implicit"]), (0.1, 0.2, -0.1), (3.0, 0.4, 1.2), (-0.5, 2.0, 0.0))
    gl.activeTexture(gl.TEXTURE1)
    cube_levels(gl, 32)
    set_params(gl, gl.TEXTURE_CUBE_MAP, "LINEAR_MIPMAP_LINEAR", "LINEAR")
    gl.activeTexture(gl.TEXTURE0)
    source = fs(CUBE_LOOKUPS["implicit"], "samplerCube")
    prog = softgl.program(gl, __import__("helpers").VS3, source)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "tex"), 1)
    r.programs[source] = prog
    for c0, cx, cy in CUBE_MAPS.values():
        r.compare(source, c0, cx, cy)


@pytest.mark.parametrize("key", ["cubemap_env", "shadow_map"])
def test_ordinary_benchmark_scenes_same_bytes_on_every_path(key):
    """benchmarks/ordinary.py's cube-map and shadow scenes (blocks of 8 cube lanes on one face;
    depth-compare sums of 8 lanes): every sampler path and thread count gives the general path's bytes."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    import ordinary
    spec = ordinary.ALL[key]
    w, h = 128, 96
    images = []
    for path in PATHS:
        for threads in (1, 2):
            gl = softgl.Context(w, h, antialias=False, threads=threads)
            use_path(gl, path)
            spec.setup(gl, w, h)()
            assert (fast_queries(gl) > 0) == (path != GENERAL)
            images.append(ordinary.canvas_pixels(gl))
    assert images[0].std() > 10
    for img in images[1:]:
        np.testing.assert_array_equal(img, images[0])


@pytest.mark.parametrize("fmt", ["RGBA8", "RGBA16F"])
@pytest.mark.parametrize("min_filter,mag_filter", [("LINEAR", "LINEAR"), ("NEAREST", "NEAREST"),
                                                   ("LINEAR_MIPMAP_LINEAR", "LINEAR")])
def test_cube_queries_of_every_lane_count(min_filter, mag_filter, fmt):
    # Small canvases and triangles: queries whose last 1-7 lanes the cube blocks take as one
    # padded block of 8 (sampler.cpp sample_2d), across face edges (seamless: those lanes again
    # by sample_lane), with implicit and explicit LODs; every path gives the general path's bits.
    gl = softgl.Context(16, 16, antialias=False)
    if fmt == "RGBA8":
        cube_levels(gl, 8)
    else:
        cube_levels(gl, 8, gl.RGBA16F, gl.FLOAT, np.float32)
    set_params(gl, gl.TEXTURE_CUBE_MAP, min_filter, mag_filter)
    # The whole viewport (w h lanes), and its lower left half.
    tris = np.array([-1, -1, 3, -1, -1, 3, -1, -1, 1, -1, -1, 1], np.float32)
    for lookup in ("texture(tex, p)", "textureLod(tex, p, lod)"):
        prog = softgl.program(gl, VS_CUBE, fs(lookup, "samplerCube"))
        gl.useProgram(prog)
        gl.uniform1f(gl.getUniformLocation(prog, "lod"), 0.6)
        gl.uniform2f(gl.getUniformLocation(prog, "special"), 1.0, 0.0)
        buf = gl.createBuffer()
        gl.bindBuffer(gl.ARRAY_BUFFER, buf)
        gl.bufferData(gl.ARRAY_BUFFER, tris, gl.STATIC_DRAW)
        loc = gl.getAttribLocation(prog, "pos")
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
        for (w, h), first in itertools.product(((1, 1), (2, 1), (3, 1), (3, 2), (5, 3), (7, 1), (9, 2), (11, 5), (13, 7)),
                                               (0, 3)):
            gl.viewport(0, 0, w, h)
            images = []
            for path in PATHS:
                use_path(gl, path)
                gl.clearColor(0.25, 0.25, 0.25, 0.25)
                gl.clear(gl.COLOR_BUFFER_BIT)
                # A corner of three faces in the middle of the viewport.
                gl.uniform3f(gl.getUniformLocation(prog, "c0"), -1.1, -0.9, 1.0)
                gl.uniform3f(gl.getUniformLocation(prog, "cx"), 2.3, 0.2, -0.1)
                gl.uniform3f(gl.getUniformLocation(prog, "cy"), 0.1, 2.1, -0.2)
                gl.drawArrays(gl.TRIANGLES, first, 3)
                images.append(gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE))
                assert (fast_queries(gl) > 0) == (path != GENERAL) or (first and w * h < 4)
            assert (images[0] != 64).any() or (first and w * h < 4)
            for img in images[1:]:
                np.testing.assert_array_equal(img, images[0], err_msg=f"{lookup} {w}x{h}")


VS_CUBE = """#version 300 es
in vec2 pos;
uniform vec3 c0, cx, cy;
out vec3 uvw;
void main() {
    vec2 f = pos * 0.5 + 0.5;
    uvw = c0 + f.x * cx + f.y * cy;
    gl_Position = vec4(pos, 0.0, 1.0);
}
"""
