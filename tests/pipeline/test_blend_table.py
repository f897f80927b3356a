"""A constant colour (a uniform-only shader) blended through a 256-entry table per channel
(pipeline/fragment_ops.h BlendTable) gives exactly the bytes of the reference blend_unorm8.

The table applies when each channel's result depends on that channel's destination alone (ES 3.0
table 4.2): no DST_ALPHA, ONE_MINUS_DST_ALPHA or SRC_ALPHA_SATURATE on rgb, unless the buffer has
no alpha (destination alpha reads 1). Checked on the kernel at every instruction-set level (lanes
and rows of four in the buffer, colour masks, any colour, out-of-range and NaN included) and in
whole draws (uniform-only against per-fragment shading, odd buffer sizes, 1 and 2 threads), and
the draws the table cannot represent must keep the old path (a float64 model of the formula).
"""
import itertools

import numpy as np
import pytest

import softgl
from softgl import _core
from test_blend_unit import EQUATIONS, FACTORS, blend64

e = lambda n: getattr(softgl, n)
CROSS_CHANNEL = {"DST_ALPHA", "ONE_MINUS_DST_ALPHA", "SRC_ALPHA_SATURATE"}   # rgb factors reading d[3]


def per_channel(funcs, has_alpha):
    return not has_alpha or not (CROSS_CHANNEL & {funcs[0], funcs[1]})


def random_colour(rng):
    c = rng.uniform(-0.2, 1.2, 4)
    if rng.random() < 0.2:
        c[rng.integers(0, 4)] = rng.choice([np.nan, np.inf, -np.inf, -0.0, 1.0, 0.0])
    return tuple(float(v) for v in np.float32(c))


def check_kernel(rng, funcs, eqs, mask, has_alpha):
    """Random quads, some as rows of four in a 26 x 12 image; every level against blend_unorm8."""
    colour = random_colour(rng)
    constant = tuple(float(v) for v in rng.uniform(-0.2, 1.2, 4))
    fe = [e(f) for f in funcs] + [e(q) for q in eqs]
    n = int(rng.integers(1, 41))
    quads = np.column_stack([rng.integers(-4, 30, n), rng.integers(-4, 14, n)]).astype(np.int32)
    # Rows of four (quads i .. i + 3 side by side) in distinct 8 x 2 cells of the image, as a
    # draw's never overlap; shifted by up to 2 pixels (unaligned rows).
    cells = list(rng.permutation(18))
    shift = int(rng.integers(0, 3))
    rows, i = 0, 0
    while i + 4 <= n:
        if rng.random() < 0.4:
            cell = int(cells.pop())
            x, y = shift + 8 * (cell % 3), 2 * (cell // 3)
            quads[i:i + 4] = [(x + 2 * k, y) for k in range(4)]
            rows |= 1 << i
            i += 4
        else:
            i += 1
    dst = rng.integers(0, 2**32, 4 * n, dtype=np.uint64).astype(np.uint32)
    image = rng.integers(0, 2**32, (12, 26), dtype=np.uint64).astype(np.uint32)
    # The expected bytes: blend_unorm8 on every lane not in a row and on every pixel of the rows.
    src = np.tile(np.array(colour, np.float32), (4 * n, 1))
    want_dst = _core.testing.blend_unorm8(fe, constant, mask, has_alpha, src, dst.view(np.uint8).reshape(-1, 4))
    want_dst = want_dst.reshape(-1).view(np.uint32).copy()
    want_image = image.copy()
    in_row = np.zeros(n, bool)
    for i in range(n):
        if rows >> i & 1:
            in_row[i:i + 4] = True
            x, y = quads[i]
            block = image[y:y + 2, x:x + 8].copy()
            px = block.view(np.uint8).reshape(-1, 4)
            out = _core.testing.blend_unorm8(fe, constant, mask, has_alpha, src[:16], px)
            want_image[y:y + 2, x:x + 8] = out.reshape(-1).view(np.uint32).reshape(2, 8)
    lanes_in_row = np.repeat(in_row, 4)
    want_dst[lanes_in_row] = dst[lanes_in_row]   # rows of four keep their lanes
    for level in range(_core.testing.simd_level() + 1):
        ok, got_dst, got_image = _core.testing.blend_table_lanes(level, fe, constant, mask, has_alpha, colour,
                                                                 quads, dst, rows, image)
        assert ok == per_channel(funcs, has_alpha)
        if not ok:
            np.testing.assert_array_equal(got_dst, dst)
            continue
        where = f"{funcs} {eqs} mask {mask} alpha {has_alpha} colour {colour} level {level}"
        np.testing.assert_array_equal(got_dst, want_dst, err_msg="lanes " + where)
        np.testing.assert_array_equal(got_image, want_image, err_msg="rows " + where)


@pytest.mark.parametrize("has_alpha", [True, False])
def test_table_equals_the_reference_for_every_factor_pair(has_alpha):
    rng = np.random.default_rng(21 + has_alpha)
    masks = [(True,) * 4, (True, False, True, False), (False, True, True, True), (False, False, False, True)]
    for sf, df in itertools.product(FACTORS, FACTORS):
        sfa, dfa = (str(f) for f in rng.choice(FACTORS, 2))
        eq, eqa = (str(q) for q in rng.choice(EQUATIONS, 2))
        check_kernel(rng, (sf, df, sfa, dfa), (eq, eqa), masks[int(rng.integers(0, 4))], has_alpha)
    for eq, eqa in itertools.product(EQUATIONS, EQUATIONS):   # every equation pair, the common factors
        for funcs in [("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA") * 2, ("ONE", "ONE") * 2, ("DST_COLOR", "ZERO", "ONE", "ONE")]:
            check_kernel(rng, funcs, (eq, eqa), (True,) * 4, has_alpha)


def test_rect_equals_the_reference():
    """apply_blend_table_to_rect (a primitive covering its whole part of a tile, whole_rect.h): the
    rectangle's pixels as blend_unorm8 gives them, all others unchanged; rows shorter and longer
    than 16 pixels, odd offsets, empty rectangles, at every level."""
    rng = np.random.default_rng(77)
    masks = [(True,) * 4, (True, False, True, False), (False, False, False, True)]
    pairs = [("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA") * 2, ("ONE", "ONE") * 2, ("DST_COLOR", "ZERO", "ONE", "ONE")]
    pairs += [tuple(str(f) for f in rng.choice(FACTORS, 4)) for _ in range(20)]
    for funcs in pairs:
        has_alpha = bool(rng.integers(0, 2))
        eqs = tuple(str(q) for q in rng.choice(EQUATIONS, 2))
        mask = masks[int(rng.integers(0, len(masks)))]
        fe = [e(f) for f in funcs] + [e(q) for q in eqs]
        colour, constant = random_colour(rng), tuple(float(v) for v in rng.uniform(-0.2, 1.2, 4))
        h, w = int(rng.integers(1, 30)), int(rng.integers(1, 70))
        image = rng.integers(0, 2**32, (h, w), dtype=np.uint64).astype(np.uint32)
        x0, x1 = sorted(int(v) for v in rng.integers(0, w + 1, 2))
        y0, y1 = sorted(int(v) for v in rng.integers(0, h + 1, 2))
        want = image.copy()
        part = image[y0:y1, x0:x1].copy()
        src = np.tile(np.array(colour, np.float32), (part.size, 1))
        out = _core.testing.blend_unorm8(fe, constant, mask, has_alpha, src, part.view(np.uint8).reshape(-1, 4))
        want[y0:y1, x0:x1] = out.reshape(-1).view(np.uint32).reshape(part.shape)
        for level in range(_core.testing.simd_level() + 1):
            ok, got = _core.testing.blend_table_rect(level, fe, constant, mask, has_alpha, colour, (x0, y0, x1, y1), image)
            assert ok == per_channel(funcs, has_alpha)
            where = f"{funcs} {eqs} mask {mask} alpha {has_alpha} colour {colour} rect {(x0, y0, x1, y1)} level {level}"
            np.testing.assert_array_equal(got, want if ok else image, err_msg=where)


VS = """#version 300 es
in vec4 aPos;
void main() { gl_Position = aPos; }
"""
# The same colour from a uniform-only shader and from one shaded per fragment.
from test_uniform_only_shading import PER_FRAGMENT_FS, UNIFORM_FS  # noqa: E402


def render(fs, size, threads, funcs, eqs, mask, colours, alpha=True, scissor=None):
    """A full-screen quad and two triangles with edges inside the buffer per colour, blended onto a
    random background (inside `scissor`, x, y, w, h, if given). Returns (RGBA bytes, gl.stats())."""
    w, h = size
    gl = softgl.Context(w, h, threads=threads, alpha=alpha, antialias=False, preserveDrawingBuffer=True)
    # Whole quads through the shader, as the blend table counts them (fragments_shaded).
    _core.testing.set_tuning(gl, skip_helper_lanes=False)
    prog = softgl.program(gl, VS, fs)
    gl.useProgram(prog)
    gl.bindVertexArray(gl.createVertexArray())
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    shapes = [[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1],
              [-0.93, -0.81], [0.97, -0.33], [-0.21, 0.88], [0.6, 0.95], [-0.7, 0.1], [0.99, -0.99]]
    gl.bufferData(gl.ARRAY_BUFFER, np.array(shapes, np.float32), gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
    # A background with every byte value: a float clear cannot give one, so a plain-write draw per
    # row band would be slow; texSubImage is not for the drawing buffer either, so draw it with
    # scissored clears of random colours.
    rng = np.random.default_rng(w * h)
    gl.enable(gl.SCISSOR_TEST)
    for y in range(0, h, 3):
        for x in range(0, w, 5):
            gl.scissor(x, y, 5, 3)
            gl.clearColor(*(float(v) for v in rng.integers(0, 256, 4) / 255))
            gl.clear(gl.COLOR_BUFFER_BIT)
    gl.disable(gl.SCISSOR_TEST)
    if scissor:
        gl.enable(gl.SCISSOR_TEST)
        gl.scissor(*scissor)
    gl.enable(gl.BLEND)
    gl.blendFuncSeparate(*(e(f) for f in funcs))
    gl.blendEquationSeparate(*(e(q) for q in eqs))
    gl.blendColor(0.2, 0.9, 0.4, 0.7)
    gl.colorMask(*mask)
    assert gl.getError() == gl.NO_ERROR
    gl.stats(reset=True)
    loc = gl.getUniformLocation(prog, "uColor")
    for k, colour in enumerate(colours):
        gl.uniform4f(loc, *colour)
        gl.drawArrays(gl.TRIANGLES, 0 if k % 2 == 0 else 6, 6)
    return gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE), gl.stats()


SIZES = [(75, 53), (130, 70)]   # partial quads at the buffer's edges; tiles split over threads


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("size", SIZES)
def test_table_draws_equal_per_fragment_shading(size, threads):
    rng = np.random.default_rng(size[0] + threads)
    cases = [(("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA") * 2, ("FUNC_ADD",) * 2, (True,) * 4, True),
             (("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA") * 2, ("FUNC_ADD",) * 2, (True, False, True, True), True),
             (("ONE", "ONE") * 2, ("FUNC_ADD",) * 2, (True,) * 4, True),
             (("DST_ALPHA", "ONE_MINUS_SRC_ALPHA", "ONE", "ONE"), ("FUNC_ADD",) * 2, (True,) * 4, False)]
    while len(cases) < 10:
        funcs = tuple(str(f) for f in rng.choice(FACTORS, 4))
        # WebGL 1 §6.13: constant colour and constant alpha factors together are an error.
        if {"CONSTANT_COLOR", "ONE_MINUS_CONSTANT_COLOR"} & set(funcs) and {"CONSTANT_ALPHA", "ONE_MINUS_CONSTANT_ALPHA"} & set(funcs):
            continue
        cases.append((funcs, tuple(str(q) for q in rng.choice(EQUATIONS, 2)),
                      tuple(bool(b) for b in rng.integers(0, 2, 4)), bool(rng.integers(0, 2))))
    for funcs, eqs, mask, alpha in cases:
        colours = [random_colour(rng) for _ in range(4)]
        got, stats = render(UNIFORM_FS, size, threads, funcs, eqs, mask, colours, alpha)
        want, ref_stats = render(PER_FRAGMENT_FS, size, threads, funcs, eqs, mask, colours, alpha)
        assert got.tobytes() == want.tobytes(), (funcs, eqs, mask, alpha)
        writes = any(mask[:3]) or (alpha and mask[3])
        plain = funcs == ("ONE", "ZERO") * 2 and eqs == ("FUNC_ADD",) * 2
        table = writes and not plain and per_channel(funcs, alpha)
        assert stats.pop("draws_blend_table") == (len(colours) if table else 0), (funcs, eqs, mask, alpha)
        assert ref_stats.pop("draws_blend_table") == 0
        assert stats.pop("draws_constant_color") == (len(colours) if writes else 0), (funcs, eqs, mask, alpha)
        assert ref_stats.pop("draws_constant_color") == 0
        counters = lambda s: {k: v for k, v in s.items() if not k.startswith("seconds")}
        assert counters(stats) == counters(ref_stats)


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("size, scissor", [((200, 150), None), ((203, 133), None), ((203, 133), (3, 5, 150, 121))])
def test_covered_tiles_equal_per_fragment_shading(size, scissor, threads):
    # Buffers of several 64-pixel tiles: most of each full-screen triangle's tiles are covered
    # whole (blended in place, tile_pass.cpp / whole_rect.h), the tiles on its diagonal and the inner
    # triangles' take the quads; odd sizes and an odd scissor make parts of partial quads.
    rng = np.random.default_rng(size[0] + size[1] + threads)
    cases = [(("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA") * 2, ("FUNC_ADD",) * 2, (True,) * 4, True),
             (("ONE", "ONE_MINUS_SRC_COLOR", "ONE", "ZERO"), ("FUNC_REVERSE_SUBTRACT", "FUNC_ADD"), (True, True, False, True), False)]
    for funcs, eqs, mask, alpha in cases:
        colours = [random_colour(rng) for _ in range(3)]
        got, stats = render(UNIFORM_FS, size, threads, funcs, eqs, mask, colours, alpha, scissor)
        want, ref_stats = render(PER_FRAGMENT_FS, size, threads, funcs, eqs, mask, colours, alpha, scissor)
        assert got.tobytes() == want.tobytes(), (funcs, eqs, mask, alpha)
        assert stats.pop("draws_blend_table") == len(colours)
        assert ref_stats.pop("draws_blend_table") == 0
        assert stats.pop("draws_constant_color") == len(colours) and ref_stats.pop("draws_constant_color") == 0
        counters = lambda s: {k: v for k, v in s.items() if not k.startswith("seconds")}
        assert counters(stats) == counters(ref_stats)


@pytest.mark.parametrize("threads", [1, 2])
def test_cross_channel_blends_keep_the_old_path(threads):
    # d[3] in the rgb factors: no table; the bytes follow the float64 formula per layer.
    rng = np.random.default_rng(5)
    for funcs in [("DST_ALPHA", "ONE_MINUS_DST_ALPHA", "ONE", "ZERO"),
                  ("SRC_ALPHA_SATURATE", "ONE", "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA"),
                  ("ONE_MINUS_DST_ALPHA", "SRC_COLOR", "DST_ALPHA", "ZERO")]:
        colours = [random_colour(rng) for _ in range(2)]
        colours = [tuple(0.5 if np.isnan(v) else v for v in c) for c in colours]
        image, stats = render(UNIFORM_FS, (75, 53), threads, funcs, ("FUNC_ADD",) * 2, (True,) * 4, colours[:1])
        assert stats["draws_blend_table"] == 0
        background, _ = render(UNIFORM_FS, (75, 53), threads, funcs, ("FUNC_ADD",) * 2, (True,) * 4, [])
        px = background.reshape(-1, 4)
        src = np.tile(np.array(colours[0], np.float32), (len(px), 1))
        want = blend64(src, px, *funcs, "FUNC_ADD", "FUNC_ADD", (0.2, 0.9, 0.4, 0.7))
        assert np.abs(image.reshape(-1, 4).astype(np.int64) - want).max() <= 1, funcs
