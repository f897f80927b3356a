"""SOFTGL_smooth: alpha times the exact covered fraction of each pixel (GL 1.5 §3.12), and the
seed documents' area averaging with SRC_ALPHA_SATURATE front to back.

Expected areas come from exact rational clipping (tests/pipeline/area_reference.py)."""
from fractions import Fraction

import numpy as np
import pytest

import softgl
from area_reference import polygon_square_area

VS = "attribute vec2 p; void main() { gl_Position = vec4(p, 0.0, 1.0); }"
FS = "precision mediump float; uniform vec4 c; void main() { gl_FragColor = c; }"
W = H = 16


def setup(gl):
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
    return gl.getUniformLocation(prog, "c")


def draw_triangle(gl, color_loc, ndc, color):
    gl.bufferData(gl.ARRAY_BUFFER, np.array(ndc, np.float32).ravel(), gl.DYNAMIC_DRAW)
    gl.uniform4f(color_loc, *color)
    gl.drawArrays(gl.TRIANGLES, 0, 3)


def window_fixed(ndc):
    # The exact snapped window position (1/256 pixel), as setup computes it.
    return [(Fraction(round((x + 1) * W / 2 * 256), 256), Fraction(round((y + 1) * H / 2 * 256), 256)) for x, y in ndc]


def test_alpha_is_the_exact_covered_fraction():
    gl = softgl.Context(W, H, antialias=False)
    ext = gl.getExtension("SOFTGL_smooth")
    gl.enable(ext.POLYGON_SMOOTH)
    loc = setup(gl)
    tri = [(-0.83, -0.71), (0.91, -0.37), (-0.12, 0.88)]
    draw_triangle(gl, loc, tri, (1, 1, 1, 1))
    alpha = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)[..., 3].astype(int)
    poly = window_fixed(tri)
    partial = 0
    for y in range(H):
        for x in range(W):
            a = float(polygon_square_area(poly, x, y))
            assert abs(alpha[y, x] - np.floor(a * 255 + 0.5)) <= 1, (x, y, a)
            partial += 0 < a < 1
    assert partial > 20          # edge pixels really are partially covered


def test_abutting_polygons_with_alpha_saturate_leave_no_seam():
    # Front to back with blendFunc(SRC_ALPHA_SATURATE, ONE) and destination alpha: the second
    # triangle adds min(a2, 1 - a1) of coverage, so a shared edge sums to full coverage.
    gl = softgl.Context(W, H, antialias=False)
    ext = gl.getExtension("SOFTGL_smooth")
    gl.enable(ext.POLYGON_SMOOTH)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA_SATURATE, gl.ONE)
    loc = setup(gl)
    a, b, c, d = (-1, -1), (1, -1), (1, 1), (-1, 1)
    draw_triangle(gl, loc, [a, b, c], (1, 0.5, 0, 1))
    # The upper-left half in two triangles sharing a slanted edge from (-1, -1) to (0.37, 1).
    draw_triangle(gl, loc, [a, (0.37, 1), d], (1, 0.5, 0, 1))
    draw_triangle(gl, loc, [a, c, (0.37, 1)], (1, 0.5, 0, 1))
    img = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE).astype(int)
    assert (np.abs(img[..., 3] - 255) <= 1).all()          # every pixel fully covered in sum
    assert (np.abs(img[..., 0] - 255) <= 1).all() and (np.abs(img[..., 1] - 128) <= 1).all()


def test_overlapping_polygons_saturate_at_full_coverage():
    # Two identical triangles front to back: the second adds min(a, 1 - a) on edge pixels.
    gl = softgl.Context(W, H, antialias=False)
    ext = gl.getExtension("SOFTGL_smooth")
    gl.enable(ext.POLYGON_SMOOTH)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA_SATURATE, gl.ONE)
    loc = setup(gl)
    tri = [(-0.8, -0.6), (0.7, -0.9), (0.1, 0.8)]
    for _ in range(2):
        draw_triangle(gl, loc, tri, (1, 1, 1, 1))
    alpha = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)[..., 3].astype(int)
    poly = window_fixed(tri)
    for y in range(H):
        for x in range(W):
            f = float(polygon_square_area(poly, x, y))
            a1 = np.floor(f * 255 + 0.5) / 255
            want = a1 + min(f, 1 - a1)
            assert abs(alpha[y, x] - np.floor(min(want, 1) * 255 + 0.5)) <= 1


def test_smooth_is_ignored_with_multisampling_and_needs_the_extension(quiet):
    gl = softgl.Context(4, 4, samples=4)
    gl.enable(0x0B41)
    assert gl.getError() == gl.INVALID_ENUM
    ext = gl.getExtension("SOFTGL_smooth")
    gl.enable(ext.POLYGON_SMOOTH)
    gl.hint(ext.POLYGON_SMOOTH_HINT, gl.FASTEST)
    assert gl.getParameter(ext.POLYGON_SMOOTH_HINT) == gl.FASTEST and gl.getError() == 0
    loc = setup(gl)
    draw_triangle(gl, loc, [(-1, -1), (1, -1), (-1, 1)], (1, 1, 1, 1))
    alpha = gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE)[..., 3]
    assert alpha[0, 0] == 255                              # MSAA coverage, not area alpha


@pytest.mark.parametrize("hint", ["NICEST", "FASTEST"])
def test_hints(hint):
    gl = softgl.Context(W, H, antialias=False)
    ext = gl.getExtension("SOFTGL_smooth")
    gl.enable(ext.POLYGON_SMOOTH)
    gl.hint(ext.POLYGON_SMOOTH_HINT, getattr(gl, hint))
    loc = setup(gl)
    tri = [(-0.9, -0.9), (0.9, -0.5), (-0.3, 0.95)]
    draw_triangle(gl, loc, tri, (1, 1, 1, 1))
    alpha = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)[..., 3].astype(float) / 255
    exact = np.array([[float(polygon_square_area(window_fixed(tri), x, y)) for x in range(W)] for y in range(H)])
    # NICEST is exact; FASTEST (8x8 samples) is within its documented bound for 3 edges.
    bound = 1 / 255 + (0 if hint == "NICEST" else 3 * 15 / 64)
    assert np.abs(alpha - exact).max() <= bound + 1e-9
