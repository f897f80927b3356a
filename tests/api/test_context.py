"""Context creation, attributes, sizes (issue 2)."""
import pytest

import softgl


def test_default_is_webgl2_with_webgl_attribute_defaults():
    gl = softgl.Context()
    assert isinstance(gl, softgl.WebGL2RenderingContext)
    assert isinstance(gl, softgl.Context)
    assert (gl.drawingBufferWidth, gl.drawingBufferHeight) == (300, 150)   # the canvas default
    assert gl.getContextAttributes() == {
        "alpha": True, "depth": True, "stencil": False, "antialias": True,
        "premultipliedAlpha": True, "preserveDrawingBuffer": False,
        "powerPreference": "default", "failIfMajorPerformanceCaveat": False,
        "desynchronized": False, "xrCompatible": False}
    assert gl.getParameter(gl.VERSION).startswith("WebGL 2.0")
    assert gl.getParameter(gl.SHADING_LANGUAGE_VERSION).startswith("WebGL GLSL ES 3.00")


def test_version_1():
    gl = softgl.Context(8, 8, version=1)
    assert isinstance(gl, softgl.WebGLRenderingContext)
    assert not isinstance(gl, softgl.WebGL2RenderingContext)
    assert gl.getParameter(gl.VERSION).startswith("WebGL 1.0")
    assert gl.getParameter(gl.SHADING_LANGUAGE_VERSION).startswith("WebGL GLSL ES 1.0")
    assert softgl.WebGLRenderingContext(4, 4).version == 1
    with pytest.raises(ValueError):
        softgl.WebGLRenderingContext(4, 4, version=2)


@pytest.mark.parametrize("attrs, bits", [
    (dict(), (8, 8, 8, 8, 24, 0)),
    (dict(alpha=False), (8, 8, 8, 0, 24, 0)),
    (dict(depth=False, stencil=True), (8, 8, 8, 8, 0, 8)),
])
def test_buffer_bits_follow_attributes(attrs, bits):
    gl = softgl.Context(4, 4, **attrs)
    names = ["RED_BITS", "GREEN_BITS", "BLUE_BITS", "ALPHA_BITS", "DEPTH_BITS", "STENCIL_BITS"]
    assert tuple(gl.getParameter(getattr(gl, n)) for n in names) == bits


def test_antialias_gives_four_samples_and_samples_option():
    gl = softgl.Context(4, 4)
    assert gl.getParameter(gl.SAMPLE_BUFFERS) == 1 and gl.getParameter(gl.SAMPLES) == 4
    gl = softgl.Context(4, 4, antialias=False)
    assert gl.getParameter(gl.SAMPLE_BUFFERS) == 0 and gl.getParameter(gl.SAMPLES) == 0
    gl = softgl.Context(4, 4, samples=16)
    assert gl.getParameter(gl.SAMPLES) == 16
    with pytest.raises(ValueError):
        softgl.Context(4, 4, samples=3)
    with pytest.raises(ValueError):
        softgl.Context(4, 4, antialias=False, samples=4)


@pytest.mark.parametrize("size", [(0, 10), (10, 0), (-1, 5), (16385, 1), (1, 10**6), (2**40, 2)])
def test_bad_sizes_raise_value_error(size):
    with pytest.raises(ValueError):
        softgl.Context(*size)


def test_size_beyond_memory_raises_before_allocating():
    # 16384^2 x 16 samples x 9 bytes = 36 GiB: more than this machine's memory budget.
    with pytest.raises(ValueError, match="memory"):
        softgl.Context(16384, 16384, samples=16, stencil=True)


def test_wrong_types_raise_type_error():
    with pytest.raises(TypeError):
        softgl.Context(10.5, 10)
    with pytest.raises(TypeError):
        softgl.Context(10, 10, alhpa=False)
    gl = softgl.Context(2, 2)
    with pytest.raises(TypeError):
        gl.blendFunc("ONE", gl.ZERO)
    with pytest.raises(TypeError):
        gl.clearColor("red", 0, 0, 1)


def test_misc_entry_points():
    gl = softgl.Context(2, 2)
    assert gl.isContextLost() is False
    gl.flush()
    gl.finish()
    assert gl.getError() == gl.NO_ERROR
    assert gl.canvas is gl.canvas and (gl.canvas.width, gl.canvas.height) == (gl.drawingBufferWidth, gl.drawingBufferHeight)
