"""softgl: a software WebGL for Python.

    import softgl
    gl = softgl.Context(640, 480, antialias=False)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    img = gl.readPixels(0, 0, 640, 480, gl.RGBA, gl.UNSIGNED_BYTE)   # (480, 640, 4), row 0 = bottom
"""
from . import _core
from .errors import Float64Warning, GLError, GLWarning
from .context import Context, WebGLRenderingContext, WebGL2RenderingContext
from . import display, io
from . import geometry, transforms, programs, scene, experiments, testing, transparency, widgets, animation
from .programs import Program, ShaderError, program

__version__ = "0.1.0"

# Every WebGL 1 and 2 constant, with WebGL's value, on the module (softgl.BLEND).
for _name, _value, _version in _core.ENUMS:
    globals()[_name] = _value
del _name, _value, _version

__all__ = ["program", "Program", "ShaderError", "Context", "WebGLRenderingContext", "WebGL2RenderingContext", "GLError", "GLWarning", "Float64Warning"]
