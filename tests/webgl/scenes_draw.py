"""Drawing scenes, judged by real WebGL (see recorder.py): every primitive mode, every
per-fragment operation, the context attributes that change pixels, and draw-call validation.

Our own re-expression of what these conformance tests check (KhronosGroup/WebGL
sdk/tests/conformance/rendering/: triangle, culling, polygon-offset, point-size,
point-no-attributes, clipping-wide-points, line-loop-tri-fan, gl-viewport-test, blending,
draw-arrays-out-of-bounds, draw-elements-out-of-bounds; context/context-attributes-alpha-depth-
stencil-antialias) and dEQP's fragment-operation groups (es2fBlendTests, es2fDepthTests,
es2fDepthRangeTests, es2fStencilTests, es2fRasterizationTests culling), plus the course's seed
exercises that need no textures.

Each scene is `def name(gl, version)`, registered with its canvas size and context attributes.
Scenes only make calls; the values returned come back as `Ref`s that later calls may pass on.
Colors are chosen as k/255 where a test is about arithmetic (blending, masks), so that rounding
ties do not decide the bytes; geometry is aligned to pixel edges where a test is about fragment
operations, and deliberately not where it is about rasterization.
"""
from __future__ import annotations

import numpy as np

from recorder import Setup

SCENES = {}
PACKED = True     # reference images stored zlib-compressed (recorder.pack)


def scene(versions=(1, 2), width=64, height=64, **attributes):
    """Register a scene; attributes are WebGL context attributes added to the defaults."""
    def register(fn):
        attrs = dict(antialias=False, preserveDrawingBuffer=True) | attributes
        SCENES[fn.__name__] = (fn, tuple(versions), dict(width=width, height=height,
                                                           attributes=attrs))
        return fn
    return register


def scene_cases():
    """[(id, scene_fn, Setup)] for every scene and version: the test ids."""
    return [(f"{name}-v{v}", fn, Setup(version=v, **kw))
            for name, (fn, versions, kw) in SCENES.items() for v in versions]


def f32(values):
    return np.array(values, np.float32).ravel()


def b(*bytes_):
    """A color given as bytes, as the floats that convert back to exactly these bytes."""
    return tuple(v / 255 for v in bytes_)


# ---------------------------------------------------------------- shaders and helpers

VS_COLOR = """
attribute vec4 aPos;
attribute vec4 aColor;
uniform float uPointSize;
varying vec4 vColor;
void main() {
  gl_Position = aPos;
  gl_PointSize = uPointSize;
  vColor = aColor;
}"""

FS_COLOR = """
precision mediump float;
varying vec4 vColor;
void main() { gl_FragColor = vColor; }"""

VS_UNIFORM = """
attribute vec4 aPos;
uniform float uPointSize;
void main() {
  gl_Position = aPos;
  gl_PointSize = uPointSize;
}"""

FS_UNIFORM = """
precision mediump float;
uniform vec4 uColor;
void main() { gl_FragColor = uColor; }"""


def program(gl, vs, fs):
    """Compile and link, recording the status queries (both sides must agree that it links)."""
    shaders = []
    for kind, source in ((gl.VERTEX_SHADER, vs), (gl.FRAGMENT_SHADER, fs)):
        shader = gl.createShader(kind)
        gl.shaderSource(shader, source)
        gl.compileShader(shader)
        gl.getShaderParameter(shader, gl.COMPILE_STATUS)
        shaders.append(shader)
    prog = gl.createProgram()
    for shader in shaders:
        gl.attachShader(prog, shader)
    gl.linkProgram(prog)
    gl.getProgramParameter(prog, gl.LINK_STATUS)
    return prog


def attribute(gl, prog, name, data, size, type_=None, normalized=False, stride=0, offset=0):
    """A new buffer holding `data`, bound to attribute `name` of `prog`; returns the location."""
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
    loc = gl.getAttribLocation(prog, name)
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, size, type_ or gl.FLOAT, normalized, stride, offset)
    return loc


def read(gl, w=64, h=64):
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE)


class Painter:
    """Axis-aligned rectangles in pixel coordinates, one uniform color: fragment-op tests
    without rasterization ties (edges on pixel boundaries)."""

    def __init__(self, gl, w=64, h=64):
        self.gl, self.w, self.h = gl, w, h
        self.prog = program(gl, VS_UNIFORM, FS_UNIFORM)
        gl.useProgram(self.prog)
        self.buf = gl.createBuffer()
        gl.bindBuffer(gl.ARRAY_BUFFER, self.buf)
        self.loc = gl.getAttribLocation(self.prog, "aPos")
        gl.enableVertexAttribArray(self.loc)
        gl.vertexAttribPointer(self.loc, 3, gl.FLOAT, False, 0, 0)
        self.color = gl.getUniformLocation(self.prog, "uColor")

    def rect(self, x0, y0, x1, y1, color, z=0.0, cw=False, z1=None):
        """Pixels [x0, x1) x [y0, y1); z (NDC) at the left edge, z1 at the right (default z)."""
        gl = self.gl
        X0, X1 = 2 * x0 / self.w - 1, 2 * x1 / self.w - 1
        Y0, Y1 = 2 * y0 / self.h - 1, 2 * y1 / self.h - 1
        z1 = z if z1 is None else z1
        quad = [(X0, Y0, z), (X1, Y0, z1), (X1, Y1, z1), (X0, Y0, z), (X1, Y1, z1), (X0, Y1, z)]
        if cw:
            quad = quad[::-1]
        gl.useProgram(self.prog)
        gl.bindBuffer(gl.ARRAY_BUFFER, self.buf)
        gl.bufferData(gl.ARRAY_BUFFER, f32(quad), gl.STREAM_DRAW)
        gl.vertexAttribPointer(self.loc, 3, gl.FLOAT, False, 0, 0)
        gl.uniform4f(self.color, *color)
        gl.drawArrays(gl.TRIANGLES, 0, 6)

    def read_stencil(self):
        """Make the red channel equal the stencil value, bit by bit (EQUAL on one bit, additive
        blend of 2^b/255), then read: stencil results compared exactly through readPixels."""
        gl = self.gl
        gl.disable(gl.DEPTH_TEST)
        gl.disable(gl.SCISSOR_TEST)
        gl.colorMask(True, True, True, True)
        gl.clearColor(0, 0, 0, 1)
        gl.clear(gl.COLOR_BUFFER_BIT)
        gl.enable(gl.STENCIL_TEST)
        gl.stencilOp(gl.KEEP, gl.KEEP, gl.KEEP)
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.ONE, gl.ONE)
        gl.blendEquation(gl.FUNC_ADD)
        for bit in range(8):
            gl.stencilFunc(gl.EQUAL, 1 << bit, 1 << bit)
            self.rect(0, 0, self.w, self.h, ((1 << bit) / 255, 0, 0, 0))
        gl.disable(gl.BLEND)
        gl.disable(gl.STENCIL_TEST)
        read(gl, self.w, self.h)


def perspective(fovy_deg, aspect, near, far):
    f = 1 / np.tan(np.radians(fovy_deg) / 2)
    return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                     [0, 0, -1, 0]], np.float64)


def rotation(angle_deg, axis):
    x, y, z = np.asarray(axis, np.float64) / np.linalg.norm(axis)
    c, s = np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))
    r = np.array([[c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
                  [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
                  [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)]])
    m = np.eye(4)
    m[:3, :3] = r
    return m


def translation(x, y, z):
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def gl_matrix(m):
    """Column-major float32, as uniformMatrix4fv(transpose=false) wants."""
    return np.asarray(m, np.float32).T.ravel().copy()


BLEND_FACTORS = ["ZERO", "ONE", "SRC_COLOR", "ONE_MINUS_SRC_COLOR", "DST_COLOR",
                 "ONE_MINUS_DST_COLOR", "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "DST_ALPHA",
                 "ONE_MINUS_DST_ALPHA", "CONSTANT_COLOR", "ONE_MINUS_CONSTANT_COLOR",
                 "CONSTANT_ALPHA", "ONE_MINUS_CONSTANT_ALPHA", "SRC_ALPHA_SATURATE"]
DEPTH_FUNCS = ["NEVER", "LESS", "EQUAL", "LEQUAL", "GREATER", "NOTEQUAL", "GEQUAL", "ALWAYS"]
STENCIL_OPS = ["KEEP", "ZERO", "REPLACE", "INCR", "DECR", "INVERT", "INCR_WRAP", "DECR_WRAP"]
MIN_EXT, MAX_EXT = 0x8007, 0x8008     # EXT_blend_minmax, == WebGL 2's MIN / MAX

# `gl.expect(ROBUST).drawArrays(...)`: a draw that reads out of range. WebGL 1.0 §6.6 / WebGL 2.0
# §5.? make it INVALID_OPERATION, softgl follows that; Chromium uses robust buffer access instead
# (no error, out-of-range reads return zeros or values inside the buffer). The test accepts exactly
# that pair (softgl INVALID_OPERATION, Chromium NO_ERROR) on annotated calls, nothing else.
ROBUST = "chromium-robust-access"


# ================================================================ primitives: triangles

@scene()
def triangle_basic(gl, version):
    # conformance/rendering/triangle: one triangle, per-vertex colors interpolated
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-0.8, -0.9, 0, 1], [0.9, -0.6, 0, 1], [0.1, 0.85, 0, 1]]), 4)
    attribute(gl, prog, "aColor", f32([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1]]), 4)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    read(gl)


@scene()
def triangle_strip_and_fan(gl, version):
    # conformance/rendering/line-loop-tri-fan (fan part) and strips: vertex order per mode
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    ring = [[0.0, 0.0]] + [[0.9 * np.cos(a), 0.9 * np.sin(a)] for a in np.linspace(0, 5, 7)]
    pos = [[x * 0.5 - 0.45, y * 0.5 + 0.45, 0, 1] for x, y in ring]             # fan: top left
    strip = [[-0.95 + 0.25 * i, -0.9 + 0.5 * (i % 2) + 0.03 * i, 0, 1] for i in range(8)]
    rng = np.random.default_rng(4)
    colors = rng.integers(0, 256, (16, 4)) / 255
    colors[:, 3] = 1
    attribute(gl, prog, "aPos", f32(pos + strip), 4)
    attribute(gl, prog, "aColor", f32(colors), 4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLE_FAN, 0, 8)
    gl.drawArrays(gl.TRIANGLE_STRIP, 8, 8)
    read(gl)


@scene()
def triangles_fill_rule_additive(gl, version):
    # Shared edges and vertices on pixel centers and pixel corners: with ONE, ONE and a small
    # color, a pixel covered twice shows up as a doubled value (the tie rule decides).
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    # a 4x4 grid of quads in pixel units (center = +0.5), two triangles each, plus a fan of
    # 8 triangles around a pixel center and one around a pixel corner
    tris = []
    def px(x, y):
        return [2 * x / 64 - 1, 2 * y / 64 - 1, 0, 1]
    for i in range(4):
        for j in range(4):
            x0, y0 = 2 + 7 * i + 0.5 * (j % 2), 2 + 7 * j + 0.5 * (i % 2)
            a, b_, c, d = px(x0, y0), px(x0 + 6, y0), px(x0 + 6, y0 + 6), px(x0, y0 + 6)
            tris += [a, b_, c, a, c, d]
    for cx, cy in ((45.5, 45.5), (45, 18)):
        for k in range(8):
            a0, a1 = k * np.pi / 4, (k + 1) * np.pi / 4
            tris += [px(cx, cy), px(cx + 13 * np.cos(a0), cy + 13 * np.sin(a0)),
                     px(cx + 13 * np.cos(a1), cy + 13 * np.sin(a1))]
    # diagonal slivers through pixel centers
    tris += [px(2.5, 40.5), px(30.5, 62.5), px(2.5, 62.5), px(2.5, 40.5), px(30.5, 40.5),
             px(30.5, 62.5)]
    attribute(gl, prog, "aPos", f32(tris), 4)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), *b(60, 60, 60, 60))
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    gl.drawArrays(gl.TRIANGLES, 0, len(tris))
    read(gl)


@scene()
def triangles_random_mesh_additive(gl, version):
    # Watertightness: a triangulated grid with jittered (sub-pixel) vertices drawn additively;
    # every covered pixel must be hit exactly once (both implementations).
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    rng = np.random.default_rng(7)
    n = 7
    grid = np.stack(np.meshgrid(np.linspace(-0.9, 0.9, n), np.linspace(-0.9, 0.9, n)), -1)
    grid[1:-1, 1:-1] += rng.uniform(-0.1, 0.1, (n - 2, n - 2, 2))
    tris = []
    for i in range(n - 1):
        for j in range(n - 1):
            a, b_, c, d = grid[i, j], grid[i, j + 1], grid[i + 1, j + 1], grid[i + 1, j]
            tris += [a, b_, c, a, c, d] if (i + j) % 2 else [a, b_, d, b_, c, d]
    attribute(gl, prog, "aPos", f32(tris), 2)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), *b(40, 80, 120, 100))
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    gl.drawArrays(gl.TRIANGLES, 0, len(tris))
    read(gl)


# ================================================================ points

VS_POINTS = """
attribute vec4 aPos;
attribute float aSize;
attribute vec4 aColor;
varying vec4 vColor;
void main() {
  gl_Position = aPos;
  gl_PointSize = aSize;
  vColor = aColor;
}"""


@scene()
def points_sizes(gl, version):
    # conformance/rendering/point-size: sizes 1..13 at pixel centers and at pixel corners
    prog = program(gl, VS_POINTS, FS_COLOR)
    gl.useProgram(prog)
    pos, size, color = [], [], []
    for i, s in enumerate([1, 2, 3, 4, 5, 8, 13]):
        for row, off in enumerate((0.5, 0.0, 0.25)):   # center, corner, quarter
            x, y = 4 + 8.5 * i + off, 8 + 20 * row + off
            pos.append([2 * x / 64 - 1, 2 * y / 64 - 1, 0, 1])
            size.append(s)
            color.append([1, (i * 30) / 255, row / 2, 1])
    attribute(gl, prog, "aPos", f32(pos), 4)
    attribute(gl, prog, "aSize", f32(size), 1)
    attribute(gl, prog, "aColor", f32(color), 4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.POINTS, 0, len(pos))
    read(gl)


@scene()
def points_wide_clipped(gl, version):
    # conformance/rendering/clipping-wide-points: wide points whose center is near or beyond
    # the viewport edge; ES 3.0 §3.4 / WebGL: what is visible of a point inside the volume draws.
    prog = program(gl, VS_POINTS, FS_COLOR)
    gl.useProgram(prog)
    pos = [[-1, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 1], [0, -1, 0, 1],     # centers on the edges
           [-0.98, -0.98, 0, 1], [0.98, 0.98, 0, 1],                    # just inside corners
           [1.05, -0.5, 0, 1], [-0.5, 1.05, 0, 1]]                       # center just outside
    attribute(gl, prog, "aPos", f32(pos), 4)
    attribute(gl, prog, "aSize", f32([16, 16, 10, 10, 12, 12, 16, 16]), 1)
    colors = [[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1], [1, 1, 0, 1], [1, 0, 1, 1], [0, 1, 1, 1],
              [1, 1, 1, 1], [0.5, 0.5, 0.5, 1]]
    attribute(gl, prog, "aColor", f32(colors), 4)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.POINTS, 0, len(pos))
    read(gl)
    # the same points through a viewport in the middle: the point still draws outside it?
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.viewport(16, 16, 32, 32)
    gl.drawArrays(gl.POINTS, 0, 4)
    read(gl)


@scene()
def points_no_attributes(gl, version):
    # conformance/rendering/point-no-attributes: a vertex shader without any attribute
    prog = program(gl, "void main() { gl_Position = vec4(0.25, -0.25, 0.0, 1.0); gl_PointSize = 9.0; }",
                   "precision mediump float; void main() { gl_FragColor = vec4(0.0, 1.0, 0.0, 1.0); }")
    gl.useProgram(prog)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.POINTS, 0, 1)
    read(gl)


@scene()
def points_point_coord(gl, version):
    # gl_PointCoord across big points (ES: origin at the upper left)
    fs = """precision mediump float;
    void main() { gl_FragColor = vec4(gl_PointCoord, 0.5, 1.0); }"""
    prog = program(gl, VS_UNIFORM, fs)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-0.5, -0.5, 0, 1], [0.5, 0.5, 0, 1], [0.4, -0.45, 0, 1]]), 4)
    gl.uniform1f(gl.getUniformLocation(prog, "uPointSize"), 24)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.POINTS, 0, 3)
    read(gl)


@scene()
def points_depth_test_lesson(gl, version):
    # seed "depth testing with points": points at several depths, with and without depth test
    prog = program(gl, VS_POINTS, FS_COLOR)
    gl.useProgram(prog)
    rng = np.random.default_rng(11)
    n = 40
    pos = np.c_[rng.uniform(-0.9, 0.9, (n, 2)), rng.uniform(-0.9, 0.9, n), np.ones(n)]
    color = np.c_[rng.integers(0, 256, (n, 3)) / 255, np.ones(n)]
    attribute(gl, prog, "aPos", f32(pos), 4)
    attribute(gl, prog, "aSize", f32(rng.integers(4, 14, n)), 1)
    attribute(gl, prog, "aColor", f32(color), 4)
    gl.clearColor(0.1, 0.1, 0.1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.drawArrays(gl.POINTS, 0, n)
    read(gl)
    gl.enable(gl.DEPTH_TEST)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.drawArrays(gl.POINTS, 0, n)
    read(gl)
    gl.depthFunc(gl.GREATER)
    gl.clearDepth(0)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.drawArrays(gl.POINTS, 0, n)
    read(gl)


# ================================================================ lines

@scene()
def lines_star(gl, version):
    # conformance/rendering/line-rendering-quality: lines in every octant, 1 pixel wide
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    pos, color = [], []
    for k in range(24):
        a = k * 2 * np.pi / 24 + 0.07
        pos += [[0.03, 0.02, 0, 1], [0.03 + 0.9 * np.cos(a), 0.02 + 0.9 * np.sin(a), 0, 1]]
        color += [[1, k / 24, 0, 1]] * 2
    attribute(gl, prog, "aPos", f32(pos), 4)
    attribute(gl, prog, "aColor", f32(color), 4)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.lineWidth(1)
    gl.drawArrays(gl.LINES, 0, len(pos))
    read(gl)


@scene()
def lines_axis_aligned_and_diagonal(gl, version):
    # Lines whose endpoints sit on pixel centers: no ambiguity for horizontal/vertical/45° lines
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    def px(x, y):
        return [2 * x / 64 - 1, 2 * y / 64 - 1, 0, 1]
    pos = [px(4.5, 4.5), px(40.5, 4.5), px(4.5, 8.5), px(4.5, 40.5), px(10.5, 10.5), px(40.5, 40.5),
           px(60.5, 10.5), px(44.5, 26.5), px(50.5, 60.5), px(20.5, 60.5), px(60.5, 30.5),
           px(60.5, 58.5)]
    color = [[1, 0, 0, 1], [0, 1, 0, 1]] * 6
    attribute(gl, prog, "aPos", f32(pos), 4)
    attribute(gl, prog, "aColor", f32(color), 4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.LINES, 0, len(pos))
    read(gl)


@scene()
def line_strip_and_loop(gl, version):
    # conformance/rendering/line-loop-tri-fan (loop part): the closing segment of LINE_LOOP
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    pts = [[-0.8, -0.7], [0.7, -0.8], [0.8, 0.6], [-0.1, 0.9], [-0.75, 0.3]]
    attribute(gl, prog, "aPos", f32(pts), 2)
    color = gl.getUniformLocation(prog, "uColor")
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.uniform4f(color, 1, 1, 0, 1)
    gl.drawArrays(gl.LINE_LOOP, 0, 5)
    read(gl)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.uniform4f(color, 0, 1, 1, 1)
    gl.drawArrays(gl.LINE_STRIP, 0, 5)
    read(gl)


# ================================================================ indexed and instanced draws

@scene()
def draw_elements_index_types(gl, version):
    # UNSIGNED_BYTE and UNSIGNED_SHORT everywhere, UNSIGNED_INT in WebGL 2 or with
    # OES_element_index_uint; offsets into the index buffer
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    grid = [[x, y, 0, 1] for y in (-0.9, -0.3, 0.3, 0.9) for x in (-0.9, -0.3, 0.3, 0.9)]
    rng = np.random.default_rng(3)
    colors = np.c_[rng.integers(0, 256, (16, 3)) / 255, np.ones(16)]
    attribute(gl, prog, "aPos", f32(grid), 4)
    attribute(gl, prog, "aColor", f32(colors), 4)
    tri = [0, 1, 5, 0, 5, 4, 2, 3, 7, 2, 7, 6, 9, 10, 14, 9, 14, 13, 4, 5, 9]
    ibuf = gl.createBuffer()
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibuf)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array(tri, np.uint8), gl.STATIC_DRAW)
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_BYTE, 0)
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_BYTE, 6)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array(tri, np.uint16), gl.STATIC_DRAW)
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 18)
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 7)    # odd offset: INVALID_OPERATION
    if version == 1:
        gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_INT, 0)  # INVALID_ENUM before the extension
        gl.getExtension("OES_element_index_uint")
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array(tri, np.uint32), gl.STATIC_DRAW)
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_INT, 72)
    gl.drawElements(gl.LINE_STRIP, 4, gl.UNSIGNED_INT, 32)
    read(gl)


VS_INSTANCED = """
attribute vec2 aPos;
attribute vec2 aOffset;
attribute vec4 aColor;
varying vec4 vColor;
void main() {
  gl_Position = vec4(aPos + aOffset, 0.0, 1.0);
  vColor = aColor;
}"""


@scene()
def instanced_draws(gl, version):
    # vertexAttribDivisor: per-instance offsets (divisor 1) and colors (divisor 2)
    prog = program(gl, VS_INSTANCED, FS_COLOR)
    gl.useProgram(prog)
    ext = gl.getExtension("ANGLE_instanced_arrays") if version == 1 else None
    divisor = ext.vertexAttribDivisorANGLE if ext else gl.vertexAttribDivisor
    attribute(gl, prog, "aPos", f32([[-0.2, -0.2], [0.15, -0.2], [0, 0.17], [-0.2, 0.2]]), 2)
    offsets = attribute(gl, prog, "aOffset",
                        f32([[-0.7 + 0.45 * (i % 4), -0.7 + 0.45 * (i // 4)] for i in range(16)]), 2)
    colors = attribute(gl, prog, "aColor",
                       f32([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1], [1, 1, 1, 1]] * 2), 4)
    divisor(offsets, 1)
    divisor(colors, 2)
    ibuf = gl.createBuffer()
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibuf)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array([0, 1, 3, 1, 2, 3], np.uint16), gl.STATIC_DRAW)
    gl.clear(gl.COLOR_BUFFER_BIT)
    if ext:
        ext.drawArraysInstancedANGLE(gl.TRIANGLES, 0, 3, 8)
        ext.drawElementsInstancedANGLE(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 0, 4)   # colors reused
    else:
        gl.drawArraysInstanced(gl.TRIANGLES, 0, 3, 8)
        gl.drawElementsInstanced(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 0, 4)
    read(gl)


@scene(versions=(2,))
def webgl2_vertex_id_instance_id_flat(gl, version):
    # GLSL ES 3.00: gl_VertexID, gl_InstanceID, flat varyings (provoking vertex = last), integer
    # attributes through vertexAttribIPointer, drawRangeElements
    vs = """#version 300 es
    in ivec2 aCell;
    flat out vec4 vFlat;
    out vec4 vSmooth;
    void main() {
      float x = float(aCell.x + gl_InstanceID * 3) * 0.25 - 0.95;
      float y = float(aCell.y) * 0.5 - 0.9 + float(gl_VertexID % 3) * 0.01;
      gl_Position = vec4(x, y, 0.0, 1.0);
      vFlat = vec4(float(gl_VertexID) / 8.0, float(gl_InstanceID) / 2.0, 0.25, 1.0);
      vSmooth = vec4(0.0, float(gl_VertexID % 2), 1.0, 1.0);
    }"""
    fs = """#version 300 es
    precision mediump float;
    flat in vec4 vFlat;
    in vec4 vSmooth;
    out vec4 color;
    void main() { color = gl_FragCoord.y > 32.0 ? vFlat : vSmooth; }"""
    prog = program(gl, vs, fs)
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([0, 0, 2, 0, 0, 4, 2, 4, 0, 2, 2, 2], np.int16),
                  gl.STATIC_DRAW)
    loc = gl.getAttribLocation(prog, "aCell")
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribIPointer(loc, 2, gl.SHORT, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArraysInstanced(gl.TRIANGLE_STRIP, 0, 4, 3)
    ibuf = gl.createBuffer()
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibuf)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array([4, 5, 1], np.uint8), gl.STATIC_DRAW)
    gl.drawRangeElements(gl.TRIANGLES, 1, 5, 3, gl.UNSIGNED_BYTE, 0)
    read(gl)


@scene()
def vertex_array_objects(gl, version):
    # VAOs (WebGL 2 or OES_vertex_array_object) keep attribute state and the element buffer
    ext = gl.getExtension("OES_vertex_array_object") if version == 1 else None
    create = ext.createVertexArrayOES if ext else gl.createVertexArray
    bind = ext.bindVertexArrayOES if ext else gl.bindVertexArray
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    vaos = []
    for k in range(2):
        vao = create()
        bind(vao)
        s = 0.8 - 0.9 * k
        attribute(gl, prog, "aPos", f32([[-0.9, -0.9 + k, 0, 1], [s, -0.8 + k, 0, 1],
                                         [-0.2, 0.05 + k * 0.8, 0, 1]]), 4)
        attribute(gl, prog, "aColor", f32([[k, 1, 0, 1]] * 3), 4,
                  gl.FLOAT, False, 0, 0)
        ibuf = gl.createBuffer()
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibuf)
        gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array([2, 1, 0][::1 - 2 * k], np.uint16),
                      gl.STATIC_DRAW)
        vaos.append(vao)
    bind(None)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, 3)          # default VAO: no enabled arrays, draws nothing
    for vao in vaos:
        bind(vao)
        gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)
    read(gl)


@scene()
def attribute_formats(gl, version):
    # vertexAttribPointer types, normalized, stride and offset; constant attributes
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    pos = np.array([[-100, -100], [100, -100], [-100, 100], [100, 100]], np.int8)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    # interleaved: int8 position (normalized) + 2 pad bytes + uint8 RGBA color (normalized)
    inter = np.zeros((4, 8), np.uint8)
    inter[:, 0:2] = pos.view(np.uint8)
    inter[:, 4:8] = [[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255], [255, 255, 0, 128]]
    gl.bufferData(gl.ARRAY_BUFFER, inter.ravel(), gl.STATIC_DRAW)
    lp = gl.getAttribLocation(prog, "aPos")
    lc = gl.getAttribLocation(prog, "aColor")
    gl.enableVertexAttribArray(lp)
    gl.enableVertexAttribArray(lc)
    gl.vertexAttribPointer(lp, 2, gl.BYTE, True, 8, 0)
    gl.vertexAttribPointer(lc, 4, gl.UNSIGNED_BYTE, True, 8, 4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.viewport(0, 0, 32, 32)
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
    # shorts, not normalized, scaled to clip space by a w of 100
    sbuf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, sbuf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-90, -90, 0, 100, 90, -80, 0, 100, 0, 90, 0, 100],
                                            np.int16), gl.STATIC_DRAW)
    gl.vertexAttribPointer(lp, 4, gl.SHORT, False, 0, 0)
    gl.disableVertexAttribArray(lc)
    gl.vertexAttrib4f(lc, 0.2, 0.4, 0.6, 1.0)     # constant attribute
    gl.viewport(32, 0, 32, 32)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    # unsigned shorts normalized, 3 components (w defaults to 1)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([0, 0, 0, 65535, 0, 0, 0, 65535, 0], np.uint16),
                  gl.STATIC_DRAW)
    gl.vertexAttribPointer(lp, 3, gl.UNSIGNED_SHORT, True, 0, 0)
    gl.vertexAttrib3f(lc, 1.0, 0.5, 0.0)           # alpha defaults to 1
    gl.viewport(0, 32, 32, 32)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    gl.viewport(32, 32, 32, 32)
    gl.disableVertexAttribArray(lp)
    gl.vertexAttrib2f(lp, 0.0, 0.0)                # a point at the center from a constant
    gl.uniform1f(gl.getUniformLocation(prog, "uPointSize"), 6)
    gl.drawArrays(gl.POINTS, 0, 1)
    read(gl)


# ================================================================ interpolation

@scene()
def color_interpolation(gl, version):
    # per-vertex colors across a large triangle and a quad (rounding of interpolated colors)
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, -1, 0, 1], [1, -1, 0, 1], [-1, 1, 0, 1],
                                     [1, -1, 0, 1], [1, 1, 0, 1], [-1, 1, 0, 1]]), 4)
    attribute(gl, prog, "aColor", f32([[1, 0, 0, 1], [0, 1, 0, 0.5], [0, 0, 1, 0],
                                       [0, 1, 0, 0.5], [1, 1, 1, 1], [0, 0, 1, 0]]), 4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    read(gl)


VS_PERSPECTIVE = """
attribute vec3 aPos;
attribute vec2 aUV;
uniform mat4 uMVP;
varying vec2 vUV;
void main() {
  gl_Position = uMVP * vec4(aPos, 1.0);
  vUV = aUV;
}"""

FS_UV = """
precision highp float;
varying vec2 vUV;
void main() { gl_FragColor = vec4(vUV, 0.0, 1.0); }"""


@scene()
def perspective_correct_varyings(gl, version):
    # A plane receding in perspective: varyings perspective-correct (a linear ramp would not be)
    prog = program(gl, VS_PERSPECTIVE, FS_UV)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, 0, 1], [1, 0, 1], [1, 0, -6], [-1, 0, -6]]), 3)
    attribute(gl, prog, "aUV", f32([[0, 0], [1, 0], [1, 1], [0, 1]]), 2)
    mvp = perspective(60, 1, 0.5, 20) @ translation(0, -0.6, -1.5) @ rotation(10, (1, 0, 0))
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uMVP"), False, gl_matrix(mvp))
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLE_FAN, 0, 4)
    read(gl)


@scene()
def clipping_behind_eye(gl, version):
    # Vertices behind the eye (w < 0) and beyond far: homogeneous clipping, no wrap-around
    prog = program(gl, VS_PERSPECTIVE, FS_UV)
    gl.useProgram(prog)
    tri = [[-1.5, -0.5, 2.0], [1.5, -0.5, 2.0], [0.0, 0.5, -8.0],     # crosses the eye plane
           [-0.6, 0.8, -0.2], [0.6, 0.9, -0.2], [0.0, 0.3, 40.0],      # two vertices before near
           [-3, -0.9, -30], [3, -0.9, -30], [0, -0.2, -2.0]]            # beyond far
    attribute(gl, prog, "aPos", f32(tri), 3)
    attribute(gl, prog, "aUV", f32([[0, 0], [1, 0], [0.5, 1]] * 3), 2)
    mvp = perspective(70, 1, 0.5, 25)
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uMVP"), False, gl_matrix(mvp))
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, 9)
    read(gl)


@scene()
def clipping_huge_coordinates(gl, version):
    # Coordinates far outside the viewport (guard band / clipping) and w near zero
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    pos = [[-1e5, -1e5, 0, 1], [1e5, -0.5e5, 0, 1], [-0.4, 0.6, 0, 1],
           [0.5, 0.5, 0, 0.001], [0.9, -0.9, 0, 1], [0.9, 0.9, 0, 1]]
    attribute(gl, prog, "aPos", f32(pos), 4)
    attribute(gl, prog, "aColor", f32([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1],
                                       [1, 1, 0, 1], [0, 1, 1, 1], [1, 0, 1, 1]]), 4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    read(gl)


# ================================================================ blending

BG = b(64, 160, 224, 96)        # destination: framebuffer contents before blending
SRC = b(200, 100, 40, 150)      # source: fragment color
CONST = b(50, 130, 210, 180)    # blendColor


@scene(width=60, height=60)
def blend_every_factor_pair(gl, version):
    # conformance/rendering/blending, es2fBlendTests: all 15 x 15 (src, dst) factors, FUNC_ADD;
    # combinations WebGL rejects (constant color with constant alpha, SRC_ALPHA_SATURATE as
    # destination in WebGL 1) leave the previous function and record their error
    p = Painter(gl, 60, 60)
    gl.clearColor(*BG)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendColor(*CONST)
    for i, s in enumerate(BLEND_FACTORS):
        for j, d in enumerate(BLEND_FACTORS):
            gl.blendFunc(gl.ONE, gl.ZERO)
            gl.blendFunc(getattr(gl, s), getattr(gl, d))
            p.rect(4 * i, 4 * j, 4 * i + 4, 4 * j + 4, SRC)
    read(gl, 60, 60)


@scene(width=60, height=16)
def blend_factors_other_colors(gl, version):
    # every factor as src and as dst against ONE with other colors, incl. alpha 0 and 1
    p = Painter(gl, 60, 16)
    gl.enable(gl.BLEND)
    gl.blendColor(*b(255, 0, 90, 10))
    for row, (dst, src) in enumerate([(b(10, 250, 128, 0), b(255, 17, 99, 255)),
                                      (b(250, 3, 77, 255), b(0, 220, 190, 1))]):
        for i, f in enumerate(BLEND_FACTORS):
            gl.disable(gl.BLEND)
            p.rect(4 * i, 8 * row, 4 * i + 4, 8 * row + 8, dst)
            gl.enable(gl.BLEND)
            gl.blendFunc(getattr(gl, f), gl.ONE)
            p.rect(4 * i, 8 * row, 4 * i + 4, 8 * row + 4, src)
            if f != "SRC_ALPHA_SATURATE" or version == 2:
                gl.blendFunc(gl.ONE, getattr(gl, f))
                p.rect(4 * i, 8 * row + 4, 4 * i + 4, 8 * row + 8, src)
    read(gl, 60, 16)


@scene(width=40, height=24)
def blend_equations(gl, version):
    # the 5 equations (MIN/MAX: WebGL 2 or EXT_blend_minmax) with a few factor pairs; MIN/MAX
    # ignore the factors
    p = Painter(gl, 40, 24)
    if version == 1:
        gl.blendEquation(MIN_EXT)                  # INVALID_ENUM before the extension
        gl.getExtension("EXT_blend_minmax")
    eqs = ["FUNC_ADD", "FUNC_SUBTRACT", "FUNC_REVERSE_SUBTRACT"]
    eq_values = [getattr(gl, e) for e in eqs] + [MIN_EXT, MAX_EXT]
    pairs = [("ONE", "ONE"), ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA"), ("DST_COLOR", "SRC_COLOR")]
    gl.clearColor(*BG)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    for i, eq in enumerate(eq_values):
        gl.blendEquation(eq)
        for j, (s, d) in enumerate(pairs):
            gl.blendFunc(getattr(gl, s), getattr(gl, d))
            p.rect(8 * i, 8 * j, 8 * i + 8, 8 * j + 8, SRC)
    read(gl, 40, 24)


@scene(width=48, height=16)
def blend_separate(gl, version):
    # blendFuncSeparate and blendEquationSeparate: RGB and alpha independent
    p = Painter(gl, 48, 16)
    gl.clearColor(*BG)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendColor(*CONST)
    cases = [("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "ONE", "ZERO"),
             ("ONE", "ONE", "ZERO", "ONE"),
             ("DST_ALPHA", "ZERO", "ONE_MINUS_DST_ALPHA", "SRC_ALPHA"),
             ("CONSTANT_COLOR", "ONE_MINUS_SRC_COLOR", "CONSTANT_ALPHA", "ONE"),
             ("SRC_ALPHA_SATURATE", "ONE", "SRC_ALPHA_SATURATE", "ZERO"),
             ("ZERO", "SRC_COLOR", "DST_COLOR", "ONE_MINUS_CONSTANT_ALPHA")]
    eqs = [("FUNC_ADD", "FUNC_SUBTRACT"), ("FUNC_REVERSE_SUBTRACT", "FUNC_ADD")]
    for i, (sr, dr, sa, da) in enumerate(cases):
        for j, (er, ea) in enumerate(eqs):
            gl.blendEquationSeparate(getattr(gl, er), getattr(gl, ea))
            gl.blendFuncSeparate(getattr(gl, sr), getattr(gl, dr), getattr(gl, sa), getattr(gl, da))
            p.rect(8 * i, 8 * j, 8 * i + 8, 8 * j + 8, SRC)
    read(gl, 48, 16)


@scene(width=32, height=8)
def blend_color_clamping(gl, version):
    # blendColor outside [0, 1] is clamped for unorm targets (ES 3.0 §4.1.7); so are shader
    # outputs (source) before blending
    p = Painter(gl, 32, 8)
    gl.clearColor(*BG)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.CONSTANT_COLOR, gl.ONE_MINUS_CONSTANT_ALPHA)
    for i, c in enumerate([(2, -1, 0.5, 1.5), (-0.5, 0.25, 3, -2), (0.2, 0.4, 0.6, 0.8),
                           (1, 1, 1, 1)]):
        gl.blendColor(*c)
        gl.getParameter(gl.BLEND_COLOR)
        p.rect(8 * i, 0, 8 * i + 8, 4, SRC)
        p.rect(8 * i, 4, 8 * i + 8, 8, (1.5, -0.5, 0.3, 2.0))
    read(gl, 32, 8)


@scene(width=32, height=32)
def blend_chain(gl, version):
    # 50 layers of SRC_ALPHA / ONE_MINUS_SRC_ALPHA: the byte result after each rounding
    p = Painter(gl, 32, 32)
    gl.clearColor(0, 0, 0, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ONE, gl.ONE_MINUS_SRC_ALPHA)
    rng = np.random.default_rng(5)
    for k in range(50):
        x0, y0 = rng.integers(0, 24, 2)
        p.rect(int(x0), int(y0), int(x0) + 8 + k % 5, int(y0) + 8, b(*rng.integers(0, 256, 4)))
    read(gl, 32, 32)


# ================================================================ depth

@scene(width=64, height=64)
def depth_every_function(gl, version):
    # es2fDepthTests: 8 functions; in each band a ramp (z -0.9..0.9) is tested against a
    # flat quad at z=0.1 (upper half) and against the same ramp again (lower half: EQUAL holds
    # exactly because the same triangles give the same depth; ES 3.0 appendix A invariance only
    # promises that for the same geometry, so the lower half is drawn alone both times)
    p = Painter(gl)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.enable(gl.DEPTH_TEST)
    for i, f in enumerate(DEPTH_FUNCS):
        y = 8 * i
        gl.depthFunc(gl.ALWAYS)
        p.rect(0, y + 4, 64, y + 8, (0.5, 0, 0, 1), z=-0.9, z1=0.9)
        p.rect(0, y, 64, y + 4, (0.5, 0, 0, 1), z=-0.9, z1=0.9)
        gl.depthFunc(getattr(gl, f))
        p.rect(0, y + 4, 64, y + 8, (0, 1, 0, 1), z=0.1)
        p.rect(0, y, 64, y + 4, (0, 0, 1, 1), z=-0.9, z1=0.9)
    read(gl)


@scene(width=64, height=32)
def depth_mask_and_clear_value(gl, version):
    # depthMask(false) keeps the buffer; clearDepth; depth test disabled writes nothing
    p = Painter(gl, 64, 32)
    gl.clearDepth(0.6)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.enable(gl.DEPTH_TEST)
    gl.depthMask(False)
    p.rect(0, 0, 32, 32, (1, 0, 0, 1), z=-0.5)       # passes, but does not write
    gl.depthMask(True)
    p.rect(16, 0, 48, 32, (0, 1, 0, 1), z=0.1)       # passes against 0.6, writes 0.55
    gl.disable(gl.DEPTH_TEST)
    p.rect(0, 0, 64, 8, (0.2, 0.2, 0.2, 1), z=-0.9)  # no depth test: no depth write either
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.LESS)
    p.rect(0, 0, 64, 32, (0, 0, 1, 1), z=0.15)       # passes only where depth is still 0.6
    read(gl, 64, 32)


@scene(width=64, height=32)
def depth_range(gl, version):
    # es2fDepthRangeTests: depthRange maps NDC z to window z (incl. reversed ranges)
    p = Painter(gl, 64, 32)
    gl.enable(gl.DEPTH_TEST)
    for i, (n, f) in enumerate([(0, 1), (0.2, 0.6), (1, 0), (0.5, 0.5)]):
        gl.depthRange(0, 1)
        gl.clearDepth(0.45)
        gl.scissor(16 * i, 0, 16, 32)
        gl.enable(gl.SCISSOR_TEST)
        gl.clear(gl.DEPTH_BUFFER_BIT)
        gl.depthRange(n, f)
        gl.depthFunc(gl.LESS)
        p.rect(16 * i, 0, 16 * i + 16, 32, (1, 0.5, 0, 1), z=-0.95, z1=0.95)
        gl.getParameter(gl.DEPTH_RANGE)
    gl.depthRange(0.7, 0.1)
    read(gl, 64, 32)


@scene(width=64, height=32)
def depth_clip_near_far(gl, version):
    # z outside [-1, 1] is clipped (no depth clamp in WebGL)
    p = Painter(gl, 64, 32)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    p.rect(0, 0, 64, 16, (1, 0, 0, 1), z=-1.5, z1=1.5)
    p.rect(0, 16, 64, 32, (0, 1, 0, 1), z=-1.1, z1=1.02)
    read(gl, 64, 32)


@scene(width=64, height=32)
def polygon_offset(gl, version):
    # conformance/rendering/polygon-offset: coplanar quads resolved by units and by factor on a
    # sloped quad; the offset applies to triangles only (not to points or lines)
    p = Painter(gl, 64, 32)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.LESS)
    # flat: the second quad at the same depth fails LESS unless pulled forward by units
    for i, (factor, units) in enumerate([(0, 0), (0, -4), (0, 4), (-1, -1)]):
        p.rect(16 * i, 0, 16 * i + 16, 16, (0.3, 0.3, 0.3, 1), z=0.2)
        gl.enable(gl.POLYGON_OFFSET_FILL)
        gl.polygonOffset(factor, units)
        p.rect(16 * i, 0, 16 * i + 16, 16, (1, 0, 0, 1), z=0.2)
        gl.disable(gl.POLYGON_OFFSET_FILL)
    # sloped: dz/dx large, factor -2 pulls it forward, units alone (-2) does not suffice
    for i, (factor, units) in enumerate([(0, 0), (-2, 0), (0, -2), (2, 0)]):
        p.rect(16 * i, 16, 16 * i + 16, 32, (0.3, 0.3, 0.3, 1), z=-0.8, z1=0.8)
        gl.enable(gl.POLYGON_OFFSET_FILL)
        gl.polygonOffset(factor, units)
        p.rect(16 * i, 16, 16 * i + 16, 32, (0, 1, 0, 1), z=-0.8, z1=0.8)
        gl.disable(gl.POLYGON_OFFSET_FILL)
    read(gl, 64, 32)


@scene(width=64, height=64, depth=False)
def depth_test_without_depth_buffer(gl, version):
    # context attribute depth:false: DEPTH_TEST enabled but no buffer, so the test always passes
    p = Painter(gl)
    gl.getParameter(gl.DEPTH_BITS)
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.NEVER)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    p.rect(8, 8, 56, 56, (1, 0, 1, 1), z=0.5)
    read(gl)


# ================================================================ stencil

@scene(width=64, height=24, stencil=True)
def stencil_every_operation(gl, version):
    # es2fStencilTests: 8 ops as sfail / dpfail / dppass (rows), on stencil values 0, 0x80 and
    # 0xFF (sub-rows) with ref 0x5A; the stencil buffer is then read back exactly
    p = Painter(gl, 64, 24)
    gl.clearStencil(0)
    gl.clearDepth(0.5)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilFunc(gl.ALWAYS, 0x80, 0xFF)
    gl.stencilOp(gl.KEEP, gl.KEEP, gl.REPLACE)
    p.rect(0, 0, 64, 24, (0, 0, 0, 0))
    for row in range(3):                         # initial values per sub-row: 0x00, 0x80, 0xFF
        gl.stencilFunc(gl.ALWAYS, [0x00, 0x80, 0xFF][row], 0xFF)
        for kind in range(3):
            p.rect(0, 8 * kind + 2 * row + 2, 64, 8 * kind + 2 * row + 4, (0, 0, 0, 0))
    gl.enable(gl.DEPTH_TEST)
    gl.depthFunc(gl.LESS)
    for i, op in enumerate(STENCIL_OPS):
        o = getattr(gl, op)
        # sfail: the stencil test fails
        gl.stencilFunc(gl.NEVER, 0x5A, 0xFF)
        gl.stencilOp(o, gl.KEEP, gl.KEEP)
        p.rect(8 * i, 0, 8 * i + 8, 8, (0, 0, 0, 0), z=-0.5)
        # dpfail: stencil passes, depth fails (0.95 behind 0.5)
        gl.stencilFunc(gl.ALWAYS, 0x5A, 0xFF)
        gl.stencilOp(gl.KEEP, o, gl.KEEP)
        p.rect(8 * i, 8, 8 * i + 8, 16, (0, 0, 0, 0), z=0.9)
        # dppass
        gl.stencilOp(gl.KEEP, gl.KEEP, o)
        p.rect(8 * i, 16, 8 * i + 8, 24, (0, 0, 0, 0), z=-0.5)
    p.read_stencil()


@scene(width=64, height=64, stencil=True)
def stencil_every_function_and_masks(gl, version):
    # 8 functions (rows) against stencil values 0..63 (columns), ref 0x25 with value mask 0x3C;
    # then a write mask limits what REPLACE writes
    p = Painter(gl)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilOp(gl.KEEP, gl.KEEP, gl.REPLACE)
    for x in range(64):
        gl.stencilFunc(gl.ALWAYS, x, 0xFF)
        p.rect(x, 0, x + 1, 64, (0, 0, 0, 1))
    gl.stencilOp(gl.KEEP, gl.KEEP, gl.KEEP)
    for i, f in enumerate(DEPTH_FUNCS):           # stencil functions share the names
        gl.stencilFunc(getattr(gl, f), 0x25, 0x3C)
        p.rect(0, 8 * i, 64, 8 * i + 4, (1, 1 - i / 8, i / 8, 1))
        gl.stencilFunc(getattr(gl, f), 0x25, 0xFF)
        p.rect(0, 8 * i + 4, 64, 8 * i + 8, (0, 1 - i / 8, i / 8, 1))
    read(gl)
    gl.stencilMask(0xF0)
    gl.stencilFunc(gl.ALWAYS, 0xAB, 0xFF)
    gl.stencilOp(gl.KEEP, gl.KEEP, gl.REPLACE)
    p.rect(0, 32, 64, 64, (0, 0, 0, 1))
    gl.stencilMask(0xFF)
    gl.stencilOp(gl.KEEP, gl.KEEP, gl.INVERT)
    gl.stencilMask(0x0F)
    p.rect(32, 0, 64, 48, (0, 0, 0, 1))
    p.read_stencil()


@scene(width=64, height=32, stencil=True)
def stencil_separate_front_back(gl, version):
    # stencilFuncSeparate / stencilOpSeparate: front (CCW) and back (CW) faces use their own
    # function and operations. WebGL 1.0 §6.11: front and back ref, value mask and write mask
    # must agree at draw time, else the draw is INVALID_OPERATION.
    p = Painter(gl, 64, 32)
    gl.clearStencil(0x10)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilFuncSeparate(gl.FRONT, gl.ALWAYS, 0x33, 0xFF)
    gl.stencilFuncSeparate(gl.BACK, gl.ALWAYS, 0x44, 0xFF)
    p.rect(0, 0, 64, 32, (0, 0, 0, 1))                      # refs differ: INVALID_OPERATION
    gl.stencilFuncSeparate(gl.BACK, gl.ALWAYS, 0x33, 0xFF)
    gl.stencilMaskSeparate(gl.BACK, 0x0F)
    p.rect(0, 0, 64, 32, (0, 0, 0, 1))                      # write masks differ: same error
    gl.stencilMaskSeparate(gl.BACK, 0xFF)
    gl.stencilOpSeparate(gl.FRONT, gl.KEEP, gl.KEEP, gl.REPLACE)
    gl.stencilOpSeparate(gl.BACK, gl.KEEP, gl.KEEP, gl.INCR)
    for i in range(4):
        p.rect(16 * i, 0, 16 * i + 16, 16, (0, 0, 0, 1), cw=bool(i % 2))
        p.rect(16 * i + 4, 4, 16 * i + 12, 12, (0, 0, 0, 1), cw=i >= 2)
    gl.frontFace(gl.CW)                          # now CW triangles use the FRONT state
    gl.stencilFuncSeparate(gl.FRONT, gl.EQUAL, 0x10, 0xFF)
    gl.stencilFuncSeparate(gl.BACK, gl.NOTEQUAL, 0x10, 0xFF)
    gl.stencilOpSeparate(gl.FRONT, gl.KEEP, gl.KEEP, gl.DECR)
    gl.stencilOpSeparate(gl.BACK, gl.ZERO, gl.KEEP, gl.INVERT)
    for i in range(4):
        p.rect(16 * i, 16, 16 * i + 16, 32, (0, 0, 0, 1), cw=bool(i % 2))
        p.rect(16 * i + 2, 0, 16 * i + 6, 32, (0, 0, 0, 1), cw=i < 2)
    gl.frontFace(gl.CCW)
    p.read_stencil()


@scene(width=32, height=32)
def stencil_test_without_stencil_buffer(gl, version):
    # stencil:false (the default): STENCIL_TEST enabled, but no buffer, so it always passes
    p = Painter(gl, 32, 32)
    gl.getParameter(gl.STENCIL_BITS)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilFunc(gl.NEVER, 1, 0xFF)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
    p.rect(4, 4, 28, 28, (1, 1, 0, 1))
    read(gl, 32, 32)


# ================================================================ culling and facing

@scene(width=64, height=32)
def culling_every_setting(gl, version):
    # conformance/rendering/culling: frontFace CCW/CW (rows) x culling off, FRONT, BACK,
    # FRONT_AND_BACK (columns); each tile has one CCW (red) and one CW (green) triangle
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-0.9, -0.9], [0.1, -0.9], [-0.9, 0.8],      # CCW
                                     [0.9, 0.9], [0.9, -0.6], [-0.2, 0.9]]), 2)    # CW
    color = gl.getUniformLocation(prog, "uColor")
    gl.clear(gl.COLOR_BUFFER_BIT)
    for row, ff in enumerate(["CCW", "CW"]):
        gl.frontFace(getattr(gl, ff))
        for col, cull in enumerate([None, "FRONT", "BACK", "FRONT_AND_BACK"]):
            gl.viewport(16 * col, 16 * row, 16, 16)
            if cull is None:
                gl.disable(gl.CULL_FACE)
            else:
                gl.enable(gl.CULL_FACE)
                gl.cullFace(getattr(gl, cull))
            gl.uniform4f(color, 1, 0, 0, 1)
            gl.drawArrays(gl.TRIANGLES, 0, 3)
            gl.uniform4f(color, 0, 1, 0, 1)
            gl.drawArrays(gl.TRIANGLES, 3, 3)
    # culling never applies to points and lines
    gl.enable(gl.CULL_FACE)
    gl.cullFace(gl.FRONT_AND_BACK)
    gl.viewport(0, 0, 64, 32)
    gl.uniform4f(color, 1, 1, 1, 1)
    gl.uniform1f(gl.getUniformLocation(prog, "uPointSize"), 3)
    gl.drawArrays(gl.POINTS, 0, 6)
    gl.drawArrays(gl.LINE_LOOP, 0, 3)
    read(gl, 64, 32)


@scene(width=64, height=32)
def front_facing(gl, version):
    # gl_FrontFacing follows frontFace; a mirrored viewport does not exist in WebGL, but a
    # negative-w transform flips the winding in window space
    fs = """precision mediump float;
    void main() { gl_FragColor = gl_FrontFacing ? vec4(1.0, 0.5, 0.0, 1.0) : vec4(0.0, 0.5, 1.0, 1.0); }"""
    prog = program(gl, VS_UNIFORM, fs)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-0.9, -0.9, 0, 1], [-0.1, -0.9, 0, 1], [-0.5, 0.9, 0, 1],
                                     [0.1, -0.9, 0, 1], [0.5, 0.9, 0, 1], [0.9, -0.9, 0, 1],
                                     # CCW in clip space, but all w < 0: window winding flips
                                     [0.9, 0.9, 0, -1], [0.1, 0.9, 0, -1], [0.5, -0.9, 0, -1]]), 4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.viewport(0, 0, 32, 32)
    gl.drawArrays(gl.TRIANGLES, 0, 9)
    gl.frontFace(gl.CW)
    gl.viewport(32, 0, 32, 32)
    gl.drawArrays(gl.TRIANGLES, 0, 9)
    read(gl, 64, 32)


# ================================================================ scissor, masks, viewport

@scene()
def scissor_and_color_mask_draws(gl, version):
    # scissor clips draws (not only clears); colorMask per channel on draws
    p = Painter(gl)
    gl.clearColor(*b(20, 40, 60, 80))
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(5, 7, 30, 20)
    p.rect(0, 0, 64, 64, (1, 0, 0, 1))
    gl.scissor(40, 40, 100, 100)
    p.rect(0, 0, 64, 64, (0, 1, 0, 1))
    gl.scissor(-10, 50, 20, 4)
    p.rect(0, 0, 64, 64, (0, 0, 1, 1))
    gl.scissor(20, 20, 0, 10)                  # empty
    p.rect(0, 0, 64, 64, (1, 1, 1, 1))
    gl.disable(gl.SCISSOR_TEST)
    for i, mask in enumerate([(True, False, False, False), (False, True, False, True),
                              (False, False, True, False), (False, False, False, True),
                              (True, True, True, False), (False, False, False, False)]):
        gl.colorMask(*mask)
        p.rect(8 * i + 8, 30, 8 * i + 14, 38, b(255, 200, 150, 100))
    gl.colorMask(True, True, True, True)
    read(gl)


@scene()
def viewport_variants(gl, version):
    # conformance/rendering/gl-viewport-test: viewports partly off-canvas, larger than the
    # canvas, with odd sizes; a full-viewport quad and a triangle through each
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, -1, 0, 1], [1, -1, 0, 1], [-1, 1, 0, 1],
                                     [-0.5, -0.5, 0, 1], [0.5, -0.5, 0, 1], [0, 0.5, 0, 1]]), 4)
    attribute(gl, prog, "aColor", f32([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1]] * 2), 4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    for vp in [(-16, -16, 48, 48), (40, 40, 48, 40), (3, 45, 17, 13), (44, 2, 15, 33)]:
        gl.viewport(*vp)
        gl.drawArrays(gl.TRIANGLES, 0, 6)
    read(gl)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.viewport(-64, -64, 192, 192)
    gl.drawArrays(gl.TRIANGLES, 3, 3)
    read(gl)


# ================================================================ context attributes

@scene(width=32, height=32, alpha=False)
def context_alpha_false(gl, version):
    # alpha:false: alpha reads 255 and DST_ALPHA blends as 1 (WebGL 1.0 §2.2)
    p = Painter(gl, 32, 32)
    gl.clearColor(*b(10, 20, 30, 40))
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.DST_ALPHA, gl.ONE_MINUS_DST_ALPHA)
    p.rect(0, 0, 16, 32, SRC)
    gl.blendFunc(gl.ONE_MINUS_DST_ALPHA, gl.DST_ALPHA)
    p.rect(16, 0, 32, 16, SRC)
    gl.blendFunc(gl.SRC_ALPHA_SATURATE, gl.ONE)
    p.rect(16, 16, 32, 32, SRC)
    read(gl, 32, 32)


@scene(width=32, height=32, premultipliedAlpha=False)
def context_premultiplied_alpha_false(gl, version):
    # premultipliedAlpha:false only changes compositing: readPixels returns what was drawn,
    # even color values above alpha
    p = Painter(gl, 32, 32)
    gl.clearColor(*b(200, 100, 50, 20))
    gl.clear(gl.COLOR_BUFFER_BIT)
    p.rect(0, 0, 16, 16, b(255, 255, 255, 0))
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    p.rect(8, 8, 32, 32, b(250, 10, 130, 60))
    read(gl, 32, 32)


@scene(width=32, height=32, antialias=True)
def msaa_resolve(gl, version):
    # context-attributes antialias:true: 4 samples, resolved by readPixels (edge pixels mix)
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-0.83, -0.91, 0, 1], [0.93, -0.37, 0, 1], [-0.27, 0.88, 0, 1],
                                     [0.5, 0.5, 0.5, 1], [0.95, 0.6, 0.5, 1], [0.6, 0.97, 0.5, 1]]), 4)
    attribute(gl, prog, "aColor", f32([[1, 1, 1, 1]] * 3 + [[1, 0, 0, 1]] * 3), 4)
    gl.getParameter(gl.SAMPLES)
    gl.getParameter(gl.SAMPLE_BUFFERS)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    read(gl, 32, 32)


@scene(width=32, height=32, antialias=True)
def msaa_depth_and_points(gl, version):
    # per-sample depth: two interpenetrating triangles; MSAA points and lines
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-0.9, -0.9, -0.5, 1], [0.9, -0.8, 0.5, 1], [0, 0.9, 0.5, 1],
                                     [-0.9, 0.6, 0.5, 1], [0.9, 0.7, -0.5, 1], [0.1, -0.9, -0.5, 1]]), 4)
    attribute(gl, prog, "aColor", f32([[0, 1, 0, 1]] * 3 + [[0, 0, 1, 1]] * 3), 4)
    gl.enable(gl.DEPTH_TEST)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    gl.uniform1f(gl.getUniformLocation(prog, "uPointSize"), 5)
    gl.disable(gl.DEPTH_TEST)
    gl.drawArrays(gl.POINTS, 0, 6)
    read(gl, 32, 32)


# ================================================================ fragment shader built-ins

@scene()
def discard_and_frag_coord(gl, version):
    # discard by a gl_FragCoord pattern; gl_FragCoord.xy at pixel centers, .z window depth
    fs = """precision highp float;
    void main() {
      if (mod(floor(gl_FragCoord.x) + floor(gl_FragCoord.y / 2.0), 3.0) == 0.0) discard;
      gl_FragColor = vec4(gl_FragCoord.x / 64.0, gl_FragCoord.y / 64.0, gl_FragCoord.z, 1.0);
    }"""
    prog = program(gl, VS_COLOR, fs)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, -1, -0.8, 1], [1, -1, 0.2, 1], [-1, 1, 0.4, 1],
                                     [1, 1, 0.9, 1]]), 4)
    gl.enable(gl.DEPTH_TEST)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
    # a discarded fragment writes no depth: a second pass at z=0.95 fills exactly the holes
    fs2 = "precision mediump float; void main() { gl_FragColor = vec4(1.0, 0.0, 1.0, 1.0); }"
    prog2 = program(gl, VS_COLOR, fs2)
    gl.useProgram(prog2)
    attribute(gl, prog2, "aPos", f32([[-1, -1, 0.95, 1], [1, -1, 0.95, 1], [-1, 1, 0.95, 1],
                                      [1, 1, 0.95, 1]]), 4)
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
    read(gl)


FS_UNIFORMS_V1 = """
precision highp float;
precision highp int;
struct Light { vec3 color; float power; int kind; bool on; };
uniform float uF;
uniform vec2 uV2;
uniform vec3 uV3;
uniform vec4 uV4;
uniform int uI;
uniform ivec2 uI2;
uniform ivec3 uI3;
uniform ivec4 uI4;
uniform bool uB;
uniform bvec2 uB2;
uniform bvec3 uB3;
uniform bvec4 uB4;
uniform mat2 uM2;
uniform mat3 uM3;
uniform mat4 uM4;
uniform float uFA[3];
uniform vec4 uVA[2];
uniform Light uLight;
uniform Light uLights[2];
void main() {
  int band = int(gl_FragCoord.x / 4.0);
  vec4 c = vec4(0.0);
  if (band == 0) c = vec4(uF, uV2, 1.0);
  else if (band == 1) c = vec4(uV3, 1.0);
  else if (band == 2) c = uV4;
  else if (band == 3) c = vec4(float(uI) / 255.0, vec2(uI2) / 255.0, 1.0);
  else if (band == 4) c = vec4(vec3(uI3) / 255.0, 1.0);
  else if (band == 5) c = vec4(uI4) / 255.0;
  else if (band == 6) c = vec4(uB ? 1.0 : 0.0, vec2(uB2) * 0.5, 1.0);
  else if (band == 7) c = vec4(vec3(uB3) * 0.75, 1.0);
  else if (band == 8) c = vec4(uB4);
  else if (band == 9) c = vec4(uM2[0], uM2[1]);
  else if (band == 10) c = vec4(uM3 * vec3(0.25, 0.5, 0.125), 1.0);
  else if (band == 11) c = uM4 * vec4(0.5, 0.25, 0.125, 1.0);
  else if (band == 12) c = vec4(uFA[0], uFA[1], uFA[2], 1.0);
  else if (band == 13) c = uVA[0] * 0.5 + uVA[1] * 0.25;
  else if (band == 14) c = vec4(uLight.color * uLight.power, uLight.on ? float(uLight.kind) / 4.0 : 0.0);
  else c = vec4(uLights[1].color, uLights[0].power);
  gl_FragColor = c;
}"""


def set_uniforms_v1(gl, prog):
    u = lambda name: gl.getUniformLocation(prog, name)   # noqa: E731
    gl.uniform1f(u("uF"), 0.25)
    gl.uniform2fv(u("uV2"), f32([0.5, 0.75]))
    gl.uniform3f(u("uV3"), 0.125, 0.375, 0.625)
    gl.uniform4fv(u("uV4"), [0.875, 0.5, 0.25, 1.0])
    gl.uniform1i(u("uI"), 17)
    gl.uniform2i(u("uI2"), 34, 51)
    gl.uniform3iv(u("uI3"), np.array([68, 85, 102], np.int32))
    gl.uniform4i(u("uI4"), 119, 136, 153, 255)
    gl.uniform1i(u("uB"), 1)
    gl.uniform2f(u("uB2"), 0.0, 2.5)                       # bools from floats: nonzero is true
    gl.uniform3iv(u("uB3"), [1, 0, 1])
    gl.uniform4i(u("uB4"), 0, 1, 1, 1)
    gl.uniformMatrix2fv(u("uM2"), False, f32([0.1, 0.2, 0.3, 0.4]))
    gl.uniformMatrix3fv(u("uM3"), False, f32([1, 0, 0, 0.5, 1, 0, 0, 0, 2]))
    gl.uniformMatrix4fv(u("uM4"), False, gl_matrix(translation(0.25, 0.125, 0.0) @ np.diag([1, 0.5, 2, 1])))
    gl.uniform1fv(u("uFA"), f32([0.2, 0.4, 0.6]))
    gl.uniform1f(u("uFA[2]"), 0.8)                          # element by name
    gl.uniform4fv(u("uVA"), f32([1, 0, 0.5, 1, 0, 1, 1, 0]))
    gl.uniform3f(u("uLight.color"), 0.5, 0.25, 1.0)
    gl.uniform1f(u("uLight.power"), 0.5)
    gl.uniform1i(u("uLight.kind"), 3)
    gl.uniform1i(u("uLight.on"), 1)
    gl.uniform3f(u("uLights[1].color"), 0.3, 0.6, 0.9)
    gl.uniform1f(u("uLights[0].power"), 0.7)
    gl.uniform1f(u("uNotThere"), 1.0)                       # null location: silently ignored
    gl.uniform1i(u("uF"), 1)                                # wrong type: INVALID_OPERATION
    gl.uniform1f(u("uI"), 1.0)                              # wrong type: INVALID_OPERATION


@scene(width=64, height=4)
def uniforms_every_type(gl, version):
    prog = program(gl, VS_UNIFORM, FS_UNIFORMS_V1)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, -1], [1, -1], [-1, 1], [1, 1]]), 2)
    set_uniforms_v1(gl, prog)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
    read(gl, 64, 4)


@scene(versions=(2,), width=32, height=4)
def uniforms_webgl2_types(gl, version):
    # uint/uvec, non-square matrices, uniformMatrix transpose=true (allowed in WebGL 2)
    fs = """#version 300 es
    precision highp float;
    uniform uint uU;
    uniform uvec3 uU3;
    uniform mat2x3 uM23;
    uniform mat3x2 uM32;
    uniform mat4x3 uM43;
    uniform mat3 uT;
    out vec4 color;
    void main() {
      int band = int(gl_FragCoord.x / 4.0);
      if (band == 0) color = vec4(float(uU) / 255.0, vec3(uU3) / 255.0);
      else if (band == 1) color = vec4(uM23 * vec2(0.5, 0.25), 1.0);
      else if (band == 2) color = vec4(uM32 * vec3(0.5, 0.25, 0.125), 0.0, 1.0);
      else if (band == 3) color = vec4(uM43 * vec4(0.25, 0.5, 0.125, 1.0), 1.0);
      else if (band == 4) color = vec4(uT[0], 1.0);
      else color = vec4(uT[1], 1.0);
    }"""
    vs = """#version 300 es
    in vec2 aPos;
    void main() { gl_Position = vec4(aPos, 0.0, 1.0); }"""
    prog = program(gl, vs, fs)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, -1], [1, -1], [-1, 1], [1, 1]]), 2)
    u = lambda name: gl.getUniformLocation(prog, name)   # noqa: E731
    gl.uniform1ui(u("uU"), 200)
    gl.uniform3uiv(u("uU3"), np.array([10, 100, 255], np.uint32))
    gl.uniformMatrix2x3fv(u("uM23"), False, f32([0.1, 0.2, 0.3, 0.4, 0.5, 0.6]))
    gl.uniformMatrix3x2fv(u("uM32"), False, f32([0.2, 0.4, 0.6, 0.8, 1.0, 0.1]))
    gl.uniformMatrix4x3fv(u("uM43"), False, f32(np.arange(12) / 16))
    gl.uniformMatrix3fv(u("uT"), True, f32([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]))
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
    read(gl, 32, 4)


# ================================================================ seed exercises

VS_CUBE = """
attribute vec3 aVertexPosition;
attribute vec4 aVertexColor;
uniform mat4 uModelViewMatrix;
uniform mat4 uProjectionMatrix;
varying vec4 vColor;
void main() {
  gl_Position = uProjectionMatrix * uModelViewMatrix * vec4(aVertexPosition, 1.0);
  vColor = aVertexColor;
}"""


def cube_geometry():
    faces = [((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0)),
             ((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
             ((0, 1, 0), (1, 0, 0), (0, 0, -1)), ((0, -1, 0), (1, 0, 0), (0, 0, 1))]
    colors = [(1, 0, 0, 0.5), (0, 1, 0, 0.5), (0, 0, 1, 0.5), (1, 1, 0, 0.5), (1, 0, 1, 0.5),
              (0, 1, 1, 0.5)]
    pos, col, idx = [], [], []
    for (n, u, v), c in zip(faces, colors):
        base = len(pos)
        n, u, v = map(np.array, (n, u, v))
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            pos.append(n + su * u + sv * v)
            col.append(c)
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return f32(pos), f32(col), np.array(idx, np.uint16)


@scene()
def seed_blended_cube(gl, version):
    # seed "Colors, Depth Testing, and Alpha Blending": a cube with per-face colors of alpha 0.5,
    # blended SRC_ALPHA / ONE_MINUS_SRC_ALPHA; first with depth test (back faces hidden), then
    # without depth test and with back faces culled, then all faces (order dependent)
    prog = program(gl, VS_CUBE, FS_COLOR)
    gl.useProgram(prog)
    pos, col, idx = cube_geometry()
    attribute(gl, prog, "aVertexPosition", pos, 3)
    attribute(gl, prog, "aVertexColor", col, 4)
    ibuf = gl.createBuffer()
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibuf)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW)
    mv = translation(0, 0, -6) @ rotation(30, (1, 0, 0)) @ rotation(40, (0, 1, 0))
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uModelViewMatrix"), False, gl_matrix(mv))
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "uProjectionMatrix"), False,
                        gl_matrix(perspective(45, 1, 0.1, 100)))
    gl.clearColor(0.9, 0.9, 0.9, 1)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    for setup in ("depth", "cull", "all"):
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        if setup == "depth":
            gl.enable(gl.DEPTH_TEST)
            gl.depthFunc(gl.LEQUAL)
        else:
            gl.disable(gl.DEPTH_TEST)
        if setup == "cull":
            gl.enable(gl.CULL_FACE)
        else:
            gl.disable(gl.CULL_FACE)
        gl.drawElements(gl.TRIANGLES, 36, gl.UNSIGNED_SHORT, 0)
        read(gl)


SPOT_VS = """#version 300 es
const int numLights = 3;
uniform mat4 uModelViewMatrix;
uniform mat4 uNormalMatrix;
uniform mat4 uProjectionMatrix;
uniform vec3 uLightPositions[numLights];
uniform vec3 uLightDirections[numLights];
in vec3 aPos;
in vec3 aNormal;
out vec3 vRay[numLights];
out vec3 vTransformedNormals[numLights];
void main(void) {
  vec4 vertex = uModelViewMatrix * vec4(aPos, 1.0);
  vec3 normal = vec3(uNormalMatrix * vec4(aNormal, 1.0));
  for (int i = 0; i < numLights; i++) {
    vec4 lightPosition = uModelViewMatrix * vec4(uLightPositions[i], 1.0);
    vRay[i] = vertex.xyz - lightPosition.xyz;
    vec3 directionLight = vec3(uNormalMatrix * vec4(uLightDirections[i], 1.0));
    vTransformedNormals[i] = normal - directionLight;
  }
  gl_Position = uProjectionMatrix * vertex;
}"""

SPOT_FS = """#version 300 es
precision mediump float;
const int numLights = 3;
uniform vec4 uLightColors[numLights];
uniform vec4 uMaterialAmbient;
uniform vec4 uMaterialDiffuse;
uniform vec4 uLightAmbient;
uniform float uLightCutOff;
in vec3 vRay[numLights];
in vec3 vTransformedNormals[numLights];
out vec4 fragColor;
void main(void) {
  vec4 Ia = uLightAmbient * uMaterialAmbient;
  vec4 Id = vec4(0.0);
  for (int i = 0; i < numLights; i++) {
    vec3 N = normalize(vTransformedNormals[i]);
    vec3 L = normalize(vRay[i]);
    float lambertTerm = dot(N, -L);
    if (lambertTerm > uLightCutOff) {
      Id += uLightColors[i] * uMaterialDiffuse * pow(lambertTerm, 10.0 * uLightCutOff);
    }
  }
  fragColor = vec4(vec3(Ia + Id), 1.0);
}"""


@scene(versions=(2,), width=64, height=48)
def seed_three_spotlights(gl, version):
    # seed "Lights" (3 spotlights with a cut-off): a tessellated floor lit by three spot lights
    prog = program(gl, SPOT_VS, SPOT_FS)
    gl.useProgram(prog)
    n = 12
    xs = np.linspace(-10, 10, n + 1)
    pos, nor = [], []
    for i in range(n):
        for j in range(n):
            a, b_, c, d = ((xs[i], 0, xs[j]), (xs[i + 1], 0, xs[j]), (xs[i + 1], 0, xs[j + 1]),
                           (xs[i], 0, xs[j + 1]))
            pos += [a, c, b_, a, d, c]
            nor += [(0, 1, 0)] * 6
    attribute(gl, prog, "aPos", f32(pos), 3)
    attribute(gl, prog, "aNormal", f32(nor), 3)
    u = lambda name: gl.getUniformLocation(prog, name)   # noqa: E731
    mv = translation(0, -2, -22) @ rotation(35, (1, 0, 0))
    gl.uniformMatrix4fv(u("uModelViewMatrix"), False, gl_matrix(mv))
    gl.uniformMatrix4fv(u("uNormalMatrix"), False, gl_matrix(np.linalg.inv(mv).T))
    gl.uniformMatrix4fv(u("uProjectionMatrix"), False, gl_matrix(perspective(45, 64 / 48, 0.1, 100)))
    gl.uniform3fv(u("uLightPositions"), f32([[0, 7, 3], [2.5, 3, 3], [-2.5, 3, 3]]))
    gl.uniform3fv(u("uLightDirections"), f32([[0, 0, 0], [0, 0, 0], [0, 0, 0]]))
    gl.uniform4fv(u("uLightColors"), f32([[0, 1, 0, 1], [1, 0, 0, 1], [0, 0, 1, 1]]))
    gl.uniform4f(u("uMaterialAmbient"), 1, 1, 1, 1)
    gl.uniform4f(u("uMaterialDiffuse"), 1, 1, 1, 1)
    gl.uniform4f(u("uLightAmbient"), 0.1, 0.1, 0.1, 1)
    gl.uniform1f(u("uLightCutOff"), 0.6)
    gl.clearColor(0, 0, 0, 1)
    gl.enable(gl.DEPTH_TEST)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, len(pos))
    read(gl, 64, 48)


@scene()
def seed_lambert_sphere(gl, version):
    # seed "Lights" (Goraud/Lambert): a lit sphere with per-vertex lighting, indexed
    vs = """
    attribute vec3 aPos;
    attribute vec3 aNormal;
    uniform mat4 uMVP;
    uniform mat3 uNormalMatrix;
    uniform vec3 uLightDirection;
    uniform vec4 uLightDiffuse;
    uniform vec4 uMaterialDiffuse;
    varying vec4 vColor;
    void main() {
      vec3 N = normalize(uNormalMatrix * aNormal);
      vec3 L = normalize(uLightDirection);
      float lambertTerm = max(dot(N, -L), 0.0);
      vColor = uMaterialDiffuse * uLightDiffuse * lambertTerm;
      vColor.a = 1.0;
      gl_Position = uMVP * vec4(aPos, 1.0);
    }"""
    prog = program(gl, vs, FS_COLOR)
    gl.useProgram(prog)
    rings, segs = 10, 16
    pos, idx = [], []
    for i in range(rings + 1):
        th = np.pi * i / rings
        for j in range(segs + 1):
            ph = 2 * np.pi * j / segs
            pos.append((np.sin(th) * np.cos(ph), np.cos(th), np.sin(th) * np.sin(ph)))
    for i in range(rings):
        for j in range(segs):
            a, b_ = i * (segs + 1) + j, (i + 1) * (segs + 1) + j
            idx += [a, a + 1, b_, b_, a + 1, b_ + 1]
    attribute(gl, prog, "aPos", f32(pos), 3)
    attribute(gl, prog, "aNormal", f32(pos), 3)
    ibuf = gl.createBuffer()
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibuf)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array(idx, np.uint16), gl.STATIC_DRAW)
    u = lambda name: gl.getUniformLocation(prog, name)   # noqa: E731
    mv = translation(0, 0, -3.2) @ rotation(20, (1, 0.3, 0))
    gl.uniformMatrix4fv(u("uMVP"), False, gl_matrix(perspective(45, 1, 0.1, 10) @ mv))
    gl.uniformMatrix3fv(u("uNormalMatrix"), False, gl_matrix(np.linalg.inv(mv[:3, :3]).T))
    gl.uniform3f(u("uLightDirection"), 0.3, -1.0, -0.6)
    gl.uniform4f(u("uLightDiffuse"), 1, 0.9, 0.8, 1)
    gl.uniform4f(u("uMaterialDiffuse"), 0.5, 0.8, 0.1, 1)
    gl.enable(gl.DEPTH_TEST)
    gl.enable(gl.CULL_FACE)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.drawElements(gl.TRIANGLES, len(idx), gl.UNSIGNED_SHORT, 0)
    read(gl)


# ================================================================ draw validation (errors)

@scene(width=8, height=8)
def draw_errors_program_and_mode(gl, version):
    # no program; bad mode; negative first/count; count 0 (no error, draws nothing)
    gl.drawArrays(gl.TRIANGLES, 0, 3)                 # no program: INVALID_OPERATION
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, -1], [1, -1], [0, 1]]), 2)
    gl.drawArrays(0x0007, 0, 3)                       # QUADS: INVALID_ENUM
    gl.drawArrays(gl.TRIANGLES, -1, 3)                # INVALID_VALUE
    gl.drawArrays(gl.TRIANGLES, 0, -3)                # INVALID_VALUE
    gl.drawArrays(gl.TRIANGLES, 0, 0)                 # fine, nothing drawn
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)   # no element buffer
    gl.drawElements(gl.TRIANGLES, 3, gl.FLOAT, 0)     # INVALID_ENUM
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, -2)  # INVALID_VALUE
    gl.drawArrays(gl.TRIANGLES, 0, 3)                 # draws
    # a program that failed to link cannot be used; one deleted while in use still draws
    bad = program(gl, VS_UNIFORM, "precision mediump float; void main() { gl_FragColor = vec4(x); }")
    gl.useProgram(bad)                                 # INVALID_OPERATION, keeps `prog`
    gl.deleteProgram(prog)
    gl.drawArrays(gl.POINTS, 0, 3)
    read(gl, 8, 8)


@scene(width=8, height=8)
def draw_errors_attribute_out_of_range(gl, version):
    # conformance/rendering/draw-arrays-out-of-bounds: an enabled attribute whose buffer is too
    # short is INVALID_OPERATION in WebGL (even where the GPU would use robust access)
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, -1, 0, 1], [1, -1, 0, 1], [0, 1, 0, 1]]), 4)
    lc = attribute(gl, prog, "aColor", f32([[1, 0, 0, 1], [0, 1, 0, 1]]), 4)
    gl.expect(ROBUST).drawArrays(gl.TRIANGLES, 0, 3)         # color has 2 vertices
    gl.drawArrays(gl.TRIANGLES, 0, 2)                        # in range
    gl.expect(ROBUST).drawArrays(gl.TRIANGLES, 1, 2)
    gl.expect(ROBUST).drawArrays(gl.TRIANGLES, 2 ** 31 - 2, 3)   # overflow must not wrap
    gl.vertexAttribPointer(lc, 4, gl.FLOAT, False, 0, 16)   # offset past the first vertex
    gl.expect(ROBUST).drawArrays(gl.TRIANGLES, 0, 2)
    gl.vertexAttribPointer(lc, 3, gl.FLOAT, False, 20, 0)   # stride 20: 2 vertices fit in 32 B
    gl.drawArrays(gl.TRIANGLES, 0, 2)
    gl.expect(ROBUST).drawArrays(gl.TRIANGLES, 0, 3)
    gl.clear(gl.COLOR_BUFFER_BIT)                     # the robust draws above drew in Chromium
    gl.disableVertexAttribArray(lc)                   # a disabled attribute is not checked
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    # an enabled attribute with no buffer bound
    gl.bindBuffer(gl.ARRAY_BUFFER, None)
    gl.enableVertexAttribArray(lc)
    gl.vertexAttribPointer(lc, 4, gl.FLOAT, False, 0, 0)    # no buffer: INVALID_OPERATION (v2:
    gl.drawArrays(gl.TRIANGLES, 0, 3)                       # offset 0 allowed with null buffer)
    read(gl, 8, 8)


@scene(width=8, height=8)
def draw_errors_index_out_of_range(gl, version):
    # conformance/rendering/draw-elements-out-of-bounds: indices past the attribute data and
    # index ranges past the element buffer
    prog = program(gl, VS_COLOR, FS_COLOR)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, -1, 0, 1], [1, -1, 0, 1], [0, 1, 0, 1], [1, 1, 0, 1]]), 4)
    attribute(gl, prog, "aColor", f32([[1, 0, 0, 1]] * 4), 4)
    ibuf = gl.createBuffer()
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibuf)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array([0, 1, 2, 1, 3, 2, 0, 1, 9], np.uint16),
                  gl.STATIC_DRAW)
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 0)    # fine
    gl.expect(ROBUST).drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 12)  # index 9 >= 4
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 8)    # past the buffer's 18 bytes
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.bufferSubData(gl.ELEMENT_ARRAY_BUFFER, 16, np.array([3], np.uint16))
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 12)   # now in range
    gl.drawElements(gl.POINTS, 1, gl.UNSIGNED_BYTE, 17)       # byte index 0 (high byte of 3)
    read(gl, 8, 8)


@scene(width=8, height=8)
def draw_errors_instanced_out_of_range(gl, version):
    # an instanced attribute (divisor 1) needs one element per instance: 17 instances of a
    # 16-element attribute read out of range
    prog = program(gl, VS_INSTANCED, FS_COLOR)
    gl.useProgram(prog)
    ext = gl.getExtension("ANGLE_instanced_arrays") if version == 1 else None
    divisor = ext.vertexAttribDivisorANGLE if ext else gl.vertexAttribDivisor
    draw = ext.drawArraysInstancedANGLE if ext else gl.drawArraysInstanced
    attribute(gl, prog, "aPos", f32([[-1, -1], [1, -1], [0, 1]]), 2)
    offsets = attribute(gl, prog, "aOffset", f32(np.zeros((16, 2))), 2)
    colors = attribute(gl, prog, "aColor", f32([[1, 0, 0, 1]] * 8), 4)
    divisor(offsets, 1)
    divisor(colors, 2)
    draw(gl.TRIANGLES, 0, 3, 16)
    gl.expect(ROBUST)
    draw(gl.TRIANGLES, 0, 3, 17)
    gl.clear(gl.COLOR_BUFFER_BIT)
    divisor(colors, 0)              # per vertex now: 8 colors for 3 vertices, any instance count
    draw(gl.TRIANGLES, 0, 3, 16)
    read(gl, 8, 8)


# ================================================================ minimal repros of differences

@scene(width=8, height=8)
def draw_elements_count_zero_offset_past_end(gl, version):
    # conformance/rendering/draw-elements-out-of-bounds: "drawElements(TRIANGLES, 0,
    # UNSIGNED_BYTE, 4)" on a 3-byte element buffer is NO_ERROR (nothing is read)
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, -1], [1, -1], [0, 1]]), 2)
    ibuf = gl.createBuffer()
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibuf)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array([0, 1, 2], np.uint8), gl.STATIC_DRAW)
    gl.drawElements(gl.TRIANGLES, 0, gl.UNSIGNED_BYTE, 4)


def grid16(rng, n, lo=2, hi=62):
    """n window positions on the 1/16-pixel grid: SwiftShader snaps to 4 sub-pixel bits
    (SUBPIXEL_BITS 4), softgl to 8; on this grid both see the same vertices, so what remains
    is the rasterization rule itself."""
    return rng.integers(lo * 16, hi * 16, (n, 2)) / 16


def to_clip(points, w=64, h=64):
    return [[2 * x / w - 1, 2 * y / h - 1, 0, 1] for x, y in points]


@scene()
def raster_rules_grid16_triangles(gl, version):
    # random triangles (both windings) with vertices on the 1/16 grid, added with ONE, ONE:
    # coverage and the tie rule (top-left) decide every byte
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    rng = np.random.default_rng(21)
    pts = grid16(rng, 3 * 40)
    # and triangles whose edges pass exactly through pixel centers (vertices at centers)
    centers = rng.integers(2, 62, (3 * 10, 2)) + 0.5
    attribute(gl, prog, "aPos", f32(to_clip(list(pts) + list(centers))), 4)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), *b(20, 20, 20, 20))
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    gl.drawArrays(gl.TRIANGLES, 0, 120)
    read(gl)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 120, 30)
    read(gl)


@scene()
def raster_rules_grid16_lines(gl, version):
    # random lines with endpoints on the 1/16 grid: the diamond-exit rule without snapping noise
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    rng = np.random.default_rng(22)
    attribute(gl, prog, "aPos", f32(to_clip(grid16(rng, 2 * 30))), 4)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), *b(40, 40, 40, 40))
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    gl.drawArrays(gl.LINES, 0, 60)
    read(gl)


@scene()
def raster_rules_grid16_points(gl, version):
    # points of sizes 1..8 with centers on the 1/16 grid (edges on pixel centers included)
    prog = program(gl, VS_POINTS, FS_COLOR)
    gl.useProgram(prog)
    rng = np.random.default_rng(23)
    n = 40
    attribute(gl, prog, "aPos", f32(to_clip(grid16(rng, n, 6, 58))), 4)
    attribute(gl, prog, "aSize", f32(rng.integers(1, 9, n)), 1)
    attribute(gl, prog, "aColor", f32([b(30, 30, 30, 30)] * n), 4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    gl.drawArrays(gl.POINTS, 0, n)
    read(gl)


def diagonal_lines(gl, segs, w, h):
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32(to_clip([p for s_ in segs for p in s_], w, h)), 4)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), 1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.LINES, 0, 2 * len(segs))
    read(gl, w, h)


# ES 3.0 §3.5.1 diamond-exit: a segment from pixel center A to pixel center B lights A (it exits
# A's diamond) but not B (it ends inside B's diamond), whatever the direction.

@scene(width=48, height=16)
def line_direction_on_pixel_centers(gl, version):
    # horizontal, vertical and the main diagonal, both ways: both implementations agree
    diagonal_lines(gl, [((2.5, 2.5), (10.5, 2.5)), ((10.5, 5.5), (2.5, 5.5)),
                        ((14.5, 2.5), (14.5, 12.5)), ((16.5, 12.5), (16.5, 2.5)),
                        ((20.5, 2.5), (28.5, 10.5)), ((28.5, 12.5), (20.5, 4.5))], 48, 16)


@scene(width=16, height=16)
def line_anti_diagonal_up_left(gl, version):
    # (12.5, 2.5) -> (4.5, 10.5): direction (-1, +1) at 45 degrees; diamond-exit lights
    # (12, 2) and not (4, 10)
    diagonal_lines(gl, [((12.5, 2.5), (4.5, 10.5))], 16, 16)


@scene(width=16, height=16)
def line_anti_diagonal_down_right(gl, version):
    # (4.5, 12.5) -> (12.5, 4.5): direction (+1, -1); diamond-exit lights (4, 12), not (12, 4)
    diagonal_lines(gl, [((4.5, 12.5), (12.5, 4.5))], 16, 16)


@scene(width=32, height=32, antialias=True)
def msaa_grid16_triangles(gl, version):
    # 4x MSAA with vertices on the 1/16 grid: the sample pattern and per-sample coverage
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    rng = np.random.default_rng(24)
    attribute(gl, prog, "aPos", f32(to_clip(grid16(rng, 3 * 12, 1, 31), 32, 32)), 4)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), *b(64, 64, 64, 64))
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    gl.drawArrays(gl.TRIANGLES, 0, 36)
    read(gl, 32, 32)


@scene(width=32, height=32)
def subpixel_precision_triangle(gl, version):
    # One triangle from triangle_strip_and_fan; pixel (14, 33) of the 64x64 canvas (here
    # (14, 1) after shifting by 32 rows): its center is 0.022 px outside the edge with 8
    # sub-pixel bits (softgl) but inside with the 4 bits SwiftShader snaps to
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    tri = [(17.6, 46.4 - 32), (10.1219, 34.0916 - 32), (21.6806, 32.5903 - 32)]
    attribute(gl, prog, "aPos", f32(to_clip(tri, 32, 32)), 4)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), 1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    read(gl, 32, 32)


@scene(width=32, height=32)
def wide_point_outside_viewport(gl, version):
    # A 16-pixel point at the left edge of an 8..24 viewport: its fragments left of x=8 are
    # outside the viewport but inside the canvas
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.useProgram(prog)
    attribute(gl, prog, "aPos", f32([[-1, 0, 0, 1]]), 4)
    gl.uniform1f(gl.getUniformLocation(prog, "uPointSize"), 16)
    gl.uniform4f(gl.getUniformLocation(prog, "uColor"), 1, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.viewport(8, 8, 16, 16)
    gl.drawArrays(gl.POINTS, 0, 1)
    read(gl, 32, 32)


@scene(width=8, height=8)
def current_program_query(gl, version):
    # getParameter(CURRENT_PROGRAM) is the program useProgram installed (and stays so after a
    # failed useProgram of an unlinked program)
    prog = program(gl, VS_UNIFORM, FS_UNIFORM)
    gl.getParameter(gl.CURRENT_PROGRAM)
    gl.useProgram(prog)
    gl.getParameter(gl.CURRENT_PROGRAM)
    bad = gl.createProgram()
    gl.linkProgram(bad)
    gl.useProgram(bad)
    gl.getParameter(gl.CURRENT_PROGRAM)
