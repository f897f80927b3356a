"""Buffers, vertex attributes and vertex array objects: state and validation (issue 4 scope).

Rules from WebGL 1.0 §5.14.5/§6.1-6.6, WebGL 2.0 §5.1, ES 3.0 §2.8-2.10 and §5.1.2.
"""
import numpy as np
import pytest

import softgl


def test_buffer_lifecycle(version):
    gl = softgl.Context(2, 2, version=version)
    buf = gl.createBuffer()
    assert not gl.isBuffer(buf)                    # not a buffer until first bound
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    assert gl.isBuffer(buf)
    assert gl.getParameter(gl.ARRAY_BUFFER_BINDING) is buf
    gl.bufferData(gl.ARRAY_BUFFER, 16, gl.DYNAMIC_DRAW)
    assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE) == 16
    assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_USAGE) == gl.DYNAMIC_DRAW
    gl.bufferSubData(gl.ARRAY_BUFFER, 4, np.array([1.5, -2.0], np.float32))
    gl.deleteBuffer(buf)
    assert not gl.isBuffer(buf)
    assert gl.getParameter(gl.ARRAY_BUFFER_BINDING) is None   # deleting unbinds
    assert gl.getError() == gl.NO_ERROR


def test_buffer_contents_roundtrip_webgl2():
    gl = softgl.Context(2, 2)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, 8 * 4, gl.STATIC_DRAW)      # sized buffers read as zeros
    gl.bufferSubData(gl.ARRAY_BUFFER, 8, np.array([7, 8, 9], np.int32))
    out = np.full(8, -1, np.int32)
    gl.getBufferSubData(gl.ARRAY_BUFFER, 0, out)
    assert out.tolist() == [0, 0, 7, 8, 9, 0, 0, 0]
    # srcOffset/length count elements of the source array, as in WebGL 2.
    gl.bufferData(gl.ARRAY_BUFFER, np.arange(10, dtype=np.uint16), gl.STATIC_DRAW, 2, 3)
    assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE) == 6
    got = np.zeros(3, np.uint16)
    gl.getBufferSubData(gl.ARRAY_BUFFER, 0, got)
    assert got.tolist() == [2, 3, 4]
    # copyBufferSubData between two buffers.
    other = gl.createBuffer()
    gl.bindBuffer(gl.COPY_WRITE_BUFFER, other)
    gl.bufferData(gl.COPY_WRITE_BUFFER, 6, gl.STATIC_COPY)
    gl.bindBuffer(gl.COPY_READ_BUFFER, buf)
    gl.copyBufferSubData(gl.COPY_READ_BUFFER, gl.COPY_WRITE_BUFFER, 2, 0, 4)
    copied = np.zeros(3, np.uint16)
    gl.getBufferSubData(gl.COPY_WRITE_BUFFER, 0, copied)
    assert copied.tolist() == [3, 4, 0]
    assert gl.getError() == gl.NO_ERROR


@pytest.mark.parametrize("steps, error", [
    (lambda gl, b: gl.bindBuffer(0x1234, b), "INVALID_ENUM"),
    (lambda gl, b: gl.bufferData(gl.ARRAY_BUFFER, 4, gl.STATIC_DRAW), "INVALID_OPERATION"),  # nothing bound
    (lambda gl, b: (gl.bindBuffer(gl.ARRAY_BUFFER, b), gl.bufferData(gl.ARRAY_BUFFER, -1, gl.STATIC_DRAW)), "INVALID_VALUE"),
    (lambda gl, b: (gl.bindBuffer(gl.ARRAY_BUFFER, b), gl.bufferData(gl.ARRAY_BUFFER, 4, 0x1234)), "INVALID_ENUM"),
    (lambda gl, b: (gl.bindBuffer(gl.ARRAY_BUFFER, b), gl.bufferData(gl.ARRAY_BUFFER, None, gl.STATIC_DRAW)), "INVALID_VALUE"),
    (lambda gl, b: (gl.bindBuffer(gl.ARRAY_BUFFER, b), gl.bufferData(gl.ARRAY_BUFFER, 4, gl.STATIC_DRAW),
                    gl.bufferSubData(gl.ARRAY_BUFFER, 2, np.zeros(3, np.uint8))), "INVALID_VALUE"),
    (lambda gl, b: (gl.bindBuffer(gl.ARRAY_BUFFER, b), gl.bufferData(gl.ARRAY_BUFFER, 4, gl.STATIC_DRAW),
                    gl.bufferSubData(gl.ARRAY_BUFFER, -1, np.zeros(1, np.uint8))), "INVALID_VALUE"),
    (lambda gl, b: (gl.bindBuffer(gl.ARRAY_BUFFER, b), gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, b)), "INVALID_OPERATION"),
    (lambda gl, b: (gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, b), gl.bindBuffer(gl.ARRAY_BUFFER, b)), "INVALID_OPERATION"),
    (lambda gl, b: (gl.deleteBuffer(b), gl.bindBuffer(gl.ARRAY_BUFFER, b)), "INVALID_OPERATION"),
    (lambda gl, b: gl.bindBuffer(gl.ARRAY_BUFFER, softgl.Context(1, 1).createBuffer()), "INVALID_OPERATION"),
    (lambda gl, b: gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE), "INVALID_OPERATION"),
    (lambda gl, b: (gl.bindBuffer(gl.ARRAY_BUFFER, b), gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BLEND)), "INVALID_ENUM"),
])
def test_buffer_errors(steps, error, version, quiet):
    gl = softgl.Context(2, 2, version=version)
    steps(gl, gl.createBuffer())
    assert gl.getError() == getattr(gl, error)


def test_webgl1_has_no_webgl2_buffer_targets(quiet):
    gl = softgl.Context(2, 2, version=1)
    gl.bindBuffer(0x8F36, gl.createBuffer())    # COPY_READ_BUFFER
    assert gl.getError() == gl.INVALID_ENUM
    assert not hasattr(gl, "getBufferSubData")
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, 4, 0x88E5)    # STREAM_READ is WebGL 2
    assert gl.getError() == gl.INVALID_ENUM


def test_vertex_attrib_pointer_state(version):
    gl = softgl.Context(2, 2, version=version)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.vertexAttribPointer(3, 2, gl.SHORT, True, 8, 4)
    gl.enableVertexAttribArray(3)
    q = lambda p: gl.getVertexAttrib(3, p)
    assert q(gl.VERTEX_ATTRIB_ARRAY_BUFFER_BINDING) is buf
    assert (q(gl.VERTEX_ATTRIB_ARRAY_SIZE), q(gl.VERTEX_ATTRIB_ARRAY_TYPE)) == (2, gl.SHORT)
    assert q(gl.VERTEX_ATTRIB_ARRAY_NORMALIZED) is True
    assert q(gl.VERTEX_ATTRIB_ARRAY_ENABLED) is True
    assert q(gl.VERTEX_ATTRIB_ARRAY_STRIDE) == 8
    assert gl.getVertexAttribOffset(3, gl.VERTEX_ATTRIB_ARRAY_POINTER) == 4
    # Defaults of an untouched attribute (ES 3.0 table 6.4).
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_SIZE) == 4
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_TYPE) == gl.FLOAT
    assert gl.getVertexAttrib(0, gl.CURRENT_VERTEX_ATTRIB).tolist() == [0, 0, 0, 1]
    assert gl.getError() == gl.NO_ERROR


def test_constant_attributes(version, quiet):
    gl = softgl.Context(2, 2, version=version)
    gl.vertexAttrib2f(1, 0.5, -2)
    assert gl.getVertexAttrib(1, gl.CURRENT_VERTEX_ATTRIB).tolist() == [0.5, -2, 0, 1]
    gl.vertexAttrib3fv(2, np.array([1, 2, 3], np.float32))
    assert gl.getVertexAttrib(2, gl.CURRENT_VERTEX_ATTRIB).tolist() == [1, 2, 3, 1]
    gl.vertexAttrib4fv(2, [1, 2])                  # too short: INVALID_VALUE, nothing changes
    assert gl.getError() == gl.INVALID_VALUE
    assert gl.getVertexAttrib(2, gl.CURRENT_VERTEX_ATTRIB).tolist() == [1, 2, 3, 1]
    gl.vertexAttrib1f(16, 1.0)
    assert gl.getError() == gl.INVALID_VALUE
    if version == 2:
        gl.vertexAttribI4i(4, -1, 2, -3, 4)
        value = gl.getVertexAttrib(4, gl.CURRENT_VERTEX_ATTRIB)
        assert value.dtype == np.int32 and value.tolist() == [-1, 2, -3, 4]
        gl.vertexAttribI4ui(5, 1, 2, 3, 4)
        assert gl.getVertexAttrib(5, gl.CURRENT_VERTEX_ATTRIB).dtype == np.uint32


@pytest.mark.parametrize("args, bound, error", [
    ((16, 4, "FLOAT", False, 0, 0), True, "INVALID_VALUE"),      # index >= MAX_VERTEX_ATTRIBS
    ((0, 0, "FLOAT", False, 0, 0), True, "INVALID_VALUE"),       # size 0
    ((0, 5, "FLOAT", False, 0, 0), True, "INVALID_VALUE"),
    ((0, 4, "BLEND", False, 0, 0), True, "INVALID_ENUM"),
    ((0, 4, "FLOAT", False, 256, 0), True, "INVALID_VALUE"),     # WebGL: stride <= 255
    ((0, 4, "FLOAT", False, -4, 0), True, "INVALID_VALUE"),
    ((0, 4, "FLOAT", False, 0, -4), True, "INVALID_VALUE"),
    ((0, 4, "FLOAT", False, 0, 2), True, "INVALID_OPERATION"),   # offset not a multiple of 4
    ((0, 4, "SHORT", False, 3, 0), True, "INVALID_OPERATION"),   # stride not a multiple of 2
    ((0, 4, "FLOAT", False, 0, 4), False, "INVALID_OPERATION"),  # no buffer, non-zero offset
])
def test_vertex_attrib_pointer_errors(args, bound, error, version, quiet):
    gl = softgl.Context(2, 2, version=version)
    if bound:
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    index, size, typ, norm, stride, offset = args
    gl.vertexAttribPointer(index, size, getattr(gl, typ), norm, stride, offset)
    assert gl.getError() == getattr(gl, error)
    if index < 16:
        assert gl.getVertexAttrib(index, gl.VERTEX_ATTRIB_ARRAY_SIZE) == 4   # unchanged


def test_vertex_array_objects_capture_attribute_state():
    gl = softgl.Context(2, 2)
    a, b = gl.createBuffer(), gl.createBuffer()
    vao = gl.createVertexArray()
    assert not gl.isVertexArray(vao)
    gl.bindVertexArray(vao)
    assert gl.isVertexArray(vao) and gl.getParameter(gl.VERTEX_ARRAY_BINDING) is vao
    gl.bindBuffer(gl.ARRAY_BUFFER, a)
    gl.vertexAttribPointer(0, 3, gl.FLOAT, False, 0, 0)
    gl.enableVertexAttribArray(0)
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, b)
    gl.bindVertexArray(None)
    # The default vertex array is untouched; ARRAY_BUFFER_BINDING is context state, not VAO state.
    assert gl.getParameter(gl.VERTEX_ARRAY_BINDING) is None
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_ENABLED) is False
    assert gl.getParameter(gl.ELEMENT_ARRAY_BUFFER_BINDING) is None
    assert gl.getParameter(gl.ARRAY_BUFFER_BINDING) is a
    gl.bindVertexArray(vao)
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_BUFFER_BINDING) is a
    assert gl.getParameter(gl.ELEMENT_ARRAY_BUFFER_BINDING) is b
    gl.vertexAttribDivisor(0, 3)
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_DIVISOR) == 3
    # Deleting the bound VAO falls back to the default one.
    gl.deleteVertexArray(vao)
    assert gl.getParameter(gl.VERTEX_ARRAY_BINDING) is None and not gl.isVertexArray(vao)
    with pytest.warns(softgl.GLWarning):
        gl.bindVertexArray(vao)
    assert gl.getError() == gl.INVALID_OPERATION


def test_deleting_a_buffer_detaches_it_from_the_bound_vao_only():
    gl = softgl.Context(2, 2)
    buf = gl.createBuffer()
    other_vao = gl.createVertexArray()
    gl.bindVertexArray(other_vao)
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.vertexAttribPointer(1, 2, gl.FLOAT, False, 0, 0)
    gl.bindVertexArray(None)
    gl.vertexAttribPointer(1, 2, gl.FLOAT, False, 0, 0)
    gl.deleteBuffer(buf)
    assert gl.getVertexAttrib(1, gl.VERTEX_ATTRIB_ARRAY_BUFFER_BINDING) is None
    gl.bindVertexArray(other_vao)   # ES 3.0 §5.1.2: other VAOs keep their (deleted) attachment
    assert gl.getVertexAttrib(1, gl.VERTEX_ATTRIB_ARRAY_BUFFER_BINDING) is buf


def test_oes_vertex_array_object_in_webgl1():
    gl = softgl.Context(2, 2, version=1)
    assert not hasattr(gl, "createVertexArray")
    ext = gl.getExtension("OES_vertex_array_object")
    vao = ext.createVertexArrayOES()
    ext.bindVertexArrayOES(vao)
    assert ext.isVertexArrayOES(vao)
    assert gl.getParameter(ext.VERTEX_ARRAY_BINDING_OES) is vao
    ext.deleteVertexArrayOES(vao)
    assert gl.getParameter(ext.VERTEX_ARRAY_BINDING_OES) is None


def test_handles_are_typed():
    gl = softgl.Context(2, 2)
    with pytest.raises(TypeError):
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createVertexArray())
    with pytest.raises(TypeError):
        softgl._core.WebGLBuffer()
