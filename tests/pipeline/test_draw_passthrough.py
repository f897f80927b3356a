"""The whole draw pipeline (vertex fetch -> setup -> raster -> tests -> blending) with the C++
passthrough shaders, against float64 references computed here from the spec's formulas.

These tests exercise the fixed-function stages independently of the GLSL compiler.
"""
import numpy as np
import pytest

import softgl
from softgl import _core

draw = _core.testing.draw_passthrough


def ctx(w=16, h=16, **kw):
    kw.setdefault("antialias", False)
    return softgl.Context(w, h, **kw)


def pixels(gl):
    return gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA,
                         gl.UNSIGNED_BYTE).astype(np.int64)


def unorm(x):
    return np.floor(np.clip(x, 0, 1) * 255 + 0.5).astype(np.int64)


def quad(z=0.0, x0=-1, y0=-1, x1=1, y1=1, w=1.0):
    p = np.array([[x0, y0, z, 1], [x1, y0, z, 1], [x0, y1, z, 1], [x1, y1, z, 1]], np.float32)
    return p * np.float32(w)


QUAD_INDICES = [0, 1, 2, 2, 1, 3]


def barycentric(px, py, v):
    (x0, y0), (x1, y1), (x2, y2) = v
    d = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    l1 = ((px - x0) * (y2 - y0) - (x2 - x0) * (py - y0)) / d
    l2 = ((x1 - x0) * (py - y0) - (px - x0) * (y1 - y0)) / d
    return 1 - l1 - l2, l1, l2


def test_color_interpolation_matches_barycentrics():
    gl = ctx(32, 24)
    rng = np.random.default_rng(5)
    pos = np.array([[-0.9, -0.8, 0, 1], [0.95, -0.3, 0, 1], [-0.2, 0.9, 0, 1]], np.float32)
    col = rng.random((3, 4)).astype(np.float32)
    col[:, 3] = 1
    draw(gl, gl.TRIANGLES, pos, col)
    img = pixels(gl)
    win = [((p[0] + 1) * 16, (p[1] + 1) * 12) for p in pos.astype(np.float64)]
    ys, xs = np.nonzero(img[..., 3])
    assert len(xs) > 100
    for x, y in zip(xs, ys):
        lam = barycentric(x + 0.5, y + 0.5, win)
        want = unorm(sum(l * col[k].astype(np.float64) for k, l in enumerate(lam)))
        assert np.abs(img[y, x] - want).max() <= 1, (x, y)


def test_perspective_correct_interpolation():
    # The same screen triangle with different w per vertex: colors interpolate as (c/w)/(1/w).
    gl = ctx(32, 32)
    w = np.array([1.0, 4.0, 2.0])
    ndc = np.array([[-0.9, -0.9], [0.9, -0.9], [-0.9, 0.9]])
    pos = np.array([[*(ndc[k] * w[k]), 0, w[k]] for k in range(3)], np.float32)
    col = np.array([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1]], np.float32)
    draw(gl, gl.TRIANGLES, pos, col)
    img = pixels(gl)
    win = [((p[0] + 1) * 16, (p[1] + 1) * 16) for p in ndc]
    ys, xs = np.nonzero(img[..., 3])
    for x, y in zip(xs, ys):
        lam = np.array(barycentric(x + 0.5, y + 0.5, win)) / w
        lam /= lam.sum()
        want = unorm(lam @ col.astype(np.float64))
        assert np.abs(img[y, x] - want).max() <= 1, (x, y)


FACTORS = ["ZERO", "ONE", "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "DST_COLOR", "ONE_MINUS_DST_ALPHA",
           "CONSTANT_COLOR", "SRC_ALPHA_SATURATE"]


@pytest.mark.parametrize("equation", ["FUNC_ADD", "FUNC_SUBTRACT", "FUNC_REVERSE_SUBTRACT", "MIN", "MAX"])
def test_blending_through_the_pipeline(equation):
    src = np.array([0.9, 0.3, 0.6, 0.7])
    dst = np.array([0.2, 0.8, 0.4, 0.5])
    k = np.array([0.25, 0.5, 0.75, 1.0])
    for sf in FACTORS:
        for df in ["ZERO", "ONE", "ONE_MINUS_SRC_ALPHA", "DST_ALPHA", "ONE_MINUS_CONSTANT_COLOR"]:
            gl = ctx(4, 4)
            gl.clearColor(*dst)
            gl.clear(gl.COLOR_BUFFER_BIT)
            gl.enable(gl.BLEND)
            gl.blendColor(*k)
            gl.blendFunc(getattr(gl, sf), getattr(gl, df))
            gl.blendEquation(getattr(gl, equation))
            draw(gl, gl.TRIANGLES, quad(), np.tile(src.astype(np.float32), (4, 1)), indices=QUAD_INDICES)
            d = unorm(dst) / 255.0   # the stored destination

            def f(name):
                return {"ZERO": np.zeros(4), "ONE": np.ones(4), "SRC_ALPHA": np.full(4, src[3]),
                        "ONE_MINUS_SRC_ALPHA": np.full(4, 1 - src[3]), "DST_COLOR": d,
                        "DST_ALPHA": np.full(4, d[3]), "ONE_MINUS_DST_ALPHA": np.full(4, 1 - d[3]),
                        "CONSTANT_COLOR": k, "ONE_MINUS_CONSTANT_COLOR": 1 - k,
                        "SRC_ALPHA_SATURATE": np.r_[np.full(3, min(src[3], 1 - d[3])), 1.0]}[name]
            S, D = f(sf), f(df)
            want = {"FUNC_ADD": src * S + d * D, "FUNC_SUBTRACT": src * S - d * D,
                    "FUNC_REVERSE_SUBTRACT": d * D - src * S, "MIN": np.minimum(src, d),
                    "MAX": np.maximum(src, d)}[equation]
            got = pixels(gl)
            assert (np.abs(got - unorm(want)) <= 1).all(), (sf, df, equation, got[0, 0], unorm(want))


@pytest.mark.parametrize("func, passes", [
    ("NEVER", False), ("LESS", True), ("EQUAL", False), ("LEQUAL", True),
    ("GREATER", False), ("NOTEQUAL", True), ("GEQUAL", False), ("ALWAYS", True)])
def test_depth_functions(func, passes):
    # First quad at NDC z = 0.2 (window 0.6), second at z = -0.2 (window 0.4), nearer.
    gl = ctx(4, 4)
    gl.enable(gl.DEPTH_TEST)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    draw(gl, gl.TRIANGLES, quad(0.2), np.tile([1, 0, 0, 1], (4, 1)).astype(np.float32), indices=QUAD_INDICES)
    gl.depthFunc(getattr(gl, func))
    draw(gl, gl.TRIANGLES, quad(-0.2), np.tile([0, 1, 0, 1], (4, 1)).astype(np.float32), indices=QUAD_INDICES)
    assert (pixels(gl)[..., 1] == (255 if passes else 0)).all()
    depth = _core.testing.read_depth(gl)
    want = round(0.4 * (2**24 - 1)) if passes else round(0.6 * (2**24 - 1))
    assert np.abs(depth.astype(np.int64) - want).max() <= 1


def test_depth_mask_and_disabled_test_leave_depth_alone():
    gl = ctx(4, 4)
    gl.clearDepth(0.5)
    gl.clear(gl.DEPTH_BUFFER_BIT)
    draw(gl, gl.TRIANGLES, quad(0.9), np.ones((4, 4), np.float32), indices=QUAD_INDICES)
    assert (_core.testing.read_depth(gl) == round(0.5 * (2**24 - 1))).all()   # test disabled
    gl.enable(gl.DEPTH_TEST)
    gl.depthMask(False)
    gl.depthFunc(gl.ALWAYS)
    draw(gl, gl.TRIANGLES, quad(0.9), np.ones((4, 4), np.float32), indices=QUAD_INDICES)
    assert (_core.testing.read_depth(gl) == round(0.5 * (2**24 - 1))).all()   # mask off


@pytest.mark.parametrize("op, start, ref, expected", [
    ("KEEP", 5, 9, 5), ("ZERO", 5, 9, 0), ("REPLACE", 5, 9, 9), ("INCR", 255, 0, 255),
    ("INCR", 5, 0, 6), ("DECR", 0, 0, 0), ("INVERT", 5, 0, 250), ("INCR_WRAP", 255, 0, 0),
    ("DECR_WRAP", 0, 0, 255)])
def test_stencil_operations_on_pass(op, start, ref, expected):
    gl = ctx(4, 4, stencil=True)
    gl.clearStencil(start)
    gl.clear(gl.STENCIL_BUFFER_BIT)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilFunc(gl.ALWAYS, ref, 0xFF)
    gl.stencilOp(gl.KEEP, gl.KEEP, getattr(gl, op))
    draw(gl, gl.TRIANGLES, quad(), np.ones((4, 4), np.float32), indices=QUAD_INDICES)
    assert (_core.testing.read_stencil(gl) == expected).all()


def test_stencil_test_masks_and_write_mask():
    gl = ctx(4, 4, stencil=True)
    gl.clearStencil(0b1010)
    gl.clear(gl.STENCIL_BUFFER_BIT | gl.COLOR_BUFFER_BIT)
    gl.enable(gl.STENCIL_TEST)
    # (ref & mask) EQUAL (stencil & mask): 0b0010 & 0b0011 == 0b1010 & 0b0011 -> pass
    gl.stencilFunc(gl.EQUAL, 0b0010, 0b0011)
    gl.stencilOp(gl.KEEP, gl.KEEP, gl.INVERT)
    gl.stencilMask(0b1100)                      # only bits 2-3 change: 1010 -> 0110
    draw(gl, gl.TRIANGLES, quad(), np.ones((4, 4), np.float32), indices=QUAD_INDICES)
    assert (pixels(gl)[..., 0] == 255).all()
    assert (_core.testing.read_stencil(gl) == 0b0110).all()
    gl.stencilFunc(gl.EQUAL, 0b0010, 0b0011)    # now 0110 & 0011 = 0010: still passes
    gl.stencilFunc(gl.NOTEQUAL, 0b0010, 0b0011)
    gl.clear(gl.COLOR_BUFFER_BIT)
    draw(gl, gl.TRIANGLES, quad(), np.ones((4, 4), np.float32), indices=QUAD_INDICES)
    assert (pixels(gl) == 0).all()              # stencil test fails everywhere


def test_back_faces_use_back_stencil_state():
    gl = ctx(4, 4, stencil=True)
    gl.clear(gl.STENCIL_BUFFER_BIT)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilOpSeparate(gl.FRONT, gl.KEEP, gl.KEEP, gl.INCR)
    gl.stencilOpSeparate(gl.BACK, gl.KEEP, gl.KEEP, gl.INVERT)
    cw = quad()[[0, 2, 1, 3]]                  # same square, clockwise: back-facing
    draw(gl, gl.TRIANGLES, cw, np.ones((4, 4), np.float32), indices=QUAD_INDICES)
    assert (_core.testing.read_stencil(gl) == 255).all()


def test_msaa_resolve_averages_covered_samples():
    # A vertical edge through the middle of a pixel column covers 2 of the 4 standard samples.
    gl = softgl.Context(4, 1, samples=4)
    x_edge = -1 + 2 * (2.5 / 4)              # window x = 2.5
    pos = np.array([[-1, -1, 0, 1], [x_edge, -1, 0, 1], [-1, 1, 0, 1], [x_edge, 1, 0, 1]], np.float32)
    draw(gl, gl.TRIANGLES, pos, np.ones((4, 4), np.float32), indices=QUAD_INDICES)
    row = pixels(gl)[0, :, 0]
    # Standard 4x pattern x offsets are 0.375, 0.875, 0.125, 0.625: two lie left of 0.5.
    assert row.tolist() == [255, 255, 128, 0]


def test_same_bytes_for_any_thread_count():
    rng = np.random.default_rng(11)
    n = 3000
    pos = np.c_[rng.uniform(-1.2, 1.2, (n, 2)), rng.uniform(-1, 1, n), np.ones(n)].astype(np.float32)
    col = rng.random((n, 4)).astype(np.float32)
    images = []
    for threads in (1, 2, 3, 4):
        gl = softgl.Context(200, 150, samples=4, threads=threads)
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
        gl.enable(gl.DEPTH_TEST)
        gl.depthFunc(gl.LEQUAL)
        draw(gl, gl.TRIANGLES, pos, col)
        images.append((pixels(gl), _core.testing.read_depth(gl)))
    for img, depth in images[1:]:
        assert np.array_equal(img, images[0][0]) and np.array_equal(depth, images[0][1])


def test_early_and_late_depth_give_the_same_image():
    rng = np.random.default_rng(2)
    n = 600
    pos = np.c_[rng.uniform(-1, 1, (n, 2)), rng.uniform(-1, 1, n), np.ones(n)].astype(np.float32)
    col = np.c_[rng.random((n, 3)), np.ones(n)].astype(np.float32)
    out = []
    for discard_below, expect_early in ((-1.0, 1), (0.0, 0)):   # alpha is never < 0: no discards
        gl = ctx(64, 64, stencil=True)
        gl.enable(gl.DEPTH_TEST)
        gl.enable(gl.STENCIL_TEST)
        gl.stencilOp(gl.KEEP, gl.INCR, gl.INCR)
        stats = draw(gl, gl.TRIANGLES, pos, col, discard_below=discard_below)
        assert stats["draws_early_depth"] == expect_early
        out.append((pixels(gl), _core.testing.read_depth(gl), _core.testing.read_stencil(gl)))
    for a, b in zip(*out):
        assert np.array_equal(a, b)


def test_discard_and_frag_depth():
    gl = ctx(4, 4)
    col = np.array([[1, 0, 0, 0.2]] * 4, np.float32)
    stats = draw(gl, gl.TRIANGLES, quad(), col, indices=QUAD_INDICES, discard_below=0.5)
    assert stats["fragments_discarded"] == 16 and (pixels(gl) == 0).all()
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.ALWAYS)
    col = np.array([[0.25, 0, 0, 1]] * 4, np.float32)
    draw(gl, gl.TRIANGLES, quad(0.9), col, indices=QUAD_INDICES, depth_from_red=True)
    assert (_core.testing.read_depth(gl) == round(0.25 * (2**24 - 1))).all()   # gl_FragDepth wins


def test_nothing_to_write_skips_the_draw():
    gl = ctx(8, 8)
    gl.colorMask(False, False, False, False)
    stats = draw(gl, gl.TRIANGLES, quad(), np.ones((4, 4), np.float32), indices=QUAD_INDICES)
    assert stats["draws_skipped_no_output"] == 1 and stats["fragments_shaded"] == 0


def test_rasterizer_discard_and_culling():
    gl = ctx(8, 8)
    gl.enable(gl.RASTERIZER_DISCARD)
    stats = draw(gl, gl.TRIANGLES, quad(), np.ones((4, 4), np.float32), indices=QUAD_INDICES)
    assert stats["vertices_shaded"] == 4 and stats["primitives"] == 0 and (pixels(gl) == 0).all()
    gl.disable(gl.RASTERIZER_DISCARD)
    gl.enable(gl.CULL_FACE)
    stats = draw(gl, gl.TRIANGLES, quad()[[0, 2, 1, 3]], np.ones((4, 4), np.float32), indices=QUAD_INDICES)
    assert stats["primitives_culled"] == 2 and (pixels(gl) == 0).all()


def test_instances_and_points():
    gl = ctx(8, 8)
    pos = np.array([[-0.75, -0.75, 0, 1], [0.25, 0.25, 0, 1]], np.float32)   # centres (1, 1), (5, 5)
    stats = draw(gl, gl.POINTS, pos, np.ones((2, 4), np.float32), point_sizes=np.array([2, 3], np.float32),
                 instances=3)
    assert stats["vertices_shaded"] == 6
    covered = pixels(gl)[..., 0] > 0
    assert covered.sum() == 4 + 9
