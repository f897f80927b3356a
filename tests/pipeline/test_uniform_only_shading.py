"""A fragment shader whose outputs depend only on uniforms runs once per draw (docs/architecture.md,
"Fast paths"; pipeline/tile_pass.cpp: its colour goes straight to the colour kernels). It must give
the same bytes and the same gl.stats() counters (but draws_constant_color) as a shader that
computes the same colour per fragment, and the colour the blend equation gives in float64. Tiny
draws run their tile pass on the caller: the bytes must not depend on the thread count."""
import numpy as np
import pytest

import softgl

SIZE = 72   # two tiles across: quads cross the 64-pixel tile border
VS = """#version 300 es
in vec4 aPos;
void main() { gl_Position = aPos; gl_PointSize = 5.0; }
"""
UNIFORM_FS = """#version 300 es
precision highp float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; }
"""
# The same colour, but reading gl_FragCoord: shaded per fragment (0.0 * x is +0.0, c + 0.0 == c).
PER_FRAGMENT_FS = """#version 300 es
precision highp float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor + vec4(0.0 * gl_FragCoord.x); }
"""
UNIFORM_DEPTH_FS = """#version 300 es
precision highp float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; gl_FragDepth = uColor.b; }
"""
PER_FRAGMENT_DEPTH_FS = """#version 300 es
precision highp float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor + vec4(0.0 * gl_FragCoord.x); gl_FragDepth = uColor.b + 0.0 * gl_FragCoord.y; }
"""
DISCARD_FS = """#version 300 es
precision highp float;
uniform vec4 uColor;
uniform float uDiscard;
out vec4 fragColor;
void main() { if (uDiscard > 0.5) discard; fragColor = uColor; }
"""
BACKGROUND = (51, 102, 153, 255)
COLORS = [(0.9, 0.3, 0.05, 0.4), (0.2, 0.7, 0.6, 0.75), (1.3, -0.2, 0.5, 0.3)]   # clamped to [0, 1]


def counters(gl):
    # draws_blend_table: uniform-only draws only (checked in test_blend_table.py).
    return {k: v for k, v in gl.stats().items() if not k.startswith("seconds") and k != "draws_blend_table"}


def render(fs, threads=1, samples=0, setup=None, z=(0.0, 0.0, 0.0), mode="TRIANGLES", extra=None):
    """Draws one shape per colour of COLORS (full-screen quad, a triangle, a point), returns
    (RGBA bytes, counters)."""
    kw = dict(antialias=samples > 0, threads=threads, preserveDrawingBuffer=True)
    if samples:
        kw["samples"] = samples
    gl = softgl.Context(SIZE, SIZE, **kw)
    # Whole quads through the shader (helper lanes too), as the constant colour counts them in
    # fragments_shaded: the two paths' counters compare.
    softgl._core.testing.set_tuning(gl, skip_helper_lanes=False)
    prog = softgl.program(gl, VS, fs)
    gl.useProgram(prog)
    gl.bindVertexArray(gl.createVertexArray())
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    quads = []
    for k in range(len(COLORS)):
        zk = z[k]
        quads += [[-1, -1, zk, 1], [1, -1, zk, 1], [1, 1, zk, 1], [-1, -1, zk, 1], [1, 1, zk, 1], [-1, 1, zk, 1]]
    tri = [[-0.9, -0.8, 0, 1], [0.95, -0.3, 0, 1], [-0.2, 0.9, 0, 1]]
    points = [[-0.3, 0.2, 0, 1], [0.77, -0.77, 0, 1], [0.0, 0.0, 0, 1]]
    data = np.array(quads + tri + points, np.float32)
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    gl.clearColor(*(c / 255 for c in BACKGROUND))
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    if setup:
        setup(gl)
    gl.stats(reset=True)
    loc = gl.getUniformLocation(prog, "uColor")
    if extra:
        extra(gl, prog)
    for k, color in enumerate(COLORS):
        gl.uniform4f(loc, *color)
        if mode == "TRIANGLES":
            gl.drawArrays(gl.TRIANGLES, 6 * k, 6)
        elif mode == "TRIANGLE":
            gl.drawArrays(gl.TRIANGLES, 6 * len(COLORS), 3)
        else:
            gl.drawArrays(gl.POINTS, 6 * len(COLORS) + 3 + k, 1)
    image = gl.readPixels(0, 0, SIZE, SIZE, gl.RGBA, gl.UNSIGNED_BYTE)
    return image, counters(gl)


def blend_layers_float64(func=("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA")):
    """The expected pixel: each layer blended in float64 (ES 3.0 §4.1.7, source clamped to [0, 1])
    and rounded to unorm8."""
    dst = np.array(BACKGROUND, np.float64) / 255
    for color in COLORS:
        src = np.clip(np.array(color, np.float64), 0, 1)
        if func == ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA"):
            out = src * src[3] + dst * (1 - src[3])
        else:   # ONE, ONE
            out = np.minimum(src + dst, 1)
        dst = np.round(np.clip(out, 0, 1) * 255) / 255
    return np.round(dst * 255).astype(int)


def alpha_blend(gl):
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)


def additive(gl):
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)


def constant_blend(gl):   # the generic kernel
    gl.enable(gl.BLEND)
    gl.blendColor(0.25, 0.5, 0.75, 0.5)
    gl.blendFunc(gl.CONSTANT_COLOR, gl.ONE_MINUS_SRC_ALPHA)


def red_green_only(gl):
    alpha_blend(gl)
    gl.colorMask(True, True, False, False)


def depth_less(gl):
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.LESS)
    alpha_blend(gl)


SETUPS = {"plain": None, "alpha_blend": alpha_blend, "additive": additive, "constant_blend": constant_blend,
          "color_mask": red_green_only, "depth_less": depth_less}


@pytest.mark.parametrize("threads", [1, 2])
def test_constant_colour_layers_match_the_float64_blend(threads):
    image, c = render(UNIFORM_FS, threads, setup=alpha_blend)
    expected = blend_layers_float64()
    assert np.abs(image.reshape(-1, 4).astype(int) - expected).max() <= 1
    assert c["samples_written"] == c["samples_blended"] == len(COLORS) * SIZE * SIZE
    image, _ = render(UNIFORM_FS, threads, setup=additive)
    assert np.abs(image.reshape(-1, 4).astype(int) - blend_layers_float64(("ONE", "ONE"))).max() <= 1


@pytest.mark.parametrize("samples", [0, 4])
@pytest.mark.parametrize("mode", ["TRIANGLES", "TRIANGLE", "POINTS"])
@pytest.mark.parametrize("setup", sorted(SETUPS))
def test_uniform_only_equals_per_fragment_shading(setup, mode, samples):
    z = (0.5, 0.7, 0.2) if setup == "depth_less" else (0.0, 0.0, 0.0)   # the second layer fails LESS
    args = dict(samples=samples, setup=SETUPS[setup], z=z, mode=mode)
    image, c = render(UNIFORM_FS, **args)
    reference, rc = render(PER_FRAGMENT_FS, **args)
    assert image.tobytes() == reference.tobytes()
    # Every uniform-only draw takes the constant colour to the colour kernels; no other does.
    assert c.pop("draws_constant_color") == c["draws"] and rc.pop("draws_constant_color") == 0
    # Hidden-surface removal's first pass asks more piling up of a cheap shader (tile_pass hides()).
    c.pop("tiles_hidden_surface"), rc.pop("tiles_hidden_surface")
    assert c == rc
    assert c["fragments_shaded"] > 0
    if setup == "depth_less" and mode == "TRIANGLES":
        assert c["fragments_killed_early"] > 0


@pytest.mark.parametrize("setup", ["plain", "depth_less"])
def test_uniform_gl_frag_depth_equals_per_fragment_shading(setup):
    # Depth written by the shader: the late depth test needs per-lane results (the general path).
    z = (0.0, 0.0, 0.0)
    image, c = render(UNIFORM_DEPTH_FS, setup=SETUPS[setup], z=z)
    reference, rc = render(PER_FRAGMENT_DEPTH_FS, setup=SETUPS[setup], z=z)
    assert image.tobytes() == reference.tobytes()
    # Without a depth test the written depth goes nowhere: the constant colour to the kernels.
    assert c.pop("draws_constant_color") == (c["draws"] if setup == "plain" else 0)
    assert rc.pop("draws_constant_color") == 0
    assert c == rc
    if setup == "depth_less":   # depths 0.05, 0.6, 0.5: the second and third layers fail LESS
        assert c["fragments_killed_late"] == 2 * SIZE * SIZE


@pytest.mark.parametrize("discard", [0.0, 1.0])
def test_uniform_discard_all_or_nothing(discard):
    def set_discard(gl, prog):
        gl.uniform1f(gl.getUniformLocation(prog, "uDiscard"), discard)
    image, c = render(DISCARD_FS, setup=alpha_blend, extra=set_discard)
    if discard:
        assert (image.reshape(-1, 4) == BACKGROUND).all()
        assert c["fragments_discarded"] == len(COLORS) * SIZE * SIZE
        assert c["samples_written"] == 0
    else:
        reference, rc = render(UNIFORM_FS, setup=alpha_blend)
        assert image.tobytes() == reference.tobytes()
        assert c["fragments_discarded"] == 0
        assert c["samples_written"] == rc["samples_written"]


def test_many_tiny_draws_are_the_same_for_every_thread_count():
    """Single-point draws (some across a tile border) run on the caller; bytes and counters must
    not depend on the thread count."""
    rng = np.random.default_rng(5)
    pos = np.column_stack([rng.uniform(-1, 1, (300, 2)), np.zeros(300), np.ones(300)]).astype(np.float32)
    results = []
    for threads in (1, 2, 3):
        gl = softgl.Context(SIZE, SIZE, threads=threads, preserveDrawingBuffer=True)
        prog = softgl.program(gl, VS, UNIFORM_FS)
        gl.useProgram(prog)
        gl.bindVertexArray(gl.createVertexArray())
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW)
        gl.enableVertexAttribArray(0)
        gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
        alpha_blend(gl)
        gl.stats(reset=True)
        loc = gl.getUniformLocation(prog, "uColor")
        for k in range(len(pos)):
            gl.uniform4f(loc, ((k * 37) % 101) / 100, 0.5, (k % 7) / 7, 0.6)
            gl.drawArrays(gl.POINTS, k, 1)
        results.append((gl.readPixels(0, 0, SIZE, SIZE, gl.RGBA, gl.UNSIGNED_BYTE).tobytes(), counters(gl)))
    assert all(r == results[0] for r in results)
    assert results[0][1]["tiles_touched"] > 300   # some points cross a tile border
