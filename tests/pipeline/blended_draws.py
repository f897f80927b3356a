"""The order-sensitive scene of the draw-structure tests (test_draw_chunks: chunks on the thread
pool; test_draw_batches: batches of primitives): blending and LEQUAL depth on, so a primitive
drawn out of order changes the bytes; a flat varying and gl_PointSize come from the vertices, so
a vertex mixed up changes them too; aOffset is per instance."""
import numpy as np

import softgl

VS = """#version 300 es
in vec4 aPos;
in vec4 aColor;
in vec2 aOffset;
out vec4 vColor;
flat out vec4 vFlat;
void main() {
    vColor = aColor;
    vFlat = aColor.bgra;
    gl_Position = aPos + vec4(aOffset * aPos.w, 0.0, 0.0);
    gl_PointSize = 1.0 + 5.0 * aColor.r;
}
"""
FS = """#version 300 es
precision highp float;
in vec4 vColor;
flat in vec4 vFlat;
out vec4 fragColor;
void main() { fragColor = vec4(vColor.rgb, 0.6) * 0.8 + vFlat * 0.2; }
"""


def counters(stats):
    return {k: v for k, v in stats.items() if not k.startswith("seconds")}


class BlendedDraws:
    """A size x size WebGL 2 context with the scene's program and state; pos (n, 4), color (n, 4)
    and offsets (instances, 2) as float attributes."""
    size = 48

    def __init__(self, threads, pos, color, offsets=None, samples=0):
        kw = dict(antialias=samples > 0, threads=threads, preserveDrawingBuffer=True)
        if samples:
            kw["samples"] = samples
        self.gl = gl = softgl.Context(self.size, self.size, **kw)
        prog = softgl.program(gl, VS, FS)
        gl.useProgram(prog)
        gl.bindVertexArray(gl.createVertexArray())
        for name, data, divisor in (("aPos", pos, 0), ("aColor", color, 0), ("aOffset", offsets, 1)):
            loc = gl.getAttribLocation(prog, name)
            if data is None:
                gl.vertexAttrib2f(loc, 0.0, 0.0)
                continue
            data = np.ascontiguousarray(data, np.float32)
            gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
            gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
            gl.enableVertexAttribArray(loc)
            gl.vertexAttribPointer(loc, data.shape[1], gl.FLOAT, False, 0, 0)
            gl.vertexAttribDivisor(loc, divisor)
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
        gl.enable(gl.DEPTH_TEST)
        gl.depthFunc(gl.LEQUAL)
        gl.clearColor(0.1, 0.2, 0.3, 1.0)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.stats(reset=True)

    def elements(self, indices, dtype=np.uint16):
        gl = self.gl
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.asarray(indices, dtype), gl.STATIC_DRAW)

    def result(self):
        """(the image's bytes, the gl.stats() counters without timings)."""
        gl = self.gl
        image = gl.readPixels(0, 0, self.size, self.size, gl.RGBA, gl.UNSIGNED_BYTE).tobytes()
        return image, counters(gl.stats())
