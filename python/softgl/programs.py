"""Building programs from GLSL sources in one call, and the stock shaders of the course."""
from __future__ import annotations

from .errors import GLError


class ShaderError(GLError):
    """A shader failed to compile or a program failed to link; the message is the info log."""

    def __init__(self, what: str, log: str):
        Exception.__init__(self, f"{what}:\n{log}")
        self.log = log


def program(gl, vertex_source: str, fragment_source: str, attribute_locations: dict | None = None):
    """Compile both shaders, link them (binding `attribute_locations` first) and return the
    WebGLProgram. Raises ShaderError with the info log on failure; leaves no GL error pending."""
    shaders = []
    for kind, source in ((gl.VERTEX_SHADER, vertex_source), (gl.FRAGMENT_SHADER, fragment_source)):
        shader = gl.createShader(kind)
        gl.shaderSource(shader, source)
        gl.compileShader(shader)
        if not gl.getShaderParameter(shader, gl.COMPILE_STATUS):
            log = gl.getShaderInfoLog(shader)
            gl.deleteShader(shader)
            for s in shaders:
                gl.deleteShader(s)
            raise ShaderError("vertex shader" if kind == gl.VERTEX_SHADER else "fragment shader", log)
        shaders.append(shader)
    prog = gl.createProgram()
    for shader in shaders:
        gl.attachShader(prog, shader)
    for name, location in (attribute_locations or {}).items():
        gl.bindAttribLocation(prog, location, name)
    gl.linkProgram(prog)
    for shader in shaders:
        gl.deleteShader(shader)   # freed with the program
    if not gl.getProgramParameter(prog, gl.LINK_STATUS):
        log = gl.getProgramInfoLog(prog)
        gl.deleteProgram(prog)
        raise ShaderError("link", log)
    return prog
