"""Long blend chains against float64, depth precision at extreme near/far ratios and z-fighting
with and without polygon offset, and fog at extreme distances and densities.

Blend chains: 1,000 layers of random blend states on an RGBA8 canvas, each layer checked against
the ES 3.0 §4.1.7 formula evaluated in float64 from the previous layer's bytes (clamped inputs,
round to nearest); the end-to-end drift from an unquantized float64 chain is reported, not
asserted (it is the 8-bit format's, not softgl's)."""
import math

import numpy as np
import pytest

import softgl
from stress_helpers import Painter, context, pixels, quiet, unorm8

N = 8                    # 8x8 canvas: 64 independent pixels, one point each
FACTORS = ["ZERO", "ONE", "SRC_COLOR", "ONE_MINUS_SRC_COLOR", "DST_COLOR", "ONE_MINUS_DST_COLOR",
           "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "DST_ALPHA", "ONE_MINUS_DST_ALPHA", "CONSTANT_COLOR",
           "ONE_MINUS_CONSTANT_COLOR", "CONSTANT_ALPHA", "ONE_MINUS_CONSTANT_ALPHA", "SRC_ALPHA_SATURATE"]
EQUATIONS = ["FUNC_ADD", "FUNC_SUBTRACT", "FUNC_REVERSE_SUBTRACT", "MIN", "MAX"]
POINTS_VS = """attribute vec4 aPos; attribute vec4 aColor; varying vec4 vC;
void main() { gl_Position = aPos; gl_PointSize = 1.0; vC = aColor; }"""
POINTS_FS = "precision highp float; varying vec4 vC; void main() { gl_FragColor = vC; }"


def factor(name, s, d, c):
    """(rgb factor (n,3), alpha factor (n,)) in float64; s, d, c are clamped (n,4) arrays."""
    one = np.ones(len(s))
    table = {
        "ZERO": (np.zeros((len(s), 3)), 0 * one), "ONE": (np.ones((len(s), 3)), one),
        "SRC_COLOR": (s[:, :3], s[:, 3]), "ONE_MINUS_SRC_COLOR": (1 - s[:, :3], 1 - s[:, 3]),
        "DST_COLOR": (d[:, :3], d[:, 3]), "ONE_MINUS_DST_COLOR": (1 - d[:, :3], 1 - d[:, 3]),
        "SRC_ALPHA": (s[:, 3:4].repeat(3, 1), s[:, 3]), "ONE_MINUS_SRC_ALPHA": (1 - s[:, 3:4].repeat(3, 1), 1 - s[:, 3]),
        "DST_ALPHA": (d[:, 3:4].repeat(3, 1), d[:, 3]), "ONE_MINUS_DST_ALPHA": (1 - d[:, 3:4].repeat(3, 1), 1 - d[:, 3]),
        "CONSTANT_COLOR": (c[:, :3], c[:, 3]), "ONE_MINUS_CONSTANT_COLOR": (1 - c[:, :3], 1 - c[:, 3]),
        "CONSTANT_ALPHA": (c[:, 3:4].repeat(3, 1), c[:, 3]),
        "ONE_MINUS_CONSTANT_ALPHA": (1 - c[:, 3:4].repeat(3, 1), 1 - c[:, 3]),
        "SRC_ALPHA_SATURATE": (np.minimum(s[:, 3], 1 - d[:, 3])[:, None].repeat(3, 1), one),
    }
    return table[name]


def blend64(src, dst, const, sf, df, sfa, dfa, eq_rgb, eq_a):
    s, d, c = np.clip(src, 0, 1), np.clip(dst, 0, 1), np.clip(const, 0, 1)
    srgb, _ = factor(sf, s, d, c)
    drgb, _ = factor(df, s, d, c)
    _, sa = factor(sfa, s, d, c)
    _, da = factor(dfa, s, d, c)
    out = np.empty_like(s)

    def apply(eq, sv, dv, fs, fd):
        return {"FUNC_ADD": sv * fs + dv * fd, "FUNC_SUBTRACT": sv * fs - dv * fd,
                "FUNC_REVERSE_SUBTRACT": dv * fd - sv * fs, "MIN": np.minimum(sv, dv),
                "MAX": np.maximum(sv, dv)}[eq]
    out[:, :3] = apply(eq_rgb, s[:, :3], d[:, :3], srgb, drgb)
    out[:, 3] = apply(eq_a, s[:, 3], d[:, 3], sa, da)
    return np.clip(out, 0, 1)


def random_state(rng):
    while True:
        sf, df, sfa, dfa = (FACTORS[int(i)] for i in rng.integers(0, len(FACTORS), 4))
        if "SRC_ALPHA_SATURATE" in (df, dfa):
            continue            # source only in WebGL
        rgb = {sf, df}
        if any("CONSTANT_COLOR" in f for f in rgb) and any("CONSTANT_ALPHA" in f for f in rgb):
            continue            # WebGL 1.0 §6.13: not together
        return sf, df, sfa, dfa, EQUATIONS[int(rng.integers(5))], EQUATIONS[int(rng.integers(5))]


def layer_points():
    ij = np.stack(np.meshgrid(np.arange(N), np.arange(N)), -1).reshape(-1, 2)
    pos = np.zeros((N * N, 4), np.float32)
    pos[:, :2] = (ij + 0.5) / N * 2 - 1
    pos[:, 3] = 1
    return pos, ij


@pytest.mark.parametrize("seed,style", [(0, "random"), (1, "random"), (2, "over")])
def test_thousand_layer_blend_chain_matches_float64_each_layer(seed, style):
    rng = np.random.default_rng(seed)
    gl = context(N, N)
    prog = softgl.program(gl, POINTS_VS, POINTS_FS, {"aPos": 0, "aColor": 1})
    gl.useProgram(prog)
    pos, ij = layer_points()
    pbuf, cbuf = gl.createBuffer(), gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, pbuf)
    gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    gl.enableVertexAttribArray(1)
    gl.enable(gl.BLEND)
    current = pixels(gl)[ij[:, 1], ij[:, 0]].astype(np.float64)
    exact = current / 255                 # the unquantized float64 chain
    worst = 0
    mismatches = 0
    for layer in range(1000):
        if style == "over":
            state = ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "ONE", "ONE_MINUS_SRC_ALPHA", "FUNC_ADD", "FUNC_ADD")
            col = np.concatenate([rng.random((N * N, 3)), rng.uniform(0.001, 0.05, (N * N, 1))], 1)
        else:
            state = random_state(rng)
            col = rng.uniform(-0.2, 1.2, (N * N, 4))
        col = col.astype(np.float32)
        const = rng.uniform(-0.1, 1.1, 4).astype(np.float32)
        sf, df, sfa, dfa, eq, eqa = state
        gl.blendFuncSeparate(*(getattr(gl, f) for f in (sf, df, sfa, dfa)))
        gl.blendEquationSeparate(getattr(gl, eq), getattr(gl, eqa))
        gl.blendColor(*const)
        gl.bindBuffer(gl.ARRAY_BUFFER, cbuf)
        gl.bufferData(gl.ARRAY_BUFFER, col, gl.STREAM_DRAW)
        gl.vertexAttribPointer(1, 4, gl.FLOAT, False, 0, 0)
        gl.drawArrays(gl.POINTS, 0, N * N)
        assert gl.getError() == gl.NO_ERROR
        got = pixels(gl)[ij[:, 1], ij[:, 0]]
        want64 = blend64(col.astype(np.float64), current / 255, np.tile(const.astype(np.float64), (N * N, 1)),
                         sf, df, sfa, dfa, eq, eqa)
        want = unorm8(want64)
        diff = np.abs(got - want)
        # float32 arithmetic may round a value within 1e-5 of a .5 step the other way: 1 step.
        near_tie = np.abs(want64 * 255 - np.floor(want64 * 255) - 0.5) < 1e-4
        assert (diff <= 1).all(), (layer, state, np.argwhere(diff > 1)[:3])
        assert ((diff == 0) | near_tie).all(), (layer, state)
        mismatches += int((diff != 0).sum())
        exact = blend64(col.astype(np.float64), exact, np.tile(const.astype(np.float64), (N * N, 1)),
                        sf, df, sfa, dfa, eq, eqa)
        current = got.astype(np.float64)
        worst = max(worst, float(np.abs(current / 255 - exact).max()))
    assert mismatches <= 64 * 1000 * 4 // 1000     # at most 0.1 % of the channel values at a tie
    if style == "over":
        # The 8-bit chain stalls where alpha * (src - dst) < 0.5/255: the drift from the exact
        # float64 chain is the format's, bounded by the stall band (1/(2*255*min alpha) steps).
        assert worst < 0.5


# ----------------------------------------------------------------------------- depth

def perspective_depth(d, near, far):
    """Window depth (depthRange 0..1) of eye distance d for a GL perspective projection, in
    float64, from float32 clip coordinates as the vertex shader would output them."""
    z_e = -np.float32(d)
    a = np.float32(-(far + near) / (far - near))
    b = np.float32(-2 * far * near / (far - near))
    zc = np.float32(a * z_e + b)
    wc = np.float32(-z_e)
    return 0.5 * (float(zc) / float(wc)) + 0.5, (zc, wc)


def draw_plane(p, zc, wc, color):
    gl = p.gl
    quad = np.array([[-1, -1, zc / wc, 1], [1, -1, zc / wc, 1], [-1, 1, zc / wc, 1], [1, 1, zc / wc, 1]], np.float64)
    quad = (quad * float(wc)).astype(np.float32)
    quad[:, 2] = zc
    quad[:, 3] = wc
    p.draw(gl.TRIANGLE_STRIP, quad, color=color)


@pytest.mark.parametrize("near,far", [(1.0, 100.0), (0.01, 1e4), (1e-3, 1e6), (1e-5, 1e7), (1.0, 1e30)])
def test_extreme_near_far_depth_order_matches_24_bit_prediction(near, far):
    """Two screen-parallel planes at eye distances d and d(1 + gap): the nearer wins exactly when
    their 24-bit depths differ (predicted in float64); when equal, the first drawn wins (LESS)."""
    rng = np.random.default_rng(int(near * 1e6) % 1000)
    results = {"resolved": 0, "tied": 0}
    for _ in range(20):
        gap = float(10 ** rng.uniform(-7, -1))
        d = float(np.exp(rng.uniform(np.log(near * 1.01), np.log(min(far, 1e8) * 0.99 / (1 + gap)))))
        gl = context(4, 4)
        gl.enable(gl.DEPTH_TEST)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        p = Painter(gl, uniform_color=True)
        z_far, (zc1, wc1) = perspective_depth(d * (1 + gap), near, far)
        z_near, (zc0, wc0) = perspective_depth(d, near, far)
        draw_plane(p, zc1, wc1, (1, 0, 0, 1))          # far plane first
        draw_plane(p, zc0, wc0, (0, 1, 0, 1))          # then the near one
        got = pixels(gl)[2, 2, :2].tolist()
        q_far = math.floor(min(max(z_far, 0), 1) * (2**24 - 1) + 0.5)
        q_near = math.floor(min(max(z_near, 0), 1) * (2**24 - 1) + 0.5)
        top = 2**24 - 1                                # the cleared depth: LESS fails against it
        if abs(q_far - q_near) >= 2:
            assert got == [0, 255 if q_near < top else 0], (d, gap, q_near, q_far)
            results["resolved"] += 1
        elif q_far == q_near and abs(z_far - z_near) * top < 0.25:
            assert got == ([255, 0] if q_far < top else [0, 0]), (d, gap)   # z-fight: LESS keeps the first
            results["tied"] += 1
    assert sum(results.values()) >= 10


@pytest.mark.parametrize("func,second_wins", [("LESS", False), ("LEQUAL", True), ("EQUAL", True)])
def test_coplanar_z_fighting_is_deterministic(func, second_wins):
    """The same triangles drawn twice give bit-identical depths: the depth function alone decides."""
    gl = context(32, 32)
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(getattr(gl, func))
    gl.clearDepth(1.0)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    p = Painter(gl, uniform_color=True)
    rng = np.random.default_rng(4)
    tris = rng.uniform(-1, 1, (30, 3, 4)).astype(np.float32)
    tris[..., 2] = rng.uniform(-0.9, 0.9, (30, 3))
    tris[..., 3] = rng.uniform(0.5, 3, (30, 3))
    tris[..., :3] *= tris[..., 3:]
    gl.depthFunc(gl.LESS)
    p.draw(gl.TRIANGLES, tris.reshape(-1, 4), color=(1, 0, 0, 1))
    first = pixels(gl)
    gl.depthFunc(getattr(gl, func))
    p.draw(gl.TRIANGLES, tris.reshape(-1, 4), color=(0, 1, 0, 1))
    img = pixels(gl)
    covered = first[..., 0] == 255
    # Only the front-most triangle of each pixel took part in the depth race.
    assert covered.sum() > 200
    if second_wins:
        assert (img[covered, 1] == 255).all()
    else:
        assert (img[covered, 0] == 255).all() and (img[..., 1] == 0).all()


@pytest.mark.parametrize("units,factor", [(-1.0, 0.0), (-2.0, 0.0), (0.0, -1.0), (-1.0, -1.0)])
def test_polygon_offset_resolves_z_fighting_of_different_triangulations(units, factor):
    """A slanted quad split along one diagonal, then along the other: without offset the two
    triangulations z-fight (LESS lets some second pixels through or not, by rounding); with a
    negative offset of one resolvable unit, or a slope factor, the second wins everywhere."""
    gl = context(64, 64)
    gl.enable(gl.DEPTH_TEST)
    p = Painter(gl, uniform_color=True)
    w = np.array([1.0, 3.0, 2.0, 5.0], np.float32)
    quad = np.array([[-0.9, -0.9, -0.6], [0.9, -0.9, 0.7], [-0.9, 0.9, 0.1], [0.9, 0.9, 0.95]], np.float32)
    # A planar quad in eye space seen in perspective: w varies, clip z is affine in (x, y, w).
    clip = np.concatenate([quad * w[:, None], w[:, None]], 1).astype(np.float32)
    clip[:, 2] = 0.3 * clip[:, 0] + 0.2 * clip[:, 1] + 0.1 * clip[:, 3]
    p.draw(gl.TRIANGLES, clip, indices=[0, 1, 3, 0, 3, 2], color=(1, 0, 0, 1))
    covered = pixels(gl)[..., 0] == 255
    gl.enable(gl.POLYGON_OFFSET_FILL)
    gl.polygonOffset(factor, units)
    p.draw(gl.TRIANGLES, clip, indices=[0, 1, 2, 1, 3, 2], color=(0, 1, 0, 1))
    img = pixels(gl)
    assert covered.sum() > 1000
    assert (img[covered, 1] == 255).all(), int((img[covered, 0] == 255).sum())


@pytest.mark.parametrize("near,far", [(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.5, 0.5)])
def test_degenerate_and_reversed_depth_ranges(near, far):
    gl = context(8, 8)
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.LEQUAL)
    with quiet():
        gl.depthRange(near, far)
    if near > far:      # WebGL 1.0 §6.12: zNear > zFar is INVALID_OPERATION, the range stays (0, 1)
        assert gl.getError() == gl.INVALID_OPERATION
        near, far = 0.0, 1.0
    gl.clear(gl.DEPTH_BUFFER_BIT)
    p = Painter(gl, uniform_color=True)
    full = np.array([[-1, -1, -0.5, 1], [3, -1, -0.5, 1], [-1, 3, -0.5, 1]], np.float32)
    p.draw(gl.TRIANGLES, full, color=(1, 0, 0, 1))
    # Window z = near + (far - near)(z_ndc + 1)/2 = near + (far - near)/4 <= 1 always: drawn.
    assert (pixels(gl)[..., 0] == 255).all()
    # A second surface at z_ndc = +0.5: window z = near + 3(far - near)/4; passes LEQUAL iff
    # that is <= the first's (reversed ranges invert the order).
    full[:, 2] = 0.5
    p.draw(gl.TRIANGLES, full, color=(0, 1, 0, 1))
    z1, z2 = near + (far - near) / 4, near + 3 * (far - near) / 4
    assert (pixels(gl)[4, 4, 1] == 255) == (z2 <= z1)


# ----------------------------------------------------------------------------- fog

VS_W = "attribute vec4 aPos; void main() { gl_Position = aPos; }"
FS_C = "precision highp float; uniform vec4 uColor; void main() { gl_FragColor = uColor; }"


def fogged(mode, w, density=1.0, start=0.0, end=1.0, color=(0.9, 0.6, 0.3, 1.0), fog=(0.2, 0.4, 0.8, 1.0)):
    gl = context(4, 4)
    ext = gl.getExtension("SOFTGL_fog")
    gl.enable(ext.FOG)
    ext.fogi(ext.FOG_MODE, getattr(ext, mode))
    ext.fogf(ext.FOG_DENSITY, density)
    ext.fogf(ext.FOG_START, start)
    ext.fogf(ext.FOG_END, end)
    ext.fogfv(ext.FOG_COLOR, fog)
    p = Painter(gl, uniform_color=True)
    w = np.float32(w)
    quad = np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [-1, 1, 0, 1], [1, 1, 0, 1]], np.float32) * w
    p.draw(gl.TRIANGLE_STRIP, quad, color=color)
    return gl, pixels(gl)[1, 1]


def fog_expected(mode, c, density, start, end, color, fog):
    """GL 1.x fog factor; LINEAR in float32 like softgl (a start..end width beyond float32's
    range is +Inf, so such a range fogs fully: documented)."""
    with np.errstate(all="ignore"):
        if mode == "LINEAR":
            c32, s32, e32 = np.float32(c), np.float32(start), np.float32(end)
            f = float((e32 - c32) / (e32 - s32)) if e32 != s32 else (1.0 if c32 < e32 else 0.0)
        elif mode == "EXP":
            f = math.exp(-density * c) if math.isfinite(density * c) else 0.0
        else:
            f = math.exp(-(density * c) ** 2) if math.isfinite((density * c) ** 2) else 0.0
    f = 0.0 if not f > 0 else min(f, 1.0)         # NaN (0 * Inf) counts as fully fogged
    return [int(math.floor(min(max(f * s + (1 - f) * g, 0), 1) * 255 + 0.5)) for s, g in zip(color[:3], fog[:3])]


@pytest.mark.parametrize("mode", ["LINEAR", "EXP", "EXP2"])
@pytest.mark.parametrize("w", [2.0**-60, 1e-6, 1.0, 1e6, 1e30, 3e38])
@pytest.mark.parametrize("density", [0.0, 1e-30, 1e-6, 1.0, 1e30, 3e38])
def test_fog_at_extreme_distances_and_densities(mode, w, density):
    start, end = (0.0, 1e6) if mode == "LINEAR" else (0.0, 1.0)
    gl, px = fogged(mode, w, density=density, start=start, end=end)
    assert gl.getError() == gl.NO_ERROR
    # Eye distance = |1/gl_FragCoord.w| = w (float32).
    want = fog_expected(mode, float(np.float32(w)), float(np.float32(density)), start, end,
                        (0.9, 0.6, 0.3), (0.2, 0.4, 0.8))
    assert np.abs(px[:3] - want).max() <= 1, (px, want)
    assert px[3] == 255


@pytest.mark.parametrize("start,end", [(5.0, 5.0), (1e30, -1e30), (-3e38, 3e38), (0.0, 1e-30)])
def test_linear_fog_with_degenerate_and_huge_ranges(start, end):
    for w in (1.0, 10.0, 1e20):
        gl, px = fogged("LINEAR", w, start=start, end=end)
        want = fog_expected("LINEAR", w, 1.0, start, end, (0.9, 0.6, 0.3), (0.2, 0.4, 0.8))
        assert np.abs(px[:3] - want).max() <= 1, (start, end, w, px, want)


def test_fog_parameters_reject_nan_or_define_it():
    gl = context(4, 4)
    ext = gl.getExtension("SOFTGL_fog")
    with quiet():
        ext.fogf(ext.FOG_DENSITY, math.nan)
        density_error = gl.getError()
        ext.fogf(ext.FOG_START, math.nan)
        start_error = gl.getError()
    # Density must be >= 0 (GL 1.x): NaN is not, so INVALID_VALUE; start/end are unconstrained.
    assert density_error == gl.INVALID_VALUE
    assert gl.getParameter(ext.FOG_DENSITY) == 1.0
    if start_error == gl.NO_ERROR:     # accepted: drawing still defined (fully fogged or not)
        gl2, px = fogged("LINEAR", 2.0, start=math.nan, end=1.0)
        assert px[3] == 255
