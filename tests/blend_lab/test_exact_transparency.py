"""SOFTGL_exact_transparency: the A-buffer against a brute-force per-pixel sort in NumPy float64,
the approximations' error ordering, the memory limit, determinism."""
import warnings

import numpy as np
import pytest

import softgl
from softgl import transparency as tr

VS = "attribute vec4 aPos; void main() { gl_Position = aPos; }"
FS = "precision highp float; uniform vec4 uColor; void main() { gl_FragColor = uColor; }"
W, H = 48, 40
# (source, destination) factor pairs a random triangle may blend with: "over", additive,
# multiplicative, premultiplied "over".
FUNCS = [("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA"), ("ONE", "ONE"), ("DST_COLOR", "ZERO"),
         ("ONE", "ONE_MINUS_SRC_ALPHA")]


def random_scene(seed, n=14):
    rng = np.random.default_rng(seed)
    tris = []
    for _ in range(n):
        xy = rng.uniform(-1.1, 1.1, (3, 2))
        z = rng.uniform(-0.9, 0.9, 3)
        color = rng.uniform(0, 1, 4).astype(np.float32)
        color[3] = np.float32(rng.uniform(0.1, 0.9))
        tris.append((np.c_[xy, z, np.ones(3)].astype(np.float32), color, FUNCS[rng.integers(len(FUNCS))]))
    background = np.float32(rng.uniform(0, 1, 3))
    return tris, background


def draw_scene(gl, tris, background, capture=True):
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    loc = gl.test_color = gl.getUniformLocation(prog, "uColor")
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    gl.clearColor(*background, 1.0)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    # The usual transparent pass: depth test on, depth writes off (the resolve re-tests these).
    gl.enable(gl.DEPTH_TEST)
    gl.depthMask(False)
    gl.enable(gl.BLEND)
    ext = gl.getExtension("SOFTGL_exact_transparency")
    if capture:
        gl.enable(ext.EXACT_TRANSPARENCY_SOFTGL)
    for pos, color, (sf, df) in tris:
        gl.blendFunc(getattr(gl, sf), getattr(gl, df))
        gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW)
        gl.uniform4f(loc, *color)
        gl.drawArrays(gl.TRIANGLES, 0, 3)
    return ext


def brute_force(tris, background):
    """Per pixel: every triangle covering the centre, sorted far to near (stable: submission
    order for equal depth), blended in float64 with its own factors and unorm clamping, over
    the background as the drawing buffer holds it (8 bits)."""
    background = np.floor(background.astype(np.float64) * 255 + 0.5) / 255
    ys, xs = np.mgrid[0:H, 0:W] + 0.5
    frags = [[[] for _ in range(W)] for _ in range(H)]
    ambiguous = np.zeros((H, W), bool)
    for k, (pos, color, funcs) in enumerate(tris):
        # Window coordinates snapped to 8 sub-pixel bits, z to [0, 1] (docs/architecture.md,
        # "Numeric rules").
        wx = np.round((pos[:, 0].astype(np.float64) + 1) * W / 2 * 256) / 256
        wy = np.round((pos[:, 1].astype(np.float64) + 1) * H / 2 * 256) / 256
        wz = (pos[:, 2].astype(np.float64) + 1) / 2
        e = [(wx[(i + 2) % 3] - wx[(i + 1) % 3]) * (ys - wy[(i + 1) % 3]) -
             (wy[(i + 2) % 3] - wy[(i + 1) % 3]) * (xs - wx[(i + 1) % 3]) for i in range(3)]
        area = sum(e)
        if area[0, 0] == 0:
            continue
        inside = np.all([ei * np.sign(area) > 0 for ei in e], axis=0)
        ambiguous |= np.any([ei == 0 for ei in e], axis=0)   # on an edge: the fill rule decides
        z = sum(e[i] * wz[i] for i in range(3)) / area
        for y, x in zip(*np.nonzero(inside)):
            frags[y][x].append((z[y, x], k))
    out = np.empty((H, W, 3))
    for y in range(H):
        for x in range(W):
            d = background.astype(np.float64).copy()
            fl = sorted(frags[y][x], key=lambda f: (-f[0], f[1]))
            zs = [f[0] for f in fl]
            if any(abs(a - b) < 1e-6 for a, b in zip(zs, zs[1:])):
                ambiguous[y, x] = True   # crossing surfaces: the order is a rounding question
            for _, k in fl:
                _, color, (sf, df) = tris[k]
                s = np.clip(color.astype(np.float64), 0, 1)
                a, da = s[3], 1.0
                factor = {"SRC_ALPHA": a, "ONE_MINUS_SRC_ALPHA": 1 - a, "ONE": 1.0, "ZERO": 0.0}
                src = s[:3] * (d if sf == "DST_COLOR" else factor[sf])
                d = np.clip(src + d * factor[df], 0, 1)
            out[y, x] = d
    return out, ambiguous


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_exact_equals_brute_force_sort(seed):
    tris, background = random_scene(seed)
    gl = softgl.Context(W, H, antialias=False, alpha=False, strict=True)
    ext = draw_scene(gl, tris, background)
    before = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)
    assert (before[..., :3] == np.round(background * 255)).all()   # captured, not blended
    exact = ext.resolve()
    img = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)[..., :3].astype(int)
    ref, ambiguous = brute_force(tris, background)
    ok = ~ambiguous
    assert ok.sum() > 0.9 * W * H
    assert np.abs(exact[..., :3] - ref)[ok].max() < 1e-9          # the float64 composite
    assert (img[ok] == np.floor(ref[ok] * 255 + 0.5)).all()        # rounded once, at the end
    assert ext.memory()["fragments"] == 0                          # resolve empties the A-buffer


def test_same_bytes_for_any_thread_count_and_multisampling():
    tris, background = random_scene(7)
    images = []
    for threads in (1, 3):
        gl = softgl.Context(W, H, antialias=True, samples=4, alpha=False, threads=threads, strict=True)
        ext = draw_scene(gl, tris, background)
        f = ext.resolve()
        images.append((gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE), f))
    assert (images[0][0] == images[1][0]).all() and (images[0][1] == images[1][1]).all()


def test_opaque_geometry_drawn_after_transparent_still_hides_it():
    # Draw a transparent quad at z = 0.5, then an opaque quad in front of it: the re-test at
    # resolve time drops the hidden transparent fragments (order independence).
    tris = [(np.array([[-1, -1, 0.5, 1], [1, -1, 0.5, 1], [-1, 1, 0.5, 1]], np.float32),
             np.float32([1, 0, 0, 0.5]), FUNCS[0])]
    gl = softgl.Context(8, 8, antialias=False, alpha=False, strict=True)
    ext = draw_scene(gl, tris, np.float32([0, 0, 0]))
    gl.disable(gl.BLEND)
    gl.depthMask(True)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [-1, 1, 0, 1]], np.float32), gl.STATIC_DRAW)
    gl.uniform4f(gl.test_color, 0, 0, 1, 1)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    ext.resolve()
    assert gl.readPixels(1, 1, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)[0, 0].tolist() == [0, 0, 255, 255]


def test_memory_limit_raises_and_never_truncates():
    tris, background = random_scene(4)
    gl = softgl.Context(W, H, antialias=False, alpha=False, strict=True)
    ext = gl.getExtension("SOFTGL_exact_transparency")
    ext.setMemoryLimit(4096)
    with pytest.raises(softgl.GLError, match="OUT_OF_MEMORY.*A-buffer needs"):
        draw_scene(gl, tris, background)
    # Not strict: a warning, the error code, and resolve refuses without touching the pixels.
    gl = softgl.Context(W, H, antialias=False, alpha=False)
    ext = gl.getExtension("SOFTGL_exact_transparency")
    ext.setMemoryLimit(4096)
    with pytest.warns(softgl.GLWarning, match="OUT_OF_MEMORY"):
        draw_scene(gl, tris, background)
    assert gl.getError() == gl.OUT_OF_MEMORY
    mem = ext.memory()
    assert mem["overflowed"] and mem["bytes_needed"] > mem["limit"] >= mem["bytes_stored"]
    before = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)
    with pytest.warns(softgl.GLWarning, match="overflowed"):
        assert ext.resolve() is None
    assert gl.getError() == gl.INVALID_OPERATION
    assert (gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE) == before).all()
    # A full clear starts again; with room, it resolves.
    ext.setMemoryLimit(1 << 24)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        draw_scene(gl, tris, background)
        assert ext.resolve() is not None
    # The Python API raises too.
    with pytest.raises(softgl.GLError, match="OUT_OF_MEMORY"):
        tr.render(tr.demo_scene(), "exact", width=64, height=64, memory_limit=10_000)


def test_extension_off_by_default(quiet):
    gl = softgl.Context(4, 4)
    gl.enable(0x1D100)
    assert gl.getError() == gl.INVALID_ENUM           # not a capability before getExtension
    assert "SOFTGL_exact_transparency" in gl.getSupportedExtensions()
    ext = gl.getExtension("SOFTGL_exact_transparency")
    assert not gl.isEnabled(ext.EXACT_TRANSPARENCY_SOFTGL)
    assert ext.resolve(0x1234) is None and gl.getError() == gl.INVALID_ENUM
    assert ext.resolve(ext.DEPTH_PEELING_SOFTGL, layers=0) is None and gl.getError() == gl.INVALID_VALUE


@pytest.fixture(scope="module")
def demo_results():
    return tr.compare(tr.demo_scene(), width=96, height=96, peeling_layers=(1, 2, 3, 4, 6, 8, 16))


def test_error_ordering_on_the_demo_scene(demo_results):
    r = {k: v.error.rmse for k, v in demo_results.items()}
    assert r["exact"] == 0
    assert r["unsorted"] > r["sorted_objects"] > r["sorted_triangles"] > 0
    peel = [r[f"peeling({k})"] for k in (1, 2, 3, 4, 6, 8, 16)]
    assert all(a >= b for a, b in zip(peel, peel[1:]))           # more layers, less error
    complexity = int(tr.depth_complexity(tr.demo_scene(), width=96, height=96).max())
    assert complexity <= 16 and r["peeling(16)"] == 0             # all layers: the exact image
    assert r["sorted_triangles"] >= r["peeling(16)"]
    assert r["sorted_triangles"] >= r[f"peeling({max(k for k in (1, 2, 3, 4, 6, 8, 16) if k >= complexity)})"]
    assert 0 < r["wboit(eq7)"] < r["unsorted"]
