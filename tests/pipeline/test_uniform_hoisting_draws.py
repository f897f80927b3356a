"""Values of uniforms and constants only are computed once before the lanes and kept while the
uniforms they read keep their values (glsl/executor.cpp, the prologue): draws that change those
uniforms between them must see the new values, and the bytes must equal the per-lane reference
(Tuning hoist_uniform_values=False) at every SIMD level and thread count."""
import numpy as np
import pytest

import softgl

W, H = 67, 45
SIMD = ["scalar", "sse2", "avx2", "avx512"][:softgl._core.testing.simd_level() + 1]

VS = """#version 300 es
in vec2 aPos;
out vec3 vPos;
void main() { vPos = vec3(aPos.x, -0.7, aPos.y); gl_Position = vec4(aPos, 0.0, 1.0); }
"""
FS = """#version 300 es
precision highp float;
uniform vec3 uLightDir[3];
uniform vec3 uLightColor[3];
uniform float uCutoff;
uniform float uExponent;
in vec3 vPos;
out vec4 fragColor;
void main() {
  vec3 c = vec3(0.05);
  for (int i = 0; i < 3; i++) {
    float s = dot(normalize(vPos), normalize(uLightDir[i]));
    if (s > cos(uCutoff)) c += uLightColor[i] * (uExponent * 0.1) * pow(s, uExponent);
  }
  fragColor = vec4(c, 1.0);
}
"""
FLAT_FS = """#version 300 es
precision highp float;
uniform vec3 uDir;
out vec4 fragColor;
void main() { fragColor = vec4(normalize(uDir) * 0.5 + 0.5, 1.0) + vec4(0.0 * gl_FragCoord.x); }
"""
LIGHTS = [
    dict(uLightDir=[0.2, -1, 0.3, -0.6, -1, -0.2, 0.5, -0.7, -0.5], uLightColor=[1, 0.5, 0.2, 0.2, 0.9, 0.4, 0.3, 0.3, 1],
         uCutoff=0.6, uExponent=8.0),
    dict(uLightDir=[-0.2, -1, 0.3, -0.6, -1, -0.2, 0.5, -0.7, -0.5], uLightColor=[1, 0.5, 0.2, 0.2, 0.9, 0.4, 0.3, 0.3, 1],
         uCutoff=0.6, uExponent=8.0),
    dict(uLightDir=[-0.2, -1, 0.3, -0.6, -1, -0.2, 0.5, -0.7, -0.5], uLightColor=[0.1, 0.5, 0.2, 0.2, 0.9, 0.4, 0.3, 0.3, 1],
         uCutoff=0.9, uExponent=3.0),
]


def context(threads, **tuning):
    gl = softgl.Context(W, H, antialias=False, threads=threads, preserveDrawingBuffer=True)
    softgl._core.testing.set_tuning(gl, **tuning)
    return gl


def grid_buffer(gl, n=12):
    xs = np.linspace(-1, 1, n + 1)
    tris = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = (xs[i], xs[j]), (xs[i + 1], xs[j]), (xs[i + 1], xs[j + 1]), (xs[i], xs[j + 1])
            tris += [a, b, c, a, c, d]
    data = np.array(tris, np.float32)
    gl.bindVertexArray(gl.createVertexArray())
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
    return len(data)


def draw_lights(gl, lights_seq, blend=True):
    """One draw per entry of lights_seq (additive blending unless blend=False), returns the bytes after each."""
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    count = grid_buffer(gl)
    if blend:
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.ONE, gl.ONE)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    images = []
    for lights in lights_seq:
        for name in ("uLightDir", "uLightColor"):
            gl.uniform3fv(gl.getUniformLocation(prog, name), np.array(lights[name], np.float32))
        gl.uniform1f(gl.getUniformLocation(prog, "uCutoff"), lights["uCutoff"])
        gl.uniform1f(gl.getUniformLocation(prog, "uExponent"), lights["uExponent"])
        gl.drawArrays(gl.TRIANGLES, 0, count)
        images.append(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE).copy())
    return images


@pytest.mark.parametrize("simd", SIMD)
@pytest.mark.parametrize("threads", [1, 2])
def test_hoisted_draws_give_the_per_lane_bytes(simd, threads):
    seq = [LIGHTS[0], LIGHTS[1], LIGHTS[1], LIGHTS[2], LIGHTS[0]]
    hoisted = draw_lights(context(threads, simd=simd), seq)
    reference = draw_lights(context(1, simd="scalar", hoist_uniform_values=False), seq)
    for k, (h, r) in enumerate(zip(hoisted, reference)):
        np.testing.assert_array_equal(h, r, err_msg=f"draw {k}")
    assert len({im.tobytes() for im in hoisted}) == len(seq)   # every draw changed the image


def test_a_uniform_changed_between_draws_is_seen():
    # Opaque draws: after each, the image is that draw's alone, which a fresh context (a new
    # executor, nothing kept) gives as the reference.
    seq = [LIGHTS[0], LIGHTS[1], LIGHTS[2], LIGHTS[1]]
    after_others = draw_lights(context(1), seq, blend=False)
    for k, lights in enumerate(seq):
        np.testing.assert_array_equal(after_others[k], draw_lights(context(1), [lights], blend=False)[0], err_msg=f"draw {k}")


@pytest.mark.parametrize("simd", SIMD)
def test_normalized_uniform_matches_float64(simd):
    gl = context(1, simd=simd)
    prog = softgl.program(gl, VS, FLAT_FS)
    gl.useProgram(prog)
    count = grid_buffer(gl, 2)
    loc = gl.getUniformLocation(prog, "uDir")
    for d in ([1.0, 2.0, 2.0], [0.0, -3.0, 4.0], [-1e-3, 5e-4, 2e-3]):
        gl.uniform3f(loc, *d)
        gl.drawArrays(gl.TRIANGLES, 0, count)
        image = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)
        v = np.array(d, np.float64)
        expected = np.round((v / np.linalg.norm(v) * 0.5 + 0.5) * 255)
        assert np.abs(image[..., :3].astype(np.int32) - expected.astype(np.int32)).max() <= 1
        assert len(np.unique(image.reshape(-1, 4), axis=0)) == 1


SCALED_VS = """#version 300 es
uniform mat4 uM;
uniform float uS;
in vec2 aPos;
out vec3 vPos;
void main() {
  vec4 p = (uM * uS) * vec4(aPos, 0.0, 1.0);   // uM * uS: uniform only, in the prologue
  vPos = vec3(p.x, -0.7, p.y);
  gl_Position = p;
}
"""


def draw_in_order(gl, order):
    """Opaque draws with the same uniforms, in `order` ("tiny": a triangle of a few pixels in the
    lower left corner, 3 vertices and a quad or two of fragments, runs of a few lanes; "grid":
    the 864-vertex grid, runs of hundreds, which does not reach that corner); the bytes after each."""
    prog = softgl.program(gl, SCALED_VS, FS)
    gl.useProgram(prog)
    count = grid_buffer(gl)
    grid = gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_BUFFER_BINDING)
    tiny = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, tiny)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-1.6, -1.6, -1.45, -1.6, -1.6, -1.4], np.float32), gl.STATIC_DRAW)
    lights = LIGHTS[0]
    for name in ("uLightDir", "uLightColor"):
        gl.uniform3fv(gl.getUniformLocation(prog, name), np.array(lights[name], np.float32))
    gl.uniform1f(gl.getUniformLocation(prog, "uCutoff"), lights["uCutoff"])
    gl.uniform1f(gl.getUniformLocation(prog, "uExponent"), lights["uExponent"])
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uM"), False,
                        np.array([0.6, 0.1, 0, 0, -0.05, 0.55, 0, 0, 0, 0, 1, 0, 0.1, 0.1, 0, 1], np.float32))
    gl.uniform1f(gl.getUniformLocation(prog, "uS"), 0.93)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    images = []
    for kind in order:
        gl.bindBuffer(gl.ARRAY_BUFFER, tiny if kind == "tiny" else grid)
        gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
        gl.drawArrays(gl.TRIANGLES, 0, 3 if kind == "tiny" else count)
        images.append(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE).copy())
    return images


@pytest.mark.parametrize("simd", SIMD)
@pytest.mark.parametrize("threads", [1, 2])
def test_prologue_kept_from_a_small_run_serves_a_larger_one(simd, threads):
    # The prologue's values are copied to the lanes a run uses (glsl/executor.cpp run_prologue):
    # kept from the tiny draw's runs of a few lanes, they must reach every lane of the grid's
    # runs. The reference draws the grid first in a fresh context (its first runs are large);
    # the two draws do not overlap, so the order does not change the bytes.
    hoisted = draw_in_order(context(threads, simd=simd), ["tiny", "grid", "tiny", "grid"])
    reference = draw_in_order(context(threads, simd=simd), ["grid", "tiny"])[-1]
    tiny_only = draw_in_order(context(threads, simd=simd), ["tiny"])[0]
    grid_only = draw_in_order(context(threads, simd=simd), ["grid"])[0]
    assert 0 < np.count_nonzero(tiny_only[..., :3].any(axis=-1)) < 20   # a few pixels ...
    assert not (tiny_only[..., :3].any(axis=-1) & grid_only[..., :3].any(axis=-1)).any()   # ... apart from the grid's
    for k in (1, 2, 3):
        np.testing.assert_array_equal(hoisted[k], reference, err_msg=f"draw {k}")
