"""A multiple-render-target scene written once, run on softgl and (for the reference files) in
Chromium's WebGL: three RGBA8 colour attachments, two overlapping triangles with per-vertex
colours, the second blended with SRC_ALPHA / ONE_MINUS_SRC_ALPHA into every buffer.

WebGL 2 uses `layout(location = n) out` and drawBuffers; WebGL 1 uses WEBGL_draw_buffers with
gl_FragData[n]. Draw buffer 1 is NONE for the second triangle, so attachment 1 keeps only the
first. References: tests/textures/reference/mrt_webgl{1,2}.npz, regenerated with
`python tools/regen_mrt_references.py` (needs `apt-get install chromium`).
"""
from __future__ import annotations

import numpy as np

SIZE = 16
# x, y, r, g, b, a per vertex; vertex coordinates chosen off pixel centres (no fill-rule ties).
VERTICES = np.array([
    [-0.93, -0.87, 1.0, 0.2, 0.1, 1.0], [0.91, -0.71, 0.1, 0.9, 0.3, 1.0], [-0.31, 0.95, 0.2, 0.3, 1.0, 1.0],
    [-0.77, 0.41, 0.9, 0.9, 0.1, 0.6], [0.83, 0.89, 0.1, 0.8, 0.9, 0.3], [0.47, -0.93, 0.8, 0.1, 0.7, 0.9],
], np.float32)

VERTEX_3 = """#version 300 es
in vec2 pos;
in vec4 col;
out vec4 v;
void main() { v = col; gl_Position = vec4(pos, 0.0, 1.0); }
"""
FRAGMENT_3 = """#version 300 es
precision highp float;
in vec4 v;
layout(location = 0) out vec4 o0;
layout(location = 1) out vec4 o1;
layout(location = 2) out vec4 o2;
void main() {
    o0 = v;
    o1 = vec4(1.0 - v.rgb, v.a);
    o2 = vec4(gl_FragCoord.xy / 16.0, v.b, v.a);
}
"""
VERTEX_1 = """attribute vec2 pos;
attribute vec4 col;
varying vec4 v;
void main() { v = col; gl_Position = vec4(pos, 0.0, 1.0); }
"""
FRAGMENT_1 = """#extension GL_EXT_draw_buffers : require
precision highp float;
varying vec4 v;
void main() {
    gl_FragData[0] = v;
    gl_FragData[1] = vec4(1.0 - v.rgb, v.a);
    gl_FragData[2] = vec4(gl_FragCoord.xy / 16.0, v.b, v.a);
}
"""
CLEAR = [(0.1, 0.1, 0.1, 1.0), (0.0, 0.0, 0.5, 1.0), (0.5, 0.0, 0.0, 0.5)]


def mrt_scene(gl):
    """The scene on a softgl context (WebGL 1 or 2); returns the three attachments' bytes
    as a (3, SIZE, SIZE, 4) uint8 array, rows bottom-up."""
    import softgl
    v1 = gl.getParameter(gl.VERSION).startswith("WebGL 1")
    if v1:
        ext = gl.getExtension("WEBGL_draw_buffers")
        attach = [ext.COLOR_ATTACHMENT0_WEBGL + i for i in range(3)]
        draw_buffers = ext.drawBuffersWEBGL
        prog = softgl.program(gl, VERTEX_1, FRAGMENT_1)
    else:
        attach = [gl.COLOR_ATTACHMENT0 + i for i in range(3)]
        draw_buffers = gl.drawBuffers
        prog = softgl.program(gl, VERTEX_3, FRAGMENT_3)
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    textures = []
    for a in attach:
        t = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, t)
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, SIZE, SIZE, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, a, gl.TEXTURE_2D, t, 0)
        textures.append(t)
    # Clear each buffer to its own colour: one draw buffer at a time.
    for i, c in enumerate(CLEAR):
        draw_buffers([attach[k] if k == i else gl.NONE for k in range(3)])
        gl.clearColor(*c)
        gl.clear(gl.COLOR_BUFFER_BIT)
    gl.viewport(0, 0, SIZE, SIZE)
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, VERTICES, gl.STATIC_DRAW)
    pos, col = gl.getAttribLocation(prog, "pos"), gl.getAttribLocation(prog, "col")
    gl.enableVertexAttribArray(pos)
    gl.vertexAttribPointer(pos, 2, gl.FLOAT, False, 24, 0)
    gl.enableVertexAttribArray(col)
    gl.vertexAttribPointer(col, 4, gl.FLOAT, False, 24, 8)
    draw_buffers(attach)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    draw_buffers([attach[0], gl.NONE, attach[2]])
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    gl.drawArrays(gl.TRIANGLES, 3, 3)
    out = []
    read = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, read)
    for t in textures:
        gl.framebufferTexture2D(gl.FRAMEBUFFER, attach[0], gl.TEXTURE_2D, t, 0)
        out.append(gl.readPixels(0, 0, SIZE, SIZE, gl.RGBA, gl.UNSIGNED_BYTE))
    return np.stack(out)


SCENE_JS = r"""
function compile(gl, type, src) {
  const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}
function mrt(version) {
  const canvas = document.createElement('canvas');
  canvas.width = P.size; canvas.height = P.size;
  const gl = canvas.getContext(version == 1 ? 'webgl' : 'webgl2', {antialias: false, preserveDrawingBuffer: true});
  let attach, drawBuffers, vs, fs;
  if (version == 1) {
    const ext = gl.getExtension('WEBGL_draw_buffers');
    if (!ext) return {error: 'no WEBGL_draw_buffers'};
    attach = [0, 1, 2].map(i => ext.COLOR_ATTACHMENT0_WEBGL + i);
    drawBuffers = b => ext.drawBuffersWEBGL(b);
    vs = P.vertex1; fs = P.fragment1;
  } else {
    attach = [0, 1, 2].map(i => gl.COLOR_ATTACHMENT0 + i);
    drawBuffers = b => gl.drawBuffers(b);
    vs = P.vertex3; fs = P.fragment3;
  }
  const prog = gl.createProgram();
  gl.attachShader(prog, compile(gl, gl.VERTEX_SHADER, vs));
  gl.attachShader(prog, compile(gl, gl.FRAGMENT_SHADER, fs));
  gl.linkProgram(prog);
  gl.bindFramebuffer(gl.FRAMEBUFFER, gl.createFramebuffer());
  const textures = attach.map(a => {
    const t = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, P.size, P.size, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, a, gl.TEXTURE_2D, t, 0);
    return t;
  });
  P.clear.forEach((c, i) => {
    drawBuffers(attach.map((a, k) => k == i ? a : gl.NONE));
    gl.clearColor(c[0], c[1], c[2], c[3]);
    gl.clear(gl.COLOR_BUFFER_BIT);
  });
  gl.viewport(0, 0, P.size, P.size);
  gl.useProgram(prog);
  gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
  gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(P.vertices), gl.STATIC_DRAW);
  const pos = gl.getAttribLocation(prog, 'pos'), col = gl.getAttribLocation(prog, 'col');
  gl.enableVertexAttribArray(pos); gl.vertexAttribPointer(pos, 2, gl.FLOAT, false, 24, 0);
  gl.enableVertexAttribArray(col); gl.vertexAttribPointer(col, 4, gl.FLOAT, false, 24, 8);
  drawBuffers(attach);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  drawBuffers([attach[0], gl.NONE, attach[2]]);
  gl.enable(gl.BLEND);
  gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
  gl.drawArrays(gl.TRIANGLES, 3, 3);
  gl.bindFramebuffer(gl.FRAMEBUFFER, gl.createFramebuffer());
  const out = [];
  for (const t of textures) {
    gl.framebufferTexture2D(gl.FRAMEBUFFER, attach[0], gl.TEXTURE_2D, t, 0);
    const px = new Uint8Array(P.size * P.size * 4);
    gl.readPixels(0, 0, P.size, P.size, gl.RGBA, gl.UNSIGNED_BYTE, px);
    out.push(Array.from(px));
  }
  const err = gl.getError();
  gl.getExtension('WEBGL_lose_context').loseContext();
  return {error: err, buffers: out};
}
result = {webgl1: mrt(1), webgl2: mrt(2)};
"""


def js_params() -> dict:
    return {"size": SIZE, "vertices": VERTICES.ravel().tolist(), "clear": CLEAR,
            "vertex1": VERTEX_1, "fragment1": FRAGMENT_1, "vertex3": VERTEX_3, "fragment3": FRAGMENT_3}
