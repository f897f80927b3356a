"""Off-screen and instancing probe (issue 18): one scene drawn into the canvas or a framebuffer object,
timed per call, with the readback hash and the last draw plan. For A/B runs and callgrind.

usage: offscreen_probe.py WHAT TARGET W H REPS [DEPTH_FORMAT]   (GRID=n env: the mesh of `draw`)
  WHAT: clear | draw (textured mesh) | inst (10k instanced cubes) | noninst (the same, written out)
  TARGET: canvas | fbo (RGBA8 texture + depth renderbuffer) | fbotexdepth (+ depth texture)
"""
import sys, time, math
import numpy as np
import softgl
what, target, W, H, reps = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
dfmt = sys.argv[6] if len(sys.argv) > 6 else "DEPTH_COMPONENT24"
gl = softgl.Context(W, H, threads=1, antialias=False, preserveDrawingBuffer=True)
if target != "canvas":
    fb = gl.createFramebuffer(); gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    ct = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, ct)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, W, H, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, ct, 0)
    att = gl.DEPTH_STENCIL_ATTACHMENT if dfmt == "DEPTH24_STENCIL8" else gl.DEPTH_ATTACHMENT
    if target == "fbo":
        rb = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
        gl.renderbufferStorage(gl.RENDERBUFFER, getattr(gl, dfmt), W, H)
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, att, gl.RENDERBUFFER, rb)
    else:
        dt = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, dt)
        gl.texImage2D(gl.TEXTURE_2D, 0, getattr(gl, dfmt), W, H, 0, gl.DEPTH_COMPONENT,
                      gl.UNSIGNED_INT if dfmt != "DEPTH_COMPONENT32F" else gl.FLOAT, None)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, att, gl.TEXTURE_2D, dt, 0)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
gl.viewport(0, 0, W, H)
gl.clearColor(0.2, 0.3, 0.4, 1.0); gl.clearDepth(1.0)
gl.enable(gl.DEPTH_TEST)

def mesh(n):  # n x n grid of small triangles, z varying
    xs = np.linspace(-0.95, 0.95, n + 1)
    P = []; UV = []
    for j in range(n):
        for i in range(n):
            x0, x1, y0, y1 = xs[i], xs[i+1], xs[j], xs[j+1]
            z = 0.3 * math.sin(i * 0.3 + j * 0.2)
            for (x, y) in ((x0, y0), (x1, y0), (x1, y1), (x0, y0), (x1, y1), (x0, y1)):
                P += [x, y, z]; UV += [(x + 1) * 2, (y + 1) * 2]
    return np.array(P, np.float32), np.array(UV, np.float32)

if what == "draw":
    vs = """#version 300 es
in vec3 aPos; in vec2 aUV; out vec2 vUV;
void main(){ vUV = aUV; gl_Position = vec4(aPos, 1.0); }"""
    fs = """#version 300 es
precision mediump float; uniform sampler2D uTex; in vec2 vUV; out vec4 o;
void main(){ o = texture(uTex, vUV); }"""
    prog = softgl.program(gl, vs, fs); gl.useProgram(prog)
    P, UV = mesh(int(__import__("os").environ.get("GRID", "100")))
    for name, data, k in (("aPos", P, 3), ("aUV", UV, 2)):
        b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b); gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        loc = gl.getAttribLocation(prog, name); gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, k, gl.FLOAT, False, 0, 0)
    rng = np.random.default_rng(1)
    img = rng.integers(0, 256, (512, 512, 4), dtype=np.uint8)
    gl.activeTexture(gl.TEXTURE1)
    t = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, t)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 512, 512, 0, gl.RGBA, gl.UNSIGNED_BYTE, img)
    gl.generateMipmap(gl.TEXTURE_2D)
    gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 1)
    nverts = len(P) // 3
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, nverts)
    def step():
        gl.clear(gl.DEPTH_BUFFER_BIT)
        gl.drawArrays(gl.TRIANGLES, 0, nverts)
elif what in ("inst", "noninst"):
    vs = """#version 300 es
in vec3 aPos; in vec3 aOff; in vec4 aCol; out vec4 vCol;
uniform mat4 uMVP;
void main(){ vCol = aCol; gl_Position = uMVP * vec4(aPos * 0.01 + aOff, 1.0); }"""
    fs = """#version 300 es
precision mediump float; in vec4 vCol; out vec4 o; void main(){ o = vCol; }"""
    prog = softgl.program(gl, vs, fs); gl.useProgram(prog)
    # cube: 8 verts, 12 triangles
    cv = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], np.float32)
    ci = np.array([0,1,3,0,3,2, 4,6,7,4,7,5, 0,4,5,0,5,1, 2,3,7,2,7,6, 0,2,6,0,6,4, 1,5,7,1,7,3], np.uint16)
    N = 10000
    rng = np.random.default_rng(2)
    off = rng.uniform(-0.9, 0.9, (N, 3)).astype(np.float32)
    col = rng.uniform(0, 1, (N, 4)).astype(np.float32)
    mvp = np.eye(4, dtype=np.float32)
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uMVP"), False, mvp.ravel())
    def attr(name, data, k, div):
        b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b); gl.bufferData(gl.ARRAY_BUFFER, np.ascontiguousarray(data), gl.STATIC_DRAW)
        loc = gl.getAttribLocation(prog, name); gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, k, gl.FLOAT, False, 0, 0); gl.vertexAttribDivisor(loc, div)
    if what == "inst":
        attr("aPos", cv, 3, 0); attr("aOff", off, 3, 1); attr("aCol", col, 4, 1)
        eb = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, eb); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, ci, gl.STATIC_DRAW)
        def step():
            gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
            gl.drawElementsInstanced(gl.TRIANGLES, 36, gl.UNSIGNED_SHORT, 0, N)
    else:
        P = (cv[ci][None, :, :]).repeat(N, 0).reshape(-1, 3)
        O = off[:, None, :].repeat(36, 1).reshape(-1, 3); C = col[:, None, :].repeat(36, 1).reshape(-1, 4)
        attr("aPos", P, 3, 0); attr("aOff", O, 3, 0); attr("aCol", C, 4, 0)
        def step():
            gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
            gl.drawArrays(gl.TRIANGLES, 0, N * 36)
else:
    def step():
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
step()
ts = []
for _ in range(reps):
    t0 = time.perf_counter(); step(); ts.append(time.perf_counter() - t0)
px = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)
import hashlib
print(f"{what} {target} {W}x{H}: median {np.median(ts)*1e3:.2f} ms  hash {hashlib.sha1(px.tobytes()).hexdigest()[:12]}")
try: print(gl.last_draw_plan())
except Exception: pass
