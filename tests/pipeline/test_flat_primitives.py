"""A primitive whose varyings have the same bits at every vertex is shaded once per primitive and
tile (pipeline/tile_pass.cpp, FragmentShader::run_flat): interpolation returns exactly that value
at every pixel where the weights are finite (pipeline/interpolate.h), so every fragment's colour is
the same. It must give the bytes of the general path -- the same shader plus 0.0 * gl_FragCoord.x,
which reads a built-in and so is shaded per fragment -- at every SIMD level and thread count, and
the colour computed by hand. A primitive whose values differ by one ulp, or are -0, is not flat."""
import numpy as np
import pytest

import softgl
from softgl import _core

SIZE = 96   # 2 x 2 tiles of 64: primitives cross tile borders
VS = """#version 300 es
in vec4 aPos;
in float aShade;
out float vShade;
void main() { gl_Position = aPos; vShade = aShade; }
"""
FLAT_FS = """#version 300 es
precision highp float;
uniform vec4 uColor;
in float vShade;
out vec4 fragColor;
void main() { fragColor = vec4(uColor.rgb * vShade, uColor.a); }
"""
# The same colour per fragment: c + 0.0 == c for every c but -0, and the colour is then clamped.
GENERAL_FS = """#version 300 es
precision highp float;
uniform vec4 uColor;
in float vShade;
out vec4 fragColor;
void main() { fragColor = vec4(uColor.rgb * vShade, uColor.a) + vec4(0.0 * gl_FragCoord.x); }
"""
BACKGROUND = (51, 102, 153, 255)
COLOR = (0.9, 0.6, 0.3, 0.45)


def scene(seed, flat, count=24):
    """Perspective triangles (w from 0.4 to 3 per vertex): positions and per-vertex shades, the same
    three times per triangle when `flat`, else the third one ulp up."""
    rng = np.random.default_rng(seed)
    pos, shade = [], []
    for _ in range(count):
        w = rng.uniform(0.4, 3.0, 3)
        xy = rng.uniform(-1.1, 1.1, (3, 2))
        z = rng.uniform(-0.9, 0.9, 3)
        for k in range(3):
            pos.append([xy[k, 0] * w[k], xy[k, 1] * w[k], z[k] * w[k], w[k]])
        s = np.float32(rng.uniform(0.2, 1.4))
        third = s if flat else np.nextafter(s, np.float32(2))
        shade += [s, s, third]
    return np.array(pos, np.float32), np.array(shade, np.float32)


def alpha_blend(gl):
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)


def additive(gl):
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)


def depth_less(gl):
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.LESS)
    alpha_blend(gl)


def color_mask(gl):
    alpha_blend(gl)
    gl.colorMask(True, False, True, True)


SETUPS = {"plain": None, "alpha_blend": alpha_blend, "additive": additive, "depth_less": depth_less,
          "color_mask": color_mask}


def render(fs, pos, shade, setup=None, threads=1, simd=None, samples=0, flat_primitives=True, batches=True):
    kw = dict(antialias=samples > 0, threads=threads, preserveDrawingBuffer=True)
    if samples:
        kw["samples"] = samples
    gl = softgl.Context(SIZE, SIZE, **kw)
    if simd:
        _core.testing.set_tuning(gl, simd=simd)
    # Full batches gather a primitive's small chunks (those take no flat colour): off, every chunk
    # of a flat primitive takes it.
    _core.testing.set_tuning(gl, flat_primitives=flat_primitives, fragment_batches=batches)
    prog = softgl.program(gl, VS, fs)
    gl.useProgram(prog)
    gl.bindVertexArray(gl.createVertexArray())
    for loc, data, size in ((gl.getAttribLocation(prog, "aPos"), pos, 4), (gl.getAttribLocation(prog, "aShade"), shade, 1)):
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, size, gl.FLOAT, False, 0, 0)
    gl.clearColor(*(c / 255 for c in BACKGROUND))
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    if setup:
        setup(gl)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), *COLOR)
    gl.stats(reset=True)
    gl.drawArrays(gl.TRIANGLES, 0, len(pos))
    stats = {k: v for k, v in gl.stats().items() if not k.startswith("seconds")}
    if samples:
        return _core.testing.read_color_samples(gl), stats
    return gl.readPixels(0, 0, SIZE, SIZE, gl.RGBA, gl.UNSIGNED_BYTE), stats


@pytest.mark.parametrize("setup", sorted(SETUPS))
@pytest.mark.parametrize("flat", [True, False])
def test_flat_primitives_give_the_general_paths_bytes(setup, flat):
    pos, shade = scene(seed=len(setup) + 100 * flat, flat=flat)
    reference, rc = render(GENERAL_FS, pos, shade, SETUPS[setup], simd="scalar")
    assert rc["fragments_flat"] == 0 and rc["draws_flat_primitives"] == 0
    assert rc["fragments_shaded"] > 0
    for threads, simd, batches in [(t, s, b) for t in (1, 2) for s in ("scalar", "sse2", "avx2", "avx512")
                                   for b in (True, False)]:
        image, c = render(FLAT_FS, pos, shade, SETUPS[setup], threads, simd, batches=batches)
        assert image.tobytes() == reference.tobytes(), (threads, simd, batches)
        assert c["draws_flat_primitives"] == 1
        if flat and not batches:   # every fragment of every primitive (finite weights)
            assert c["fragments_flat"] == c["fragments_shaded"] > 0
        elif flat:                 # small chunks gathered
            assert 0 < c["fragments_flat"] < c["fragments_shaded"]
        else:      # one ulp apart at a vertex: none
            assert c["fragments_flat"] == 0
        assert c["samples_written"] == rc["samples_written"]


@pytest.mark.parametrize("samples", [0, 4])
def test_flat_multisampled_equals_general(samples):
    pos, shade = scene(seed=7, flat=True)
    reference, _ = render(GENERAL_FS, pos, shade, alpha_blend, samples=samples)
    image, c = render(FLAT_FS, pos, shade, alpha_blend, samples=samples)
    assert c["fragments_flat"] > 0
    np.testing.assert_array_equal(image, reference)


def test_flat_colour_by_hand():
    # One opaque triangle covering the centre, w = 1, 2, 3 (perspective), shade 0.75 everywhere:
    # the colour is float32(uColor.rgb) * 0.75, alpha 0.45, each rounded to unorm8 (ES 3.0 §2.1.6.1).
    w = np.array([1.0, 2.0, 3.0])
    xy = np.array([[-0.9, -0.9], [0.9, -0.9], [0.0, 0.9]])
    pos = np.array([[xy[k, 0] * w[k], xy[k, 1] * w[k], 0.0, w[k]] for k in range(3)], np.float32)
    shade = np.full(3, 0.75, np.float32)
    image, c = render(FLAT_FS, pos, shade, batches=False)
    assert c["fragments_flat"] == c["fragments_shaded"] > 0
    expected = [round(float(np.float32(COLOR[i]) * np.float32(0.75)) * 255) for i in range(3)]
    expected.append(round(float(np.float32(COLOR[3])) * 255))
    centre = image.reshape(SIZE, SIZE, 4)[SIZE // 2, SIZE // 2]
    assert centre.tolist() == expected == [172, 115, 57, 115]


def test_one_ulp_apart_is_not_flat_and_interpolates():
    # The same triangle with the third shade one ulp up: shaded per fragment; the pixels still get
    # the 8-bit colour of the (almost equal) values.
    w = np.array([1.0, 2.0, 3.0])
    xy = np.array([[-0.9, -0.9], [0.9, -0.9], [0.0, 0.9]])
    pos = np.array([[xy[k, 0] * w[k], xy[k, 1] * w[k], 0.0, w[k]] for k in range(3)], np.float32)
    s = np.float32(0.75)
    shade = np.array([s, s, np.nextafter(s, np.float32(1))], np.float32)
    image, c = render(FLAT_FS, pos, shade, batches=False)
    assert c["fragments_flat"] == 0 and c["fragments_shaded"] > 0
    assert image.reshape(SIZE, SIZE, 4)[SIZE // 2, SIZE // 2].tolist() == [172, 115, 57, 115]


def test_negative_zero_is_not_flat():
    # -0 at every vertex: v_0 + (+0) is +0 where a weight is positive (interpolate.h), so -0 is
    # not kept at every pixel; such a primitive goes the general way.
    pos, _ = scene(seed=3, flat=True, count=4)
    shade = np.full(len(pos), -0.0, np.float32)
    reference, _ = render(GENERAL_FS, pos, shade, additive)
    image, c = render(FLAT_FS, pos, shade, additive, batches=False)
    assert c["fragments_flat"] == 0 and c["fragments_shaded"] > 0
    assert image.tobytes() == reference.tobytes()


@pytest.mark.parametrize("setup", ["plain", "alpha_blend", "depth_less"])
def test_flat_primitives_switched_off_is_the_same_shader_per_fragment(setup):
    # The same program with Tuning::flat_primitives off: every fragment shaded, the same bytes.
    pos, shade = scene(seed=11 + len(setup), flat=True)
    reference, rc = render(FLAT_FS, pos, shade, SETUPS[setup], simd="scalar", flat_primitives=False)
    assert rc["fragments_flat"] == 0 and rc["draws_flat_primitives"] == 0
    for threads in (1, 2):
        for simd in ("scalar", "sse2", "avx2", "avx512"):
            image, c = render(FLAT_FS, pos, shade, SETUPS[setup], threads, simd)
            assert image.tobytes() == reference.tobytes(), (threads, simd)
            assert 0 < c["fragments_flat"] <= c["fragments_shaded"]


def test_extreme_perspective_matches_the_switched_off_path():
    # w from 1e-3 to 1e4 at the vertices of a triangle: the 1/w plane spans 7 orders of magnitude
    # over a tile, where the bound (weights_finite_in) may not hold and the lanes are checked.
    rng = np.random.default_rng(17)
    pos, shade = [], []
    for _ in range(16):
        w = 10.0 ** rng.uniform(-3, 4, 3)
        xy = rng.uniform(-1.5, 1.5, (3, 2))
        for k in range(3):
            pos.append([xy[k, 0] * w[k], xy[k, 1] * w[k], 0.0, w[k]])
        shade += [np.float32(rng.uniform(0.2, 1.0))] * 3
    pos, shade = np.array(pos, np.float32), np.array(shade, np.float32)
    reference, rc = render(FLAT_FS, pos, shade, alpha_blend, simd="scalar", flat_primitives=False)
    assert rc["fragments_shaded"] > 0
    for simd in ("scalar", "sse2", "avx2", "avx512"):
        image, c = render(FLAT_FS, pos, shade, alpha_blend, 2, simd)
        assert image.tobytes() == reference.tobytes(), simd
        assert c["fragments_flat"] > 0
