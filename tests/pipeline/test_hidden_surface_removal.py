"""Hidden-surface removal (pipeline/tile_pass.cpp OwnerMap; docs/architecture.md, "Fast paths"):
without blending, a pixel ends with the colour of the last fragment that passed the tests, so in
tiles where a draw's primitives pile up only those fragments are shaded. It must not change a
byte: every draw here is compared with the same draw without it (mode 0, the context's tuning
hidden_surface_removal='off') and with it in every tile (mode 2, 'in_every_tile'), colour and
depth, at 1 and 2 threads; flat-coloured rectangles are also compared with a painter's model in
NumPy, and the counters with a hand count."""
import numpy as np
import pytest

import softgl
from softgl import _core

SIZE = 133   # three tiles across, the last one partial; odd: quads reach past the edge
VS = """#version 300 es
in vec4 aPos;
in vec4 aColor;
out vec4 vColor;
void main() { gl_Position = aPos; gl_PointSize = 9.0; vColor = aColor; }
"""
COPY_FS = """#version 300 es
precision highp float;
in vec4 vColor;
out vec4 fragColor;
void main() { fragColor = vColor; }
"""
UNIFORM_FS = """#version 300 es
precision highp float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; }
"""
# Derivatives and implicit-LOD lookups read the quad's other lanes (helpers where not owned).
DERIVATIVE_FS = """#version 300 es
precision highp float;
in vec4 vColor;
uniform sampler2D uTex;
out vec4 fragColor;
void main() {
  vec2 uv = vColor.xy * 7.0 + gl_FragCoord.xy * 0.01;
  fragColor = vec4(fwidth(vColor.rg) * 20.0, dFdy(vColor.b) * 30.0, 1.0) * 0.5 + texture(uTex, uv) * 0.5;
}
"""
# Two outputs: both come from the owner.
MRT_FS = """#version 300 es
precision highp float;
in vec4 vColor;
layout(location = 0) out vec4 out0;
layout(location = 1) out vec4 out1;
void main() { out0 = vColor; out1 = vColor.bgra * 0.5; }
"""
DISCARD_FS = """#version 300 es
precision highp float;
in vec4 vColor;
out vec4 fragColor;
void main() { if (vColor.a < 0.3) discard; fragColor = vColor; }
"""


MODES = ("off", "where_piles_up", "in_every_tile", "where_boxes_pile_up")   # modes 0, 1, 2, 3


@pytest.fixture
def hsr_mode():
    """The default tuning for the test's contexts, hidden-surface removal where primitives pile
    up (each draw sets its mode); the previous default is back after the test."""
    previous = _core.testing.set_default_tuning(hidden_surface_removal="where_piles_up")
    yield
    _core.testing.set_default_tuning(**previous)


def counters(gl):
    return {k: v for k, v in gl.stats().items() if not k.startswith("seconds")}


def triangles(rng, n, spread=1.0, z=(-0.9, 0.9)):
    """n large random triangles (positions x, y, z, w) and a colour per vertex."""
    centre = rng.uniform(-spread, spread, (n, 1, 2))
    corner = rng.uniform(-1.0, 1.0, (n, 3, 2))
    xy = (centre + corner).reshape(-1, 2)
    zz = np.repeat(rng.uniform(*z, n), 3) + rng.uniform(-0.05, 0.05, 3 * n)
    pos = np.column_stack([xy, zz, np.ones(3 * n)]).astype(np.float32)
    return pos, rng.uniform(0, 1, (3 * n, 4)).astype(np.float32)


def render(mode, fs, pos, color, threads=1, setup=None, primitive="TRIANGLES", fbo=None, stencil=False):
    """Draws pos/color in one drawArrays; returns (colour bytes, depth words, counters)."""
    gl = softgl.Context(SIZE, SIZE, threads=threads, antialias=False, stencil=stencil, preserveDrawingBuffer=True)
    prog = softgl.program(gl, VS, fs, {"aPos": 0, "aColor": 1})
    gl.useProgram(prog)
    gl.bindVertexArray(gl.createVertexArray())
    for loc, data in ((0, pos), (1, color)):
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(data, np.float32), gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, 4, gl.FLOAT, False, 0, 0)
    targets = fbo(gl) if fbo else None
    gl.clearColor(0.2, 0.4, 0.6, 1.0)
    gl.clearDepth(0.625)   # window depth of z = 0.25: EQUAL passes there
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    if setup:
        setup(gl, prog)
    gl.stats(reset=True)
    _core.testing.set_tuning(gl, hidden_surface_removal=MODES[mode])
    gl.drawArrays(getattr(gl, primitive), 0, len(pos))
    assert gl.getError() == gl.NO_ERROR
    plan = gl.last_draw_plan()
    assert plan["hidden_surface_in_every_tile"] == (mode == 2)
    if mode == 0:
        assert plan["hidden_surface_removal_why_not"] == "tuning_off"
    stats = counters(gl)
    if targets:
        images = []
        for k, (fmt, kind) in enumerate(targets):
            gl.readBuffer(gl.COLOR_ATTACHMENT0 + k)
            images.append(gl.readPixels(0, 0, SIZE, SIZE, fmt, kind).tobytes())
        return images, None, stats
    image = gl.readPixels(0, 0, SIZE, SIZE, gl.RGBA, gl.UNSIGNED_BYTE).tobytes()
    return image, _core.testing.read_depth(gl).tobytes(), stats


def same_with_and_without(fs, pos, color, expect_hidden=True, **kw):
    """Renders in modes 0, 1, 2, 3 at 1 and 2 threads; all must give the same bytes. Returns mode
    0's image and the counters of modes 0 and 2."""
    results = {(m, t): render(m, fs, pos, color, threads=t, **kw) for m in (0, 1, 2, 3) for t in (1, 2)}
    reference = results[(0, 1)]
    for key, (image, depth, _) in results.items():
        assert image == reference[0], f"colour differs with hidden-surface removal mode/threads {key}"
        assert depth == reference[1], f"depth differs with hidden-surface removal mode/threads {key}"
    off, every = results[(0, 1)][2], results[(2, 1)][2]
    assert off["fragments_hidden"] == 0 and off["tiles_hidden_surface"] == 0
    for m in (1, 2, 3):   # the pass runs in the same tiles at any thread count
        assert results[(m, 1)][2]["tiles_hidden_surface"] == results[(m, 2)][2]["tiles_hidden_surface"]
    if expect_hidden:
        assert every["fragments_hidden"] > 0
        assert every["fragments_shaded"] < off["fragments_shaded"]
    else:
        assert every["fragments_hidden"] == 0
    # The tests and the writes happen exactly as often as without it.
    for key in ("fragments_killed_early", "primitives_rasterized"):
        assert every[key] == off[key], key
    return reference[0], off, every


DEPTH_FUNCS = ("NEVER", "LESS", "EQUAL", "LEQUAL", "GREATER", "NOTEQUAL", "GEQUAL", "ALWAYS")


def test_overlapping_triangles_without_depth(hsr_mode):
    pos, color = triangles(np.random.default_rng(1), 60)
    same_with_and_without(COPY_FS, pos, color)


@pytest.mark.parametrize("func", DEPTH_FUNCS)
@pytest.mark.parametrize("mask", (True, False))
def test_every_depth_function_and_mask(hsr_mode, func, mask):
    pos, color = triangles(np.random.default_rng(2), 40, z=(-0.8, 0.8))
    # Quantised depths: EQUAL and LEQUAL meet ties.
    pos[:, 2] = np.round(pos[:, 2] * 4) / 4

    def setup(gl, prog):
        gl.enable(gl.DEPTH_TEST)
        gl.depthFunc(getattr(gl, func))
        gl.depthMask(mask)
    same_with_and_without(DERIVATIVE_FS if func in ("LESS", "GEQUAL") else COPY_FS, pos, color,
                          setup=setup, expect_hidden=func != "NEVER")


def test_colour_mask_and_uniform_colour(hsr_mode):
    pos, color = triangles(np.random.default_rng(3), 30)

    def setup(gl, prog):
        gl.colorMask(True, False, True, False)
        gl.uniform4f(gl.getUniformLocation(prog, "uColor"), 0.9, 0.1, 0.3, 0.5)
    same_with_and_without(UNIFORM_FS, pos, color, setup=setup)
    same_with_and_without(COPY_FS, pos, color, setup=setup)


def test_derivatives_and_texture_lod_use_the_quads_other_lanes(hsr_mode):
    pos, color = triangles(np.random.default_rng(4), 30)

    def setup(gl, prog):
        tex = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, tex)
        img = np.random.default_rng(5).integers(0, 256, (32, 32, 4), dtype=np.uint8)
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 32, 32, 0, gl.RGBA, gl.UNSIGNED_BYTE, img)
        gl.generateMipmap(gl.TEXTURE_2D)
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR)
    same_with_and_without(DERIVATIVE_FS, pos, color, setup=setup)


def test_points_and_plain_write_blending(hsr_mode):
    rng = np.random.default_rng(6)
    pos = np.column_stack([rng.uniform(-1, 1, (3000, 2)), rng.uniform(-1, 1, 3000), np.ones(3000)]).astype(np.float32)
    color = rng.uniform(0, 1, (3000, 4)).astype(np.float32)

    def setup(gl, prog):   # ONE, ZERO, FUNC_ADD: a plain write on the drawing buffer
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.ONE, gl.ZERO)
        gl.enable(gl.DEPTH_TEST)
    same_with_and_without(COPY_FS, pos, color, setup=setup, primitive="POINTS")


def test_float_and_multiple_render_targets(hsr_mode):
    pos, color = triangles(np.random.default_rng(7), 30)
    color[::7] = [np.inf, -np.inf, 2.5, np.nan]   # stored as given in a float buffer

    def fbo(gl):
        assert gl.getExtension("EXT_color_buffer_float")
        gl.bindFramebuffer(gl.FRAMEBUFFER, gl.createFramebuffer())
        formats = [(gl.RGBA32F, gl.FLOAT), (gl.RGBA8, gl.UNSIGNED_BYTE)]
        for k, (internal, kind) in enumerate(formats):
            tex = gl.createTexture()
            gl.bindTexture(gl.TEXTURE_2D, tex)
            gl.texImage2D(gl.TEXTURE_2D, 0, internal, SIZE, SIZE, 0, gl.RGBA, kind, None)
            gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + k, gl.TEXTURE_2D, tex, 0)
        gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1])
        return [(gl.RGBA, kind) for _, kind in formats]
    same_with_and_without(MRT_FS, pos, color, fbo=fbo)


def test_not_used_where_the_result_depends_on_hidden_fragments(hsr_mode):
    pos, color = triangles(np.random.default_rng(8), 30)

    def blend(gl, prog):
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)

    def stencil(gl, prog):
        gl.enable(gl.STENCIL_TEST)
        gl.stencilOp(gl.KEEP, gl.KEEP, gl.INCR)
    same_with_and_without(COPY_FS, pos, color, setup=blend, expect_hidden=False)
    same_with_and_without(COPY_FS, pos, color, setup=stencil, stencil=True, expect_hidden=False)
    same_with_and_without(DISCARD_FS, pos, color, expect_hidden=False)


def test_batches_each_remove_their_own_hidden_surfaces(hsr_mode):
    pos, color = triangles(np.random.default_rng(9), 50)
    _core.testing.set_default_tuning(batch_primitives=7)   # hsr_mode restores the default
    same_with_and_without(COPY_FS, pos, color)


def test_rectangles_match_a_painters_model_and_a_hand_count(hsr_mode):
    """Flat-coloured axis-aligned rectangles on pixel edges, no depth: each pixel shows the last
    rectangle covering it. Every pixel covered by k rectangles is written k times without removal,
    once with it (mode 2: in every tile), and hidden k - 1 times."""
    rng = np.random.default_rng(10)
    n = 25
    pos, color, expect = [], [], np.zeros((SIZE, SIZE, 4), np.uint8)
    expect[...] = np.round(np.array([0.2, 0.4, 0.6, 1.0]) * 255)
    layers = np.zeros((SIZE, SIZE), np.int64)
    for _ in range(n):
        x0, x1 = sorted(rng.integers(0, SIZE // 2 + 1, 2) * 2)   # even edges: whole quads
        y0, y1 = sorted(rng.integers(0, SIZE // 2 + 1, 2) * 2)
        if x0 == x1 or y0 == y1:
            continue
        c = rng.integers(0, 256, 4)
        X0, X1, Y0, Y1 = (2 * np.array([x0, x1, y0, y1]) / SIZE - 1)
        pos += [[X0, Y0, 0, 1], [X1, Y0, 0, 1], [X1, Y1, 0, 1], [X0, Y0, 0, 1], [X1, Y1, 0, 1], [X0, Y1, 0, 1]]
        color += [c / 255] * 6
        expect[y0:y1, x0:x1] = c
        layers[y0:y1, x0:x1] += 1
    pos, color = np.array(pos, np.float32), np.array(color, np.float32)
    image, off, every = same_with_and_without(COPY_FS, pos, color)
    assert np.array_equal(np.frombuffer(image, np.uint8).reshape(SIZE, SIZE, 4), expect)
    assert off["samples_written"] == layers.sum()
    assert every["samples_written"] == np.count_nonzero(layers)
    assert every["fragments_hidden"] == layers.sum() - np.count_nonzero(layers)


def test_deep_piles_past_the_kept_quads_bound(hsr_mode):
    """The first pass keeps each primitive's quads for the second (no second raster), at most 2^16
    quads per tile; the primitives after that are rasterized again. 150 full-canvas layers put
    ~150 x 1,024 quads in a whole tile, so both kinds are drawn: each pixel shows the last layer
    and is written once per layer without removal, once with it."""
    rng = np.random.default_rng(11)
    n = 150
    colors = rng.integers(0, 256, (n, 4))
    quad = [[-1, -1, 0, 1], [1, -1, 0, 1], [1, 1, 0, 1], [-1, -1, 0, 1], [1, 1, 0, 1], [-1, 1, 0, 1]]
    pos = np.array(quad * n, np.float32)
    color = np.repeat(colors / 255, 6, axis=0).astype(np.float32)
    image, off, every = same_with_and_without(COPY_FS, pos, color)
    expect = np.broadcast_to(colors[-1].astype(np.uint8), (SIZE, SIZE, 4))
    assert np.array_equal(np.frombuffer(image, np.uint8).reshape(SIZE, SIZE, 4), expect)
    assert off["samples_written"] == n * SIZE * SIZE
    assert every["samples_written"] == SIZE * SIZE
    assert every["fragments_hidden"] == (n - 1) * SIZE * SIZE


def grid(cells, z, rng):
    """A mesh of cells x cells squares (two triangles each) over the whole canvas at depth z, its
    inner vertices jittered (the triangles still tile the canvas once), colours at random."""
    t = np.linspace(-1, 1, cells + 1)
    x, y = np.meshgrid(t, t)
    jitter = rng.uniform(-0.3, 0.3, (2, cells + 1, cells + 1)) * (2 / cells)
    jitter[:, [0, -1], :] = 0
    jitter[:, :, [0, -1]] = 0
    x, y = x + jitter[0], y + jitter[1]
    tris = []
    for i in range(cells):
        for j in range(cells):
            a, b, c, d = (i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)
            tris += [a, b, c, a, c, d]
    pos = np.array([[x[v], y[v], z, 1.0] for v in tris], np.float32)
    return pos, rng.uniform(0, 1, (len(pos), 4)).astype(np.float32)


def test_a_mesh_covering_the_tiles_once_skips_the_first_pass(hsr_mode):
    """A triangle covers at most its area, half its bounding box or less: a mesh of small
    triangles that covers each tile once has boxes that cover it twice, and the first pass would
    hide nothing there. Counted by area (mode 1) the pass does not run; by boxes (mode 3) it
    does; the same mesh twice (the second layer in front) piles up either way and hides the
    first. Same bytes in every mode."""
    rng = np.random.default_rng(12)

    def setup(gl, prog):
        tex = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, tex)
        img = np.random.default_rng(5).integers(0, 256, (32, 32, 4), dtype=np.uint8)
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 32, 32, 0, gl.RGBA, gl.UNSIGNED_BYTE, img)
        gl.generateMipmap(gl.TEXTURE_2D)
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR)
        gl.enable(gl.DEPTH_TEST)
    once = grid(24, 0.2, rng)   # triangles of ~15 pixels
    same_with_and_without(DERIVATIVE_FS, *once, setup=setup, expect_hidden=False)
    by_area = render(1, DERIVATIVE_FS, *once, setup=setup)[2]
    by_boxes = render(3, DERIVATIVE_FS, *once, setup=setup)[2]
    assert by_area["tiles_hidden_surface"] == 0 and by_area["fragments_hidden"] == 0
    assert by_boxes["tiles_hidden_surface"] == 9 and by_boxes["fragments_hidden"] == 0   # 3 x 3 tiles
    back, front = grid(24, 0.2, rng), grid(24, -0.2, rng)
    twice = np.concatenate([back[0], front[0]]), np.concatenate([back[1], front[1]])
    same_with_and_without(DERIVATIVE_FS, *twice, setup=setup)
    by_area = render(1, DERIVATIVE_FS, *twice, setup=setup)[2]
    assert by_area["tiles_hidden_surface"] == 9
    assert by_area["fragments_hidden"] == SIZE * SIZE   # the back layer, every pixel once
