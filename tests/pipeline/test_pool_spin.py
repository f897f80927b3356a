"""The thread pool's threads spin for a while after each call before they sleep (runtime/thread_pool.h,
Tuning::pool_spin_microseconds): a frame's consecutive draws find the workers awake. Spinning must
never change what is drawn, nor the order of draws and the calls between them.

The scene is a run of small opaque rectangles, one draw each, with a uniform colour that changes
between draws, a buffer update, a texture upload and a framebuffer switch in between, and
readPixels in the middle: the expected pixels are computed here by hand (rectangles on pixel
edges cover exactly their pixels; a colour c is stored as round(255 c), ES 3.0 §2.1.6.1), at
1, 2 and 3 threads, with spinning off, at its default and long.
"""
import numpy as np
import pytest

import softgl
from softgl import _core

W, H = 192, 128   # 3 x 2 tiles of 64 px

VS = """attribute vec2 aPos;
void main() { gl_Position = vec4(aPos, 0.0, 1.0); }
"""
FS = """precision mediump float;
uniform vec4 uColor;
uniform sampler2D uTex;
uniform float uUseTex;
void main() {
  vec4 t = texture2D(uTex, vec2(0.5, 0.5));
  gl_FragColor = mix(uColor, t, uUseTex);
}
"""


def _program(gl):
    prog = gl.createProgram()
    for kind, src in ((gl.VERTEX_SHADER, VS), (gl.FRAGMENT_SHADER, FS)):
        s = gl.createShader(kind)
        gl.shaderSource(s, src)
        gl.compileShader(s)
        assert gl.getShaderParameter(s, gl.COMPILE_STATUS), gl.getShaderInfoLog(s)
        gl.attachShader(prog, s)
    gl.linkProgram(prog)
    assert gl.getProgramParameter(prog, gl.LINK_STATUS), gl.getProgramInfoLog(prog)
    return prog


def _rect_vertices(x0, y0, x1, y1, w=W, h=H):
    """Two triangles covering pixels [x0, x1) x [y0, y1) exactly (edges on pixel boundaries)."""
    a, b = 2 * x0 / w - 1, 2 * x1 / w - 1
    c, d = 2 * y0 / h - 1, 2 * y1 / h - 1
    return np.array([a, c, b, c, b, d, a, c, b, d, a, d], np.float32)


def _rects(rng, n):
    out = []
    for _ in range(n):
        x0 = int(rng.integers(0, W - 8))
        y0 = int(rng.integers(0, H - 8))
        out.append((x0, y0, min(W, x0 + int(rng.integers(4, 90))), min(H, y0 + int(rng.integers(4, 70)))))
    return out


def _byte(c):
    return int(np.floor(c * 255 + 0.5))


def _run(threads, spin):
    """Returns every readPixels of the scene and the expected images, computed alongside."""
    gl = softgl.Context(W, H, threads=threads, antialias=False, depth=False)
    if spin is not None:
        _core.testing.set_tuning(gl, pool_spin_microseconds=spin)
    prog = _program(gl)
    gl.useProgram(prog)
    u_color, u_use = gl.getUniformLocation(prog, "uColor"), gl.getUniformLocation(prog, "uUseTex")
    gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 0)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, 12 * 4, gl.DYNAMIC_DRAW)
    loc = gl.getAttribLocation(prog, "aPos")
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    for p in (gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER):
        gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST)
    # A framebuffer object the run switches to and back from.
    fbo_tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, fbo_tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, W, H, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)
    for p in (gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER):
        gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST)
    fbo = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, fbo_tex, 0)
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.bindFramebuffer(gl.FRAMEBUFFER, None)
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.clearColor(0.0, 0.0, 0.0, 1.0)
    gl.clear(gl.COLOR_BUFFER_BIT)

    rng = np.random.default_rng(7)
    expected = {None: np.zeros((H, W, 4), np.uint8), fbo: np.zeros((H, W, 4), np.uint8)}
    expected[None][..., 3] = 255
    got, want = [], []
    target = None
    for k, (x0, y0, x1, y1) in enumerate(_rects(rng, 60)):
        if k % 17 == 16:   # switch between the canvas and the framebuffer object
            target = fbo if target is None else None
            gl.bindFramebuffer(gl.FRAMEBUFFER, target)
        textured = k % 7 == 3
        if textured:       # a texture upload right before the draw that reads it
            texel = rng.integers(0, 256, 4).astype(np.uint8)
            gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 1, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, texel.reshape(1, 1, 4))
            color = texel
        else:
            c = rng.integers(0, 256, 4) / 255.0
            gl.uniform4f(u_color, *c)
            color = np.array([_byte(v) for v in c], np.uint8)
        gl.uniform1f(u_use, 1.0 if textured else 0.0)
        gl.bufferSubData(gl.ARRAY_BUFFER, 0, _rect_vertices(x0, y0, x1, y1))
        gl.drawArrays(gl.TRIANGLES, 0, 6)
        expected[target][y0:y1, x0:x1] = color
        if k % 11 == 5:    # readPixels in the middle of the run
            got.append(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE))
            want.append(expected[target].copy())
    for t in (None, fbo):
        gl.bindFramebuffer(gl.FRAMEBUFFER, t)
        got.append(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE))
        want.append(expected[t].copy())
    assert gl.getError() == gl.NO_ERROR
    return got, want


@pytest.mark.parametrize("threads", [1, 2, 3])
@pytest.mark.parametrize("spin", [0, None, 5000])
def test_consecutive_small_draws_with_changes_between_them(threads, spin):
    got, want = _run(threads, spin)
    assert len(got) == len(want) > 3
    for i, (g, w) in enumerate(zip(got, want)):
        diff = np.argwhere(g != w)
        assert diff.size == 0, f"readPixels {i}: first differing (row, column, channel) {diff[0].tolist()}"


def test_pool_spin_is_a_tuning_field():
    gl = softgl.Context(8, 8, threads=2)
    assert _core.testing.tuning(gl)["pool_spin_microseconds"] == 100
    previous = _core.testing.set_tuning(gl, pool_spin_microseconds=0)
    assert previous["pool_spin_microseconds"] == 100
    assert _core.testing.tuning(gl)["pool_spin_microseconds"] == 0
    for bad in (-1, 1_000_001):
        with pytest.raises(ValueError):
            _core.testing.set_tuning(gl, pool_spin_microseconds=bad)
    assert _core.testing.tuning(gl)["pool_spin_microseconds"] == 0
