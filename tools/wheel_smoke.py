"""Run by .ci/run in a clean venv holding only the softgl wheel and its dependencies: import it,
compile a shader, draw, and check the pixels by hand (no test-suite helpers, no source tree)."""
import sys
from pathlib import Path

import numpy as np

import softgl

assert "site-packages" in Path(softgl.__file__).parts, softgl.__file__
gl = softgl.Context(4, 4, antialias=False, strict=True)
vs = "attribute vec2 p; void main() { gl_Position = vec4(p, 0.0, 1.0); }"
fs = "precision mediump float; void main() { gl_FragColor = vec4(1.0, 0.5, 0.25, 1.0); }"
prog = softgl.program(gl, vs, fs, {"p": 0})
gl.useProgram(prog)
gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 1, -1, -1, 1, 1, 1], np.float32), gl.STATIC_DRAW)
gl.enableVertexAttribArray(0)
gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
img = gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE)
# 0.5 * 255 = 127.5 and 0.25 * 255 = 63.75 round to nearest: 128 and 64.
assert (img == np.array([255, 128, 64, 255], np.uint8)).all(), img[0, 0]
print(f"softgl {softgl.__version__} from {Path(softgl.__file__).parent}: wheel works", file=sys.stderr)
