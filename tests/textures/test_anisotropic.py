"""EXT_texture_filter_anisotropic: softgl's rule (cpp/softgl/surface/sampler.cpp, "anisotropic
filtering": the extension specification's suggested method) against a float64 NumPy computation
of the same rule, bit-equality with the isotropic lookup where N = 1, and the same bytes at every
SIMD level and thread count."""
import numpy as np
import pytest

import softgl
from helpers import fs3, near_weight_tie, pixel_coords, render_float, sample_mipmapped

def mip_texture(gl, size=32, seed=21):
    """Random, independent levels (so that a wrong level or probe shows); the same for a seed."""
    rng = np.random.default_rng(seed)
    levels = []
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    level, n = 0, size
    while n >= 1:
        img8 = rng.integers(0, 256, (n, n, 4), dtype=np.uint8)
        gl.texImage2D(gl.TEXTURE_2D, level, gl.RGBA, n, n, 0, gl.RGBA, gl.UNSIGNED_BYTE, img8)
        levels.append(img8 / 255.0)
        level, n = level + 1, n // 2
    return tex, levels


def anisotropic_reference(levels, s, t, kx, ky, max_aniso, min_filter, mag_filter="LINEAR"):
    """The rule in float64: Px, Py in texels per pixel (kx, ky here: the quad is affine), N probes
    at lambda' = log2(Pmax / N) spread along the major axis; magnified pixels are isotropic."""
    size = levels[0].shape[0]
    pmax, pmin = max(kx, ky), min(kx, ky)
    if np.log2(pmax) <= 0:
        return sample_mipmapped(levels, s, t, np.full(s.shape, np.log2(pmax)), min_filter, mag_filter, weights8=True), [(s, t)]
    n = int(min(np.ceil(pmax / pmin - 1 / 64), np.floor(min(max_aniso, 16))))
    lam = np.full(s.shape, np.log2(pmax / n))
    step = np.array([kx / size, 0.0]) if kx > ky else np.array([0.0, ky / size])   # d(s, t) per pixel
    total = np.zeros(s.shape + (4,))
    probes = []
    for i in range(1, n + 1):
        off = i / (n + 1) - 0.5
        ps, pt = s + off * step[0], t + off * step[1]
        probes.append((ps, pt))
        total += sample_mipmapped(levels, ps, pt, lam, min_filter, mag_filter, weights8=True)
    return total / n, probes


def render(min_filter, kx, ky, max_aniso, *, extension=True, **context):
    gl = softgl.Context(8, 8, antialias=False, **context)
    _, levels = mip_texture(gl)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, getattr(gl, min_filter))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR)
    if extension:
        ext = gl.getExtension("EXT_texture_filter_anisotropic")
        gl.texParameterf(gl.TEXTURE_2D, ext.TEXTURE_MAX_ANISOTROPY_EXT, max_aniso)
    W = H = 16
    c0 = (0.0137, 0.0291, 0)
    cx, cy = (kx * W / 32, 0, 0), (0, ky * H / 32, 0)
    got = render_float(gl, fs3(), W, H, c0, cx, cy)
    assert gl.getError() == gl.NO_ERROR
    return got, levels, pixel_coords(W, H, c0, cx, cy)


# (texels per pixel along x, along y, TEXTURE_MAX_ANISOTROPY_EXT): N and lambda' in the comment.
CASES = [(5.3, 1.2, 16.0),    # N = 5, lambda' = 0.084
         (1.1, 11.0, 4.0),    # N = 4 (the limit), lambda' = 1.46, along y
         (9.7, 2.2, 8.0),     # N = 5, lambda' = 0.956
         (13.0, 1.3, 6.5),    # N = 6 (floor of 6.5), lambda' = 1.115
         (40.0, 3.1, 16.0),   # N = 13, lambda' = 1.62
         (3.0, 2.9, 16.0)]    # N = 2 (ratio 1.03), lambda' = 0.58


@pytest.mark.parametrize("min_filter", ["LINEAR_MIPMAP_LINEAR", "NEAREST_MIPMAP_NEAREST", "LINEAR"])
@pytest.mark.parametrize("kx, ky, max_aniso", CASES)
def test_against_float64_rule(min_filter, kx, ky, max_aniso):
    got, levels, (s, t, _) = render(min_filter, kx, ky, max_aniso)
    ref, probes = anisotropic_reference(levels, s, t, kx, ky, max_aniso, min_filter)
    # float32 probe coordinates (from the pipeline's interpolated derivatives) may round an 8-bit
    # weight (README "Choices") the other way near a tie: that moves a probe by at most 1/256 of
    # a texel difference. Everywhere within that; almost everywhere to float rounding.
    err = np.abs(got - ref).max(axis=2)
    assert err.max() < 1 / 256 + 1e-5
    assert (err < 1e-5).mean() > 0.85
    # and it is not the isotropic lookup
    iso, _, _ = render(min_filter, kx, ky, max_aniso, extension=False)
    assert np.abs(got - iso).max() > 0.01


@pytest.mark.parametrize("kx, ky", [(2.7, 2.7), (2.7, 2.68), (0.6, 0.15), (0.9, 0.05)],
                         ids=["isotropic", "ratio-within-1/64", "magnified", "magnified-thin"])
def test_one_probe_and_magnification_are_the_isotropic_lookup(kx, ky):
    got, _, _ = render("LINEAR_MIPMAP_LINEAR", kx, ky, 16.0)
    iso, _, _ = render("LINEAR_MIPMAP_LINEAR", kx, ky, 16.0, extension=False)
    np.testing.assert_array_equal(got, iso)


def test_anisotropy_one_is_isotropic():
    got, _, _ = render("LINEAR_MIPMAP_LINEAR", 9.7, 2.2, 1.0)
    iso, _, _ = render("LINEAR_MIPMAP_LINEAR", 9.7, 2.2, 1.0, extension=False)
    np.testing.assert_array_equal(got, iso)


def test_same_bits_every_simd_level_and_thread_count():
    """A perspective floor (derivatives differ per pixel) drawn RGBA8 with anisotropy 16."""
    vs = """#version 300 es
    in vec2 pos; out vec2 uv;
    void main() { float w = 1.0 + (pos.y * 0.5 + 0.5) * 7.0;   // receding: w grows upwards
                  uv = (pos * 0.5 + 0.5) * vec2(2.0, 8.0);
                  gl_Position = vec4(pos * w, 0.0, w); }"""
    fs = """#version 300 es
    precision highp float; uniform sampler2D tex; in vec2 uv; out vec4 o;
    void main() { o = texture(tex, uv); }"""
    results = []
    from softgl import _core
    simd = ["scalar", "sse2", "avx2", "avx512"][:_core.testing.simd_level() + 1]
    configs = [(1, lv, "best", True) for lv in simd] + [(2, simd[-1], "best", True), (1, simd[-1], "general", True),
                                                        (1, simd[-1], "best", False)]
    for threads, level, path, aniso in configs:
        if True:
            gl = softgl.Context(64, 48, threads=threads, antialias=False)
            _core.testing.set_tuning(gl, simd=level, sampler_path=path)
            mip_texture(gl, 64)
            gl.generateMipmap(gl.TEXTURE_2D)
            gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR)
            ext = gl.getExtension("EXT_texture_filter_anisotropic")
            gl.texParameterf(gl.TEXTURE_2D, ext.TEXTURE_MAX_ANISOTROPY_EXT, 16.0 if aniso else 1.0)
            prog = softgl.program(gl, vs, fs)
            gl.useProgram(prog)
            buf = gl.createBuffer()
            gl.bindBuffer(gl.ARRAY_BUFFER, buf)
            gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 1, -1, -1, 1, -1, 1, 1, -1, 1, 1], np.float32), gl.STATIC_DRAW)
            gl.enableVertexAttribArray(0)
            gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
            gl.drawArrays(gl.TRIANGLES, 0, 6)
            results.append(gl.readPixels(0, 0, 64, 48, gl.RGBA, gl.UNSIGNED_BYTE))
    isotropic = results.pop()
    assert (np.abs(results[0].astype(int) - isotropic).max(axis=2) > 8).mean() > 0.2   # it filters otherwise
    for r in results[1:]:
        np.testing.assert_array_equal(r, results[0])
