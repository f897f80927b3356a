"""Texture scenes written once, run on softgl and (to make reference images) in Chromium's WebGL.

Each scene is a JavaScript-compatible sequence of WebGL calls written in Python against `gl`;
`multitexture_js()` is the same scene as a JavaScript page body for tools/regen_texture_references.py.
"""
from __future__ import annotations

import numpy as np

# The course exercise (multitexturing, "one shader with changing textures"): three quads drawn
# with one program; the ground quad samples a checkerboard on unit 0, the two small quads sample
# a 1x1 red texture made from the bytes [255, 0, 0] on unit 1.
VERTEX = """
attribute vec4 vPosition;
attribute vec2 vTexCoord;
varying vec2 fTexCoord;
uniform mat4 projection;
void main() {
    fTexCoord = vTexCoord;
    gl_Position = projection * vPosition;
}
"""
FRAGMENT = """
precision mediump float;
varying vec2 fTexCoord;
uniform sampler2D texMap;
void main() {
    gl_FragColor = texture2D(texMap, fTexCoord);
}
"""
WIDTH = HEIGHT = 64
CHECKER_SIZE = 64      # texels per side
CHECKS = 8             # squares per side


def checkerboard() -> np.ndarray:
    """CHECKER_SIZE^2 RGBA bytes: black and white squares, CHECKS per side."""
    i, j = np.meshgrid(np.arange(CHECKER_SIZE), np.arange(CHECKER_SIZE), indexing="ij")
    white = ((i // (CHECKER_SIZE // CHECKS)) + (j // (CHECKER_SIZE // CHECKS))) % 2 == 0
    img = np.zeros((CHECKER_SIZE, CHECKER_SIZE, 4), np.uint8)
    img[white] = 255
    img[..., 3] = 255
    return img


def perspective(fovy_deg, aspect, near, far):
    f = 1.0 / np.tan(np.radians(fovy_deg) / 2)
    return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                     [0, 0, -1, 0]], np.float64)


# Positions (x, y, z, w) and texture coordinates of the three quads (two triangles each): a ground
# quad y = -1 with the checkerboard repeated, one quad parallel to it above, one perpendicular.
QUADS = np.array([
    # ground: x in [-4, 4], z in [-1, -9], the texture repeated 4 times; the coordinates are
    # offset by odd fractions so that no pixel centre lands exactly on a texel edge (where
    # NEAREST would depend on the last bit of the interpolation)
    [-4, -1, -1, 1, 0.0123, 0.0317], [4, -1, -1, 1, 4.0123, 0.0317], [4, -1, -9, 1, 4.0123, 4.0317],
    [-4, -1, -1, 1, 0.0123, 0.0317], [4, -1, -9, 1, 4.0123, 4.0317], [-4, -1, -9, 1, 0.0123, 4.0317],
    # small quad parallel to the ground
    [0.25, -0.5, -1.25, 1, 0, 0], [0.75, -0.5, -1.25, 1, 1, 0], [0.75, -0.5, -1.75, 1, 1, 1],
    [0.25, -0.5, -1.25, 1, 0, 0], [0.75, -0.5, -1.75, 1, 1, 1], [0.25, -0.5, -1.75, 1, 0, 1],
    # small quad perpendicular to the ground
    [-1, -1, -2.5, 1, 0, 0], [-1, 0, -2.5, 1, 1, 0], [-1, 0, -3, 1, 1, 1],
    [-1, -1, -2.5, 1, 0, 0], [-1, 0, -3, 1, 1, 1], [-1, -1, -3, 1, 0, 1],
], np.float32)


def multitexture_scene(gl, minify=None):
    """The exercise on a softgl context; returns the RGBA bytes (rows bottom-up)."""
    import softgl
    minify = gl.NEAREST if minify is None else minify
    prog = softgl.program(gl, VERTEX, FRAGMENT)
    gl.useProgram(prog)
    gl.clearColor(0.3921, 0.5843, 0.9294, 1.0)
    gl.enable(gl.DEPTH_TEST)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, QUADS, gl.STATIC_DRAW)
    pos = gl.getAttribLocation(prog, "vPosition")
    tex = gl.getAttribLocation(prog, "vTexCoord")
    gl.vertexAttribPointer(pos, 4, gl.FLOAT, False, 24, 0)
    gl.enableVertexAttribArray(pos)
    gl.vertexAttribPointer(tex, 2, gl.FLOAT, False, 24, 16)
    gl.enableVertexAttribArray(tex)
    proj = perspective(90, 1, 1, 25).T.astype(np.float32).ravel()
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "projection"), False, proj)

    gl.activeTexture(gl.TEXTURE0)
    t0 = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, t0)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, CHECKER_SIZE, CHECKER_SIZE, 0, gl.RGBA, gl.UNSIGNED_BYTE,
                  checkerboard())
    gl.generateMipmap(gl.TEXTURE_2D)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.REPEAT)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, minify)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST)

    gl.activeTexture(gl.TEXTURE1)
    t1 = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, t1)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, 1, 1, 0, gl.RGB, gl.UNSIGNED_BYTE, np.array([255, 0, 0], np.uint8))

    sampler = gl.getUniformLocation(prog, "texMap")
    gl.uniform1i(sampler, 0)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    gl.uniform1i(sampler, 1)
    gl.drawArrays(gl.TRIANGLES, 6, 12)
    return gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE)
