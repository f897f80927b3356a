"""Texture sampling against float64 NumPy references (ES 3.0 §3.8.10-11): every filter and wrap
mode, LOD selection on magnified/minified/anisotropic quads, explicit LOD, cube map faces and
seams, shadow comparison, sRGB decode, texelFetch/textureSize. Results are drawn into RGBA32F
targets so that they are compared as floats."""
import numpy as np
import pytest

import softgl
from helpers import fs3, near_weight_tie, pixel_coords, render_float, sample_level, sample_mipmapped

WRAPS = ["REPEAT", "CLAMP_TO_EDGE", "MIRRORED_REPEAT"]
RNG = np.random.default_rng(5)


def upload(gl, img8, unit=0, target=None):
    target = gl.TEXTURE_2D if target is None else target
    tex = gl.createTexture()
    gl.activeTexture(gl.TEXTURE0 + unit)
    gl.bindTexture(target, tex)
    h, w = img8.shape[:2]
    gl.texImage2D(target, 0, gl.RGBA, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, np.ascontiguousarray(img8))
    return tex


@pytest.mark.parametrize("wrap_s", WRAPS)
@pytest.mark.parametrize("wrap_t", WRAPS)
@pytest.mark.parametrize("filt", ["NEAREST", "LINEAR"])
def test_magnified_filters_and_wraps(filt, wrap_s, wrap_t):
    gl = softgl.Context(8, 8, antialias=False)
    img8 = RNG.integers(0, 256, (5, 3, 4), dtype=np.uint8)    # NPOT: all wraps allowed in WebGL 2
    upload(gl, img8)
    for pname, value in ((gl.TEXTURE_MIN_FILTER, filt), (gl.TEXTURE_MAG_FILTER, filt),
                         (gl.TEXTURE_WRAP_S, wrap_s), (gl.TEXTURE_WRAP_T, wrap_t)):
        gl.texParameteri(gl.TEXTURE_2D, pname, getattr(gl, value))
    W, H = 37, 29
    c0, cx, cy = (-1.37, -0.83, 0), (3.71, 0, 0), (0, 2.93, 0)   # magnified: < 1 texel per pixel
    got = render_float(gl, fs3(), W, H, c0, cx, cy)
    assert gl.getError() == gl.NO_ERROR
    s, t, _ = pixel_coords(W, H, c0, cx, cy)
    # RGBA8: LINEAR with 8-bit weights (README "Choices"), except where a weight is a rounding tie.
    ref = sample_level(img8 / 255.0, s, t, filt == "LINEAR", wrap_s, wrap_t, weights8=True)
    sure = ~near_weight_tie(s, t, [(3, 5)])
    assert sure.mean() > 0.9
    np.testing.assert_allclose(got[sure], ref[sure], atol=2e-6)


def mip_texture(gl, size=32):
    """A texture with random, independent levels (so that a wrong level shows)."""
    levels = []
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    level, n = 0, size
    while n >= 1:
        img8 = RNG.integers(0, 256, (n, n, 4), dtype=np.uint8)
        gl.texImage2D(gl.TEXTURE_2D, level, gl.RGBA, n, n, 0, gl.RGBA, gl.UNSIGNED_BYTE, img8)
        levels.append(img8 / 255.0)
        level, n = level + 1, n // 2
    return tex, levels


MIN_FILTERS = ["NEAREST", "LINEAR", "NEAREST_MIPMAP_NEAREST", "LINEAR_MIPMAP_NEAREST",
               "NEAREST_MIPMAP_LINEAR", "LINEAR_MIPMAP_LINEAR"]


@pytest.mark.parametrize("min_filter", MIN_FILTERS)
@pytest.mark.parametrize("scale", [(0.6, 0.6), (2.7, 2.7), (5.3, 1.2), (1.1, 11.0), (40.0, 40.0)],
                         ids=["magnified", "minified", "anisotropic-x", "anisotropic-y", "beyond-last-level"])
def test_lod_selection_from_derivatives(min_filter, scale):
    gl = softgl.Context(8, 8, antialias=False)
    _, levels = mip_texture(gl)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, getattr(gl, min_filter))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR)
    W = H = 16
    kx, ky = scale      # texels per pixel along x and y
    c0 = (0.0137, 0.0291, 0)
    cx, cy = (kx * W / 32, 0, 0), (0, ky * H / 32, 0)
    got = render_float(gl, fs3(), W, H, c0, cx, cy)
    assert gl.getError() == gl.NO_ERROR
    s, t, _ = pixel_coords(W, H, c0, cx, cy)
    # ES 3.0 eq. 3.19: rho = max of the two scale factors (isotropic, no anisotropic filtering).
    lam = np.full(s.shape, np.log2(max(kx, ky)))
    ref = sample_mipmapped(levels, s, t, lam, min_filter, "LINEAR", weights8=True)
    # float32 texel coordinates: u = s * 32 up to ~640 carries ~6e-5 of rounding into the
    # fractions, which can move an 8-bit weight (README "Choices") only near a rounding tie.
    used = {0, min(5, max(0, int(np.floor(lam[0, 0])))), min(5, max(0, int(np.floor(lam[0, 0])) + 1))}
    sure = ~near_weight_tie(s, t, [(32 >> k, 32 >> k) for k in used], eps=1.6e-2)
    assert sure.mean() > 0.6
    np.testing.assert_allclose(got[sure], ref[sure], atol=1e-5)


@pytest.mark.parametrize("lod", [-0.5, 0.0, 0.3, 1.0, 1.75, 2.5, 4.9, 7.0])
def test_explicit_lod(lod):
    gl = softgl.Context(8, 8, antialias=False)
    _, levels = mip_texture(gl)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST)
    W = H = 12
    c0, cx, cy = (0.021, 0.043, 0), (1.3, 0, 0), (0, 1.1, 0)
    got = render_float(gl, fs3(lookup="textureLod(tex, uvw.xy, lod)"), W, H, c0, cx, cy,
                       setup=lambda p: gl.uniform1f(gl.getUniformLocation(p, "lod"), lod))
    s, t, _ = pixel_coords(W, H, c0, cx, cy)
    ref = sample_mipmapped(levels, s, t, np.full(s.shape, lod), "LINEAR_MIPMAP_LINEAR", "NEAREST", weights8=True)
    sure = ~near_weight_tie(s, t, [(32 >> k, 32 >> k) for k in range(6)])
    assert sure.mean() > 0.8
    np.testing.assert_allclose(got[sure], ref[sure], atol=1e-5)


def test_min_max_lod_and_base_level_clamp():
    gl = softgl.Context(8, 8, antialias=False)
    _, levels = mip_texture(gl)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST_MIPMAP_NEAREST)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_BASE_LEVEL, 1)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAX_LEVEL, 3)
    gl.texParameterf(gl.TEXTURE_2D, gl.TEXTURE_MAX_LOD, 1.0)
    W = H = 4
    c0, cx, cy = (0.01, 0.02, 0), (1, 0, 0), (0, 1, 0)
    got = render_float(gl, fs3(lookup="textureLod(tex, uvw.xy, 10.0)"), W, H, c0, cx, cy)
    s, t, _ = pixel_coords(W, H, c0, cx, cy)
    # lambda clamped to MAX_LOD = 1 -> level base + 1 = 2 (nearest level for lambda 1: ceil(1.5) - 1).
    np.testing.assert_allclose(got, sample_level(levels[2], s, t, False), atol=1e-6)


FACE_COLORS = np.array([[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255],
                        [255, 255, 0, 255], [255, 0, 255, 255], [0, 255, 255, 255]], np.uint8)


def cube_texture(gl, size=4, faces=None):
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, tex)
    for f in range(6):
        img = np.broadcast_to(FACE_COLORS[f], (size, size, 4)).copy() if faces is None else faces[f]
        gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, 0, gl.RGBA, size, size, 0, gl.RGBA, gl.UNSIGNED_BYTE, img)
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAG_FILTER, gl.NEAREST)
    return tex


def test_cube_face_selection_and_face_coordinates():
    gl = softgl.Context(8, 8, antialias=False)
    size = 4
    faces = RNG.integers(0, 256, (6, size, size, 4), dtype=np.uint8)
    cube_texture(gl, size, faces)
    # Directions over a sphere of the grid (W x H pixels): x in [-1, 1], y in [-1, 1], z fixed per row band.
    W, H = 24, 24
    c0, cx, cy = (-1.013, -0.977, 0.611), (2.05, 0, -1.3), (0, 2.01, 0)
    got = render_float(gl, fs3("samplerCube", "texture(tex, uvw)"), W, H, c0, cx, cy)
    rx, ry, rz = pixel_coords(W, H, c0, cx, cy)
    # ES 3.0 table 3.21
    ax, ay, az = np.abs(rx), np.abs(ry), np.abs(rz)
    face = np.where((ax >= ay) & (ax >= az), np.where(rx >= 0, 0, 1),
                    np.where(ay >= az, np.where(ry >= 0, 2, 3), np.where(rz >= 0, 4, 5)))
    sc = np.choose(face, [-rz, rz, rx, rx, rx, -rx])
    tc = np.choose(face, [-ry, -ry, rz, -rz, -ry, -ry])
    ma = np.choose(face, [ax, ax, ay, ay, az, az])
    s, t = (sc / ma + 1) / 2, (tc / ma + 1) / 2
    i = np.clip(np.floor(s * size).astype(int), 0, size - 1)
    j = np.clip(np.floor(t * size).astype(int), 0, size - 1)
    ref = faces[face, j, i] / 255.0
    np.testing.assert_allclose(got, ref, atol=1e-6)


def test_cube_seams_are_filtered_across_faces_in_webgl2():
    # Exactly on the +X/+Z edge, LINEAR filtering averages texels of both faces (ES 3.0 §3.8.9.1
    # seamless filtering); WebGL 1 clamps inside one face.
    results = {}
    for version in (1, 2):
        gl = softgl.Context(1, 1, version=version, antialias=False)
        tex = cube_texture(gl, 2)
        gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAG_FILTER, gl.LINEAR)
        gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER, gl.LINEAR)
        fs = """precision highp float; uniform samplerCube tex;
        void main() { gl_FragColor = textureCube(tex, vec3(1.0, 0.0001, 0.9999)); }"""
        vs = "attribute vec2 pos; void main() { gl_Position = vec4(pos, 0.0, 1.0); }"
        prog = softgl.program(gl, vs, fs)
        from helpers import draw_quad
        draw_quad(gl, prog)
        results[version] = gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)[0, 0]
    # +X is red, +Z is magenta: across the seam blue is mixed in (about half).
    assert results[1][2] < 5
    assert 100 < results[2][2] < 155


def test_shadow_comparison_with_pcf():
    gl = softgl.Context(8, 8, antialias=False)
    depth = np.array([[0.1, 0.3], [0.6, 0.9]], np.float32)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.DEPTH_COMPONENT32F, 2, 2, 0, gl.DEPTH_COMPONENT, gl.FLOAT, depth)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_FUNC, gl.LEQUAL)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE)
    W = H = 10
    c0, cx, cy = (0.0, 0.0, 0.0), (1, 0, 0.7), (0, 1, 0.35)
    got = render_float(gl, fs3("sampler2DShadow", "texture(tex, uvw)", ""), W, H, c0, cx, cy)
    assert gl.getError() == gl.NO_ERROR
    s, t, r = pixel_coords(W, H, c0, cx, cy)
    # ES 3.0 §3.8.16: compare each texel (ref <= D), then filter the 0/1 results.
    passed = (np.clip(r, 0, 1)[..., None, None] <= depth).astype(np.float64)
    ref = np.stack([sample_level(np.repeat(passed[y, x][..., None], 4, axis=2), s[y, x], t[y, x], True,
                                 "CLAMP_TO_EDGE", "CLAMP_TO_EDGE")[0] for y in range(H) for x in range(W)]).reshape(H, W)
    np.testing.assert_allclose(got[..., 0], ref, atol=1e-6)


def test_srgb_texels_decode_before_filtering():
    gl = softgl.Context(8, 8, antialias=False)
    img = np.arange(0, 256, dtype=np.uint8)[:, None].repeat(4, axis=1).reshape(16, 16, 4).copy()
    img[..., 3] = 200
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.SRGB8_ALPHA8, 16, 16, 0, gl.RGBA, gl.UNSIGNED_BYTE, img)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST)
    got = render_float(gl, fs3(), 16, 16, (0, 0, 0), (1, 0, 0), (0, 1, 0))
    c = img / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)   # ES 3.0 eq. 3.24
    lin[..., 3] = c[..., 3]
    np.testing.assert_allclose(got, lin, atol=1e-6)


def test_texel_fetch_and_texture_size():
    gl = softgl.Context(8, 8, antialias=False)
    tex, levels = mip_texture(gl, 8)
    got = render_float(gl, fs3(lookup="texelFetch(tex, ivec2(uvw.xy), 1)"), 4, 4, (0, 0, 0), (4, 0, 0), (0, 4, 0))
    np.testing.assert_allclose(got, levels[1], atol=1e-7)
    size = render_float(gl, fs3(lookup="vec4(textureSize(tex, 0), textureSize(tex, 2))"), 1, 1, (0, 0, 0), (1, 0, 0), (0, 1, 0))
    np.testing.assert_array_equal(size[0, 0], [8, 8, 2, 2])


def test_integer_texture_fetches_exact_values():
    gl = softgl.Context(8, 8, antialias=False)
    vals = np.array([[[-2147483648, 7, -1, 2147483647]]], np.int32)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32I, 1, 1, 0, gl.RGBA_INTEGER, gl.INT, vals)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST)
    fs = """#version 300 es
    precision highp float; precision highp isampler2D;
    uniform isampler2D tex; in vec3 uvw; out vec4 color;
    void main() { ivec4 v = texture(tex, uvw.xy); color = vec4(v == ivec4(-2147483648, 7, -1, 2147483647)); }"""
    got = render_float(gl, fs, 1, 1, (0, 0, 0), (1, 0, 0), (0, 1, 0))
    np.testing.assert_array_equal(got[0, 0], [1, 1, 1, 1])
