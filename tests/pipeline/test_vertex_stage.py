"""The vertex stage of instanced draws (pipeline/draw.cpp, vertex_fetch.cpp, glsl_stages.cpp): a
vertex job packs whole instances when an instance has fewer vertices than a job (1,024), a
per-instance attribute is read once per run of lanes of one instance and broadcast over it, and the
shader writes positions, point sizes and varyings straight into the batch's arrays.

Each vertex of each instance is drawn as a point on its own pixel (placed from gl_VertexID and
gl_InstanceID), coloured from a per-instance attribute (element instance / divisor, ES 3.0 §2.9.3),
a per-vertex attribute and gl_VertexID, so every lane's inputs and outputs are checked against the
formula, at 1, 2 and 3 threads and every SIMD level the CPU has.
"""
import numpy as np
import pytest

import softgl
from softgl._core import testing

SIZE = 64   # 4,096 pixels: one per (instance, vertex)

VS = """#version 300 es
uniform int uPerInstance;
in vec2 aRG;      // per instance (divisor)
in float aB;      // per vertex
out vec4 vColor;
void main() {
    int k = gl_InstanceID * uPerInstance + gl_VertexID;
    vec2 pixel = vec2(float(k % SIZE), float(k / SIZE)) + 0.5;
    vColor = vec4(aRG, aB, float(gl_VertexID % 256) / 255.0);
    gl_Position = vec4(pixel / HALF.0 - 1.0, 0.0, 1.0);
    WRITE_POINT
}"""

FS = """#version 300 es
precision highp float;
in vec4 vColor;
out vec4 fragColor;
void main() { fragColor = vColor; }"""


def draw_instances(per_instance, instances, divisor, threads, simd, write_point_size):
    source = (VS.replace("SIZE", str(SIZE)).replace("HALF", str(SIZE // 2))
              .replace("WRITE_POINT", "gl_PointSize = 1.0;" if write_point_size else ""))
    gl = softgl.Context(SIZE, SIZE, antialias=False, preserveDrawingBuffer=True, threads=threads)
    if simd is not None:
        testing.set_tuning(gl, simd=simd)
    prog = softgl.program(gl, source, FS)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "uPerInstance"), per_instance)
    gl.bindVertexArray(gl.createVertexArray())
    elements = (instances + divisor - 1) // divisor
    rg = (np.arange(2 * elements).reshape(-1, 2) * 7 % 256).astype(np.float32) / 255
    b = (np.arange(per_instance) * 13 % 256).astype(np.float32) / 255
    for name, data, size, div in (("aRG", rg, 2, divisor), ("aB", b, 1, 0)):
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        loc = gl.getAttribLocation(prog, name)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, size, gl.FLOAT, False, 0, 0)
        gl.vertexAttribDivisor(loc, div)
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArraysInstanced(gl.POINTS, 0, per_instance, instances)
    assert gl.getError() == gl.NO_ERROR
    return gl.readPixels(0, 0, SIZE, SIZE, gl.RGBA, gl.UNSIGNED_BYTE).reshape(SIZE * SIZE, 4)


def expected(per_instance, instances, divisor):
    out = np.zeros((SIZE * SIZE, 4), np.uint8)
    for i in range(instances):
        e = i // divisor
        v = np.arange(per_instance)
        k = i * per_instance + v
        out[k, 0] = (2 * e) * 7 % 256
        out[k, 1] = (2 * e + 1) * 7 % 256
        out[k, 2] = v * 13 % 256
        out[k, 3] = v % 256
    return out


# (vertices per instance, instances): many instances packed in a job with runs that do not
# divide 1,024; one vertex per instance (a run of one lane); an instance larger than a job
# (its runs cross jobs); instances that end mid-job.
@pytest.mark.parametrize("per_instance, instances", [(37, 100), (1, 4000), (1500, 2), (5, 819)])
@pytest.mark.parametrize("divisor", [1, 3])
def test_instanced_vertices_match_the_formula(per_instance, instances, divisor):
    want = expected(per_instance, instances, divisor)
    for threads in (1, 2, 3):
        got = draw_instances(per_instance, instances, divisor, threads, None, write_point_size=threads == 2)
        bad = np.flatnonzero((got != want).any(axis=1))
        assert bad.size == 0, f"{threads} threads: pixel {bad[0]} is {got[bad[0]]}, expected {want[bad[0]]}"


@pytest.mark.parametrize("simd", ["scalar", "sse2", "avx2", "avx512"])
def test_instanced_vertices_every_simd_level(simd):
    if ["scalar", "sse2", "avx2", "avx512"].index(simd) > testing.simd_level():
        pytest.skip(f"this CPU has no {simd}")
    want = expected(37, 100, 2)
    np.testing.assert_array_equal(draw_instances(37, 100, 2, 2, simd, write_point_size=False), want)
