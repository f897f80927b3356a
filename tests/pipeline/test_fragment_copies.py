"""Fragment shaders that only copy varyings or constants to their colour outputs skip the executor
(docs/architecture.md, "Fast paths"; FragmentShader::copies). The shortcut must give the executor's
bits exactly, -0.0, infinities and NaN payloads included (a Mov copies bits), and must not be taken
by shaders that do more (discard, gl_FragDepth, built-ins, arithmetic). (NaN payloads do not survive
the float attachment on either path; the Mov semantics keep them in the results.)

Expected values: flat varyings carry the provoking vertex's bits unchanged (ES 3.0 §2.18.1), so a
copy of one is compared with the input bits themselves; smooth varyings are compared with the same
draw run on the executor (the context's tuning fragment_copies=False). gl.stats() counts the draws
that took the shortcut (draws_copied_varying)."""
import numpy as np
import pytest

import softgl

core = pytest.importorskip("softgl._core")

W = H = 16
# Two triangles covering the viewport; the second's last vertex (index 5) provokes its flat values.
QUAD = np.array([-1, -1, 1, -1, -1, 1, -1, 1, 1, -1, 1, 1], np.float32).reshape(6, 2)

SPECIAL = np.array([0x80000000, 0x7F800000, 0xFF800000, 0x7FC12345,   # -0, +Inf, -Inf, quiet NaN
                    0xFFC00001, 0x7FBFFFFF, 0x00000001, 0x3F800000],   # -NaN, NaN (signalling bit), denormal, 1
                   np.uint32)


def vertex_values(seed):
    """(6, 8) float32: every vertex gets special bit patterns mixed with ordinary values."""
    r = np.random.default_rng(seed)
    bits = r.choice(SPECIAL, size=(6, 8)).astype(np.uint32)
    ordinary = r.uniform(-2, 2, (6, 8)).astype(np.float32).view(np.uint32)
    bits = np.where(r.random((6, 8)) < 0.5, bits, ordinary)
    bits[5] = SPECIAL   # the provoking vertex of the second triangle: all of them
    return bits.view(np.float32)


VS = """#version 300 es
in vec2 pos;
in vec4 a;
in vec4 b;
{q} out vec4 vA;
{q} out vec4 vB;
void main() {{ vA = a; vB = b; gl_Position = vec4(pos, 0.0, 1.0); }}
"""


def render(fs, values, qualifier="flat", outputs=1, copies=True, setup=None):
    """Draws QUAD into `outputs` RGBA32F attachments; returns their (H, W, 4) uint32 bits and how
    many draws took the copy shortcut."""
    gl = softgl.Context(W, H, antialias=False)
    core.testing.set_tuning(gl, fragment_copies=copies)
    assert gl.getExtension("EXT_color_buffer_float") is not None
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    texs = []
    for i in range(outputs):
        t = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, t)
        gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, W, H)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, t, 0)
        texs.append(t)
    gl.drawBuffers([gl.COLOR_ATTACHMENT0 + i for i in range(outputs)])
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    prog = softgl.program(gl, VS.format(q=qualifier), fs)
    gl.useProgram(prog)
    for name, data in (("pos", QUAD), ("a", values[:, :4]), ("b", values[:, 4:])):
        loc = gl.getAttribLocation(prog, name)
        buf = gl.createBuffer()
        gl.bindBuffer(gl.ARRAY_BUFFER, buf)
        gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(data, np.float32), gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, data.shape[1], gl.FLOAT, False, 0, 0)
    if setup:
        setup(gl, prog)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    taken = gl.stats()["draws_copied_varying"]
    assert gl.last_draw_plan()["fragment_copies"] == (taken == 1)
    out = []
    for t in texs:
        read = gl.createFramebuffer()
        gl.bindFramebuffer(gl.FRAMEBUFFER, read)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, t, 0)
        out.append(np.asarray(gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT), np.float32).reshape(H, W, 4).view(np.uint32))
    assert gl.getError() == gl.NO_ERROR
    return out, taken


def fs(body, outputs="layout(location = 0) out vec4 o0;", qualifier="flat"):
    return f"""#version 300 es
precision highp float;
{qualifier} in vec4 vA;
{qualifier} in vec4 vB;
{outputs}
void main() {{ {body} }}
"""


def matches(got, want):
    """Bit for bit, except that a NaN may come back as another NaN: the pipeline does not keep
    payloads on the way to the float attachment (either path)."""
    want = np.broadcast_to(np.asarray(want, np.uint32), got.shape)
    both_nan = np.isnan(got.view(np.float32)) & np.isnan(want.view(np.float32))
    return bool(((got == want) | both_nan).all())


def second_triangle(bits):
    """The pixels whose centres lie strictly inside the second triangle (x + y > 0 in NDC)."""
    c = (np.arange(W) + 0.5) / W * 2 - 1
    x, y = np.meshgrid(c, c)
    return bits[(x + y) > 0.1]


def test_flat_copy_is_the_provoking_vertex_bits():
    values = vertex_values(1)
    want = values[5, :4].view(np.uint32)
    for copies in (True, False):
        (got,), taken = render(fs("o0 = vA;"), values, copies=copies)
        assert taken == (1 if copies else 0)
        assert matches(second_triangle(got), want)


@pytest.mark.parametrize("body, want", [
    ("o0 = vB.wzyx;", lambda v: v[5, [7, 6, 5, 4]]),                       # not consecutive: the tile pass copies
    ("o0 = vec4(vA.xy, -0.0, 1.0);", lambda v: np.array([v[5, 0], v[5, 1], -0.0, 1.0], np.float32)),
    ("o0 = vec4(vB.x, vB.x, vA.w, vA.w);", lambda v: v[5, [4, 4, 3, 3]]),
])
def test_swizzles_and_constants(body, want):
    values = vertex_values(2)
    expected = np.asarray(want(values), np.float32).view(np.uint32)
    for copies in (True, False):
        (got,), taken = render(fs(body), values, copies=copies)
        assert taken == (1 if copies else 0)
        assert matches(second_triangle(got), expected)


def test_smooth_copy_equals_the_executor():
    for seed in range(3):
        values = vertex_values(10 + seed)
        source = fs("o0 = vA;", qualifier="smooth")
        (a,), taken = render(source, values, qualifier="smooth")
        (b,), _ = render(source, values, qualifier="smooth", copies=False)
        assert taken == 1
        assert (a == b).all()
        assert np.isnan(a.view(np.float32)).any()   # the special values did reach the pixels


def test_mrt_copies():
    values = vertex_values(3)
    outputs = "layout(location = 0) out vec4 o0;\nlayout(location = 2) out vec4 o2;"
    source = fs("o0 = vB; o2 = vA.yxzw;", outputs)
    (a0, a1, a2), taken = render(source, values, outputs=3)
    (b0, b1, b2), _ = render(source, values, outputs=3, copies=False)
    assert taken == 1
    assert matches(second_triangle(a0), values[5, 4:].view(np.uint32))
    assert matches(second_triangle(a2), values[5, [1, 0, 2, 3]].view(np.uint32))
    for a, b in ((a0, b0), (a1, b1), (a2, b2)):
        assert (a == b).all()


@pytest.mark.parametrize("body", [
    "if (vA.x > 100.0) discard; o0 = vA;",     # discard: never the shortcut, even when not taken
    "o0 = vA; gl_FragDepth = 0.5;",
    "o0 = gl_FragCoord;",
    "o0 = vec4(gl_FragCoord.xy, vA.zw);",
    "o0 = vA * 1.0;",
    "o0 = vA; if (vB.x > 0.0) o0 = vB;",
])
def test_other_shaders_run_on_the_executor(body):
    values = vertex_values(4)
    (a,), taken = render(fs(body), values)
    (b,), _ = render(fs(body), values, copies=False)
    assert taken == 0
    assert (a == b).all()


BLENDS = {"off": None, "alpha_over": ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA"), "additive": ("ONE", "ONE")}


@pytest.mark.parametrize("mode", ["TRIANGLES", "LINES"])
@pytest.mark.parametrize("blend", list(BLENDS))
@pytest.mark.parametrize("spread", [0.15, 1.0])
def test_webgl1_frag_color_and_blending_on_the_drawing_buffer(mode, blend, spread):
    """gl_FragColor = v through the RGBA8 colour kernels (the fused copy kernel, with blending or
    without, small and large primitives): the same bytes either way."""
    r = np.random.default_rng(5)
    n = 300 if spread < 1 else 30
    pos = (r.uniform(-1, 1, (n, 1, 2)) + r.uniform(-spread, spread, (n, 3, 2))).reshape(-1, 2).astype(np.float32)
    color = r.uniform(-0.2, 1.2, (n * 3, 4)).astype(np.float32)
    vs = ("attribute vec2 pos; attribute vec4 color; varying vec4 v;"
          "void main() { v = color; gl_Position = vec4(pos, 0.0, 1.0); }")
    fs1 = "precision mediump float; varying vec4 v; void main() { gl_FragColor = v; }"
    images = []
    for copies in (True, False):
        gl = softgl.Context(64, 64, antialias=False)
        # Every fragment through the kernels: hidden-surface removal picks its tiles by shader
        # cost, so it would shade different fragments in the two runs (its own tests). Whole
        # quads when the shader runs, as the fused kernel counts them (fragments_shaded).
        core.testing.set_tuning(gl, fragment_copies=copies, hidden_surface_removal="off", skip_helper_lanes=False)
        prog = softgl.program(gl, vs, fs1)
        gl.useProgram(prog)
        for name, data in (("pos", pos), ("color", color)):
            loc = gl.getAttribLocation(prog, name)
            gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
            gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
            gl.enableVertexAttribArray(loc)
            gl.vertexAttribPointer(loc, data.shape[1], gl.FLOAT, False, 0, 0)
        if BLENDS[blend]:
            gl.enable(gl.BLEND)
            gl.blendFunc(*(getattr(gl, f) for f in BLENDS[blend]))
        gl.drawArrays(getattr(gl, mode), 0, 3 * n)
        assert gl.stats()["draws_copied_varying"] == (1 if copies else 0)
        plan = gl.last_draw_plan()
        assert plan["fused_copy"] == copies, plan["text"]   # the fused kernel: smooth vec4, RGBA8
        images.append((np.asarray(gl.readPixels(0, 0, 64, 64, gl.RGBA, gl.UNSIGNED_BYTE)), gl.stats()))
    assert (images[0][0] == images[1][0]).all()
    assert images[0][0].any()
    # The draw kinds differ: a fused copy, or a shader that can run once per flat primitive
    # (none here: the colours differ at the vertices, fragments_flat is 0 in both).
    kinds = ("draws_copied_varying", "draws_flat_primitives")
    counters = [{k: v for k, v in stats.items() if not k.startswith("seconds") and k not in kinds
                 and k != "quads_blended_in_place"}
                for _, stats in images]
    assert counters[0] == counters[1]   # the same counters (fragments shaded, samples written...)


# The fused copy kernel (pipeline/fragment_ops.h, write_interpolated_color_lanes) against the two
# stages it replaces, interpolation then the colour kernel, at every instruction-set level, and
# against the scalar level of those stages (the reference).
KERNELS = {   # blend on?, (src_rgb, dst_rgb, src_alpha, dst_alpha, eq_rgb, eq_alpha)
    "plain": (False, (1, 0, 1, 0, 0x8006, 0x8006)),
    "alpha_over": (True, (0x0302, 0x0303, 0x0302, 0x0303, 0x8006, 0x8006)),
    "additive": (True, (1, 1, 1, 1, 0x8006, 0x8006)),
}
SPECIAL_COLOURS = np.array([0.0, -0.0, 1.0, 0.5, np.inf, -np.inf, np.nan, 1e-40, 1.0000001, 0.99999994], np.float32)


def chunk_quads(r, n_segments, size=64):
    """Quads as the fused kernel gets them: single quads and rows of four side by side (bit i of
    `rows` set where one starts), in distinct 8x2 slots of a size x size image, in random order or
    column by column."""
    slots = r.permutation((size // 8) * (size // 2))[:n_segments]
    if r.random() < 0.5:   # runs up the same columns, as the raster's 8x8 blocks give
        slots = sorted(slots, key=lambda slot: (slot % (size // 8), slot // (size // 8)))
    quads, rows = [], 0
    for slot in slots:
        x, y = int(slot % (size // 8)) * 8, int(slot // (size // 8)) * 2
        if r.random() < 0.6:
            rows |= (1 << len(quads)) if r.random() < 0.8 else 0   # some rows of four go through lanes
            quads += [(x + 2 * k, y) for k in range(4)]
        else:
            quads.append((x + 2 * int(r.integers(0, 4)), y))
    return np.array(quads, np.int32).reshape(-1, 2), rows


@pytest.mark.parametrize("kernel", list(KERNELS))
@pytest.mark.parametrize("vertices", [3, 2])
@pytest.mark.parametrize("constant_w", [False, True])
def test_fused_copy_kernel_equals_interpolation_then_colour_kernel(kernel, vertices, constant_w):
    """The lanes and, for rows of four, the image's pixels equal the scalar two-stage reference run
    on lanes gathered from the image."""
    blend, fe = KERNELS[kernel]
    r = np.random.default_rng(11 + vertices + 2 * constant_w)
    levels = range(core.testing.simd_level() + 1)
    for case in range(40):
        planes = r.normal(0, 1, (4, 3)) * np.array([1e-2, 1e-2, 1.0])
        if constant_w:
            planes[3] = (0.0, 0.0, r.choice([1.0, 0.5, -2.0]))
        else:
            planes[3] = (*r.normal(0, 1e-3, 2), r.uniform(0.5, 2.0))
        if case % 8 == 3:   # weights that overflow at some pixels: a constant channel is NaN there
            planes[1:3] *= 1e38
        quads, rows = chunk_quads(r, int(r.integers(0, 9)))
        n = len(quads)
        ox, oy = (int(v) for v in r.integers(0, 64 * 256, 2))
        values = r.uniform(-0.2, 1.2, (vertices, 7)).astype(np.float32)
        if case % 4 == 0:   # special values at some vertices (a value equal at every vertex stays exact)
            values[r.random(values.shape) < 0.3] = r.choice(SPECIAL_COLOURS)
        if case % 5 == 0:
            values[:, 3] = 0.5   # alpha equal at every vertex, as the benchmark's triangles have
        first = int(r.integers(0, 4))
        mask = [True] * 4 if case % 3 else [bool(b) for b in r.integers(0, 2, 4)]
        has_alpha = bool(case % 7)
        dst = r.integers(0, 2**32, 4 * n, dtype=np.uint64).astype(np.uint32)
        image = r.integers(0, 2**32, (64, 64), dtype=np.uint64).astype(np.uint32)
        base = (0, 0) if case % 2 else (64, 0)

        def run(level, fused, lanes, bits):
            return core.testing.interpolated_color_lanes(level, fused, planes, ox, oy, quads, values, base[0], base[1],
                                                         first, blend, fe, mask, has_alpha, lanes, bits, image)
        # The reference: row quads' lanes gathered from the image, scattered back after.
        in_row = np.zeros(n, bool)
        for i in range(n):
            in_row[i:i + 4] |= bool(rows >> i & 1)
        px, py = quads[:, 0:1] + np.array([0, 1, 0, 1]), quads[:, 1:2] + np.array([0, 0, 1, 1])
        gathered = np.where(np.repeat(in_row, 4), image[py, px].ravel(), dst)
        lanes, _ = run(0, False, gathered, 0)
        want_image = image.copy()
        want_image[py[in_row], px[in_row]] = lanes.reshape(n, 4)[in_row]
        want_lanes = np.where(np.repeat(in_row, 4), dst, lanes)
        for level in levels:
            msg = f"case {case} level {level}"
            np.testing.assert_array_equal(run(level, False, dst, 0)[0], run(0, False, dst, 0)[0], err_msg=msg)
            got_lanes, got_image = run(level, True, dst, rows)
            np.testing.assert_array_equal(got_lanes, want_lanes, err_msg=msg)
            np.testing.assert_array_equal(got_image, want_image, err_msg=msg)
