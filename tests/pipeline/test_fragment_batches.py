"""Shade full batches (pipeline/tile_pass.cpp, "gather"): the fragments of many primitives of a tile
gathered into one shader run, as whole quads or, for a shader that reads no quad neighbour, as
single covered pixels (no helper lanes). The reference is the shader run per primitive chunk
(Tuning fragment_batches=False): every draw here must give its bytes, whatever the order rules
(overlapping fragments blended in draw order, early depth written at test time, late tests,
discard, fog, MSAA) make of the batches."""
import numpy as np
import pytest

import softgl
from softgl.testing import tuned

W, H = 96, 80   # two tiles across, partial quads at the edges

VS = """#version 300 es
in vec4 aPos;
in vec4 aColor;
out vec4 vColor;
flat out int vId;
void main() { vColor = aColor; vId = gl_VertexID; gl_Position = aPos; gl_PointSize = 3.0; }
"""
HEAD = "#version 300 es\nprecision highp float;\nin vec4 vColor;\nflat in int vId;\nout vec4 o;\n"
SHADERS = {
    # Not a copy: the executor runs (sqrt keeps it from being one).
    "plain": "void main() { o = vec4(sqrt(vColor.rgb), vColor.a); }",
    # Per-lane built-ins and a flat varying.
    "builtins": """void main() {
        o = vec4(fract(gl_FragCoord.x * 0.173 + gl_FragCoord.y * 0.091), gl_FragCoord.z,
                 fract(gl_FragCoord.w * 3.7 + float(vId % 7) * 0.11), gl_FrontFacing ? 0.8 : 0.3); }""",
    # Derivatives: whole quads, helper lanes shaded.
    "derivatives": "void main() { o = vec4(vColor.rgb + 8.0 * abs(dFdx(vColor.rgb)) + 8.0 * abs(dFdy(vColor.gbr)), vColor.a); }",
    # Late tests: discard, and depth written by the shader.
    "discard": "void main() { if (vColor.a < 0.45) discard; o = vec4(sqrt(vColor.rgb), vColor.a); }",
    "frag_depth": "void main() { gl_FragDepth = vColor.a; o = vec4(sqrt(vColor.rgb), 0.6); }",
    "point_coord": "void main() { o = vec4(gl_PointCoord, vColor.b, vColor.a); }",
}


def alpha_blend(gl):
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)


def depth_less(gl):
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.LESS)


def blend_depth(gl):
    alpha_blend(gl)
    depth_less(gl)


def additive_mask(gl):   # a kernel that reads the destination, and a colour mask
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    gl.colorMask(True, False, True, True)


def stencil(gl):   # early tests sample by sample
    depth_less(gl)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilFunc(gl.NOTEQUAL, 1, 0xFF)
    gl.stencilOp(gl.KEEP, gl.KEEP, gl.INCR)


def fog(gl):   # lane by lane, the primitive's planes per lane
    alpha_blend(gl)
    ext = gl.getExtension("SOFTGL_fog")
    gl.enable(ext.FOG)
    ext.fogi(ext.FOG_MODE, ext.LINEAR)
    ext.fogf(ext.FOG_START, 1.0)
    ext.fogf(ext.FOG_END, 4.0)
    ext.fogfv(ext.FOG_COLOR, [0.2, 0.4, 0.8, 1.0])


STATES = {"none": None, "blend": alpha_blend, "depth": depth_less, "blend_depth": blend_depth,
          "additive_mask": additive_mask, "stencil": stencil, "fog": fog}


def geometry(mode, n=500, pixels=7.0, seed=3, mixed=False):
    """n small primitives, overlapping, with perspective (w from 1 to 3) and both facings; `mixed`:
    every seventh one large (its chunks are shaded on their own, between gathered batches)."""
    r = np.random.default_rng(seed)
    per = {"TRIANGLES": 3, "LINES": 2, "POINTS": 1}[mode]
    centre = r.uniform(-1, 1, (n, 1, 2))
    scale = np.where(np.arange(n) % 7 == 3, 8.0, 1.0)[:, None, None] if mixed else 1.0
    xy = (centre + r.uniform(-1, 1, (n, per, 2)) * scale * (pixels / W)).reshape(-1, 2)
    z = np.repeat(r.uniform(-0.9, 0.9, (n, 1)), per, axis=1).reshape(-1, 1) + r.uniform(-0.05, 0.05, (n * per, 1))
    w = r.uniform(1, 3, (n * per, 1))
    pos = np.concatenate([xy * w, z * w, w], axis=1).astype(np.float32)
    color = r.uniform(0, 1, (n * per, 4)).astype(np.float32)
    return pos, color


def render(shader, state, mode="TRIANGLES", samples=0, threads=1, mixed=False, **tuning):
    kw = dict(antialias=samples > 0, threads=threads, preserveDrawingBuffer=True, stencil=True)
    if samples:
        kw["samples"] = samples
    gl = softgl.Context(W, H, **kw)
    with tuned(gl, **tuning):
        prog = softgl.program(gl, VS, HEAD + SHADERS[shader])
        gl.useProgram(prog)
        pos, color = geometry(mode, mixed=mixed)
        for name, data in (("aPos", pos), ("aColor", color)):
            loc = gl.getAttribLocation(prog, name)
            gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
            gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
            gl.enableVertexAttribArray(loc)
            gl.vertexAttribPointer(loc, 4, gl.FLOAT, False, 0, 0)
        gl.clearColor(0.1, 0.2, 0.3, 0.4)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
        if STATES[state]:
            STATES[state](gl)
        gl.stats(reset=True)
        gl.drawArrays(getattr(gl, mode), 0, len(pos))
        # A second draw over the first: the depth and stencil the first left must be the same too.
        gl.drawArrays(getattr(gl, mode), 0, len(pos) // 2)
        assert gl.getError() == gl.NO_ERROR
        image = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)
        stats = {k: v for k, v in gl.stats().items() if not k.startswith("seconds")}
        return np.asarray(image), stats, gl.last_draw_plan()


def check_same_bytes(shader, state, mode="TRIANGLES", samples=0, threads=1, mixed=False):
    ref, ref_stats, ref_plan = render(shader, state, mode, samples, threads, mixed, fragment_batches=False)
    quads, quad_stats, quad_plan = render(shader, state, mode, samples, threads, mixed, skip_helper_lanes=False)
    pixels, pixel_stats, plan = render(shader, state, mode, samples, threads, mixed)
    assert ref_plan["fragment_batches"] is False and ref_plan["fragment_batches_why_not"] == "tuning_off"
    assert quad_plan["fragment_batches"] and plan["fragment_batches"], plan["text"]
    assert ref.any() and (ref != ref[0, 0]).any()
    assert quads.tobytes() == ref.tobytes(), (shader, state, mode, samples)
    assert pixels.tobytes() == ref.tobytes(), (shader, state, mode, samples)
    # The same fragments tested and written; whole quads shade the reference's lanes, single
    # pixels only the covered ones.
    shaded = [s.pop("fragments_shaded") for s in (ref_stats, quad_stats, pixel_stats)]
    assert ref_stats == quad_stats == pixel_stats
    assert shaded[1] == shaded[0]
    derivatives = shader == "derivatives"
    assert plan["no_helper_lanes"] == (not derivatives), plan["text"]
    if derivatives:
        assert plan["no_helper_lanes_why_not"] == "quad_neighbours" and shaded[2] == shaded[0]
    else:
        assert quad_plan["no_helper_lanes_why_not"] == "tuning_off"
        assert shaded[2] < shaded[1]
    return ref_stats


@pytest.mark.parametrize("state", sorted(STATES))
@pytest.mark.parametrize("shader", ["plain", "builtins", "derivatives", "discard", "frag_depth"])
def test_triangles_batched_equal_per_primitive(shader, state):
    stats = check_same_bytes(shader, state)
    if state in ("depth", "blend_depth"):
        assert stats["fragments_killed_early" if shader in ("plain", "builtins", "derivatives")
                     else "fragments_killed_late"] > 0


@pytest.mark.parametrize("state", ["blend", "blend_depth", "additive_mask", "fog"])
@pytest.mark.parametrize("shader", ["plain", "derivatives", "discard"])
def test_large_and_small_triangles_mixed(shader, state):
    check_same_bytes(shader, state, mixed=True)


@pytest.mark.parametrize("samples", [0, 4])
@pytest.mark.parametrize("mode", ["LINES", "POINTS"])
@pytest.mark.parametrize("state", ["blend", "blend_depth", "fog"])
def test_lines_and_points_batched_equal_per_primitive(mode, state, samples):
    check_same_bytes("point_coord" if mode == "POINTS" else "builtins", state, mode, samples)
    check_same_bytes("discard", state, mode, samples)


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("state", ["blend", "blend_depth", "stencil", "additive_mask"])
@pytest.mark.parametrize("shader", ["plain", "derivatives", "discard"])
def test_multisampled_batched_equal_per_primitive(shader, state, threads):
    check_same_bytes(shader, state, samples=4, threads=threads)


def test_plan_says_why_a_draw_is_not_batched():
    gl = softgl.Context(16, 16, antialias=False)
    pos = np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [-1, 1, 0, 1]], np.float32)

    def draw(fs):
        prog = softgl.program(gl, VS, fs)
        gl.useProgram(prog)
        loc = gl.getAttribLocation(prog, "aPos")
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, 4, gl.FLOAT, False, 0, 0)
        gl.drawArrays(gl.TRIANGLES, 0, 3)
        return gl.last_draw_plan()

    plan = draw(HEAD + "void main() { o = vColor; }")   # straight into pixels, no shader batch
    assert plan["fused_copy"] and plan["fragment_batches_why_not"] == "fused_copy"
    assert plan["no_helper_lanes_why_not"] == "fused_copy"
    plan = draw(HEAD + "uniform vec4 u; void main() { o = u; }")   # the colour computed once
    assert plan["constant_color"] and plan["fragment_batches_why_not"] == "constant_color"
    plan = draw(HEAD + SHADERS["derivatives"])
    assert plan["fragment_batches"] and plan["no_helper_lanes_why_not"] == "quad_neighbours"
    # An implicit-LOD lookup reads the quad's neighbours too, where the LOD can change the result
    # (here a mipmapped texture); an explicit LOD does not. Unbound, the unit samples (0, 0, 0, 1)
    # whatever the LOD (tests/pipeline/test_lod_free_helper_lanes.py).
    tex = HEAD + "uniform sampler2D s; void main() { o = texture(s, vColor.xy) + vColor; }"
    assert draw(tex)["no_helper_lanes"]
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 4, 4, 0, gl.RGBA, gl.UNSIGNED_BYTE, np.zeros((4, 4, 4), np.uint8))
    gl.generateMipmap(gl.TEXTURE_2D)
    assert draw(tex)["no_helper_lanes_why_not"] == "quad_neighbours"
    assert draw(tex.replace("texture(s, vColor.xy)", "textureLod(s, vColor.xy, 0.0)"))["no_helper_lanes"]
    plan = draw(HEAD + SHADERS["plain"])
    assert plan["fragment_batches"] and plan["no_helper_lanes"]
    ext = gl.getExtension("SOFTGL_smooth")
    gl.enable(ext.POLYGON_SMOOTH)
    assert draw(HEAD + SHADERS["plain"])["fragment_batches_why_not"] == "smoothing"


SIMD = ["scalar", "sse2", "avx2", "avx512"][:softgl._core.testing.simd_level() + 1]


@pytest.mark.parametrize("simd", SIMD)
@pytest.mark.parametrize("shader", ["builtins", "discard"])
def test_every_simd_level_gives_the_reference_bytes(shader, simd):
    # The covered lanes move into a batch by AVX2 gathers or a scalar loop; interpolation and the
    # colour kernels at each level: the per-primitive reference at the best level either way.
    ref, _, _ = render(shader, "blend_depth", fragment_batches=False)
    image, _, plan = render(shader, "blend_depth", mixed=False, simd=simd)
    assert plan["simd"] == simd and plan["no_helper_lanes"]
    assert image.tobytes() == ref.tobytes()
