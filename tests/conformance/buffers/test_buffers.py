"""conformance/buffers: binding rules, bufferData/bufferSubData validation, zero-initialised
storage, index validation (out of range, resized, updated, copied). Rules from WebGL 1.0 §5.14.5,
§6.2 (buffer target rules), §6.6 (index validation) and WebGL 2.0 §5.1, §5.14."""
import numpy as np
import pytest

from conformance.helpers import (GREEN, QUAD, array_buffer, attribute, context, error, errors,
                                 pixel, program, read)


def test_buffer_bind_target_rules(version):
    # buffer-bind-test: a buffer first bound to ARRAY_BUFFER can never be bound to
    # ELEMENT_ARRAY_BUFFER and vice versa (WebGL 1.0 §6.2 / WebGL 2.0 §5.1).
    gl = context(version=version)
    a, e = gl.createBuffer(), gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, a)
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, e)
    assert error(gl) == gl.NO_ERROR
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, a)
    assert error(gl) == gl.INVALID_OPERATION
    gl.bindBuffer(gl.ARRAY_BUFFER, e)
    assert error(gl) == gl.INVALID_OPERATION
    gl.bindBuffer(gl.ARRAY_BUFFER, None)
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, None)
    assert error(gl) == gl.NO_ERROR
    gl.bindBuffer(gl.TEXTURE_2D, a)
    assert error(gl) == gl.INVALID_ENUM
    if version == 2:
        gl.bindBuffer(gl.COPY_READ_BUFFER, a)          # other targets accept array buffers
        gl.bindBuffer(gl.UNIFORM_BUFFER, a)
        assert error(gl) == gl.NO_ERROR
        gl.bindBuffer(gl.COPY_WRITE_BUFFER, e)          # copy targets take either kind
        assert error(gl) == gl.NO_ERROR
        fresh = gl.createBuffer()
        gl.bindBuffer(gl.UNIFORM_BUFFER, fresh)          # now "other data"
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, fresh)
        assert error(gl) == gl.INVALID_OPERATION


def test_buffer_data_and_sub_data_validation(version):
    # buffer-data-and-buffer-sub-data
    gl = context(version=version)
    gl.bufferData(gl.ARRAY_BUFFER, 4, gl.STATIC_DRAW)
    assert error(gl) == gl.INVALID_OPERATION              # nothing bound
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, -4, gl.STATIC_DRAW)
    assert error(gl) == gl.INVALID_VALUE
    gl.bufferData(gl.ARRAY_BUFFER, 0, gl.STATIC_DRAW)
    assert error(gl) == gl.NO_ERROR
    gl.bufferData(gl.ARRAY_BUFFER, None, gl.STATIC_DRAW)
    assert error(gl) == gl.INVALID_VALUE
    gl.bufferData(gl.ARRAY_BUFFER, 16, 0x1234)
    assert error(gl) == gl.INVALID_ENUM
    for usage in (gl.STATIC_DRAW, gl.DYNAMIC_DRAW, gl.STREAM_DRAW):
        gl.bufferData(gl.ARRAY_BUFFER, 16, usage)
        assert error(gl) == gl.NO_ERROR
        assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_USAGE) == usage
    assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE) == 16
    data = np.arange(4, dtype=np.uint8)
    gl.bufferSubData(gl.ARRAY_BUFFER, 12, data)             # exactly fits
    assert error(gl) == gl.NO_ERROR
    gl.bufferSubData(gl.ARRAY_BUFFER, 13, data)             # one byte past the end
    assert error(gl) == gl.INVALID_VALUE
    gl.bufferSubData(gl.ARRAY_BUFFER, -1, data)
    assert error(gl) == gl.INVALID_VALUE
    gl.bufferSubData(gl.ARRAY_BUFFER, 16, np.zeros(0, np.uint8))   # empty at the end: fine
    assert error(gl) == gl.NO_ERROR
    with pytest.raises(TypeError):                           # srcData is not nullable in the IDL
        gl.bufferSubData(gl.ARRAY_BUFFER, 0, None)
    gl.bindBuffer(gl.ARRAY_BUFFER, None)
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, data)
    assert error(gl) == gl.INVALID_OPERATION


def test_buffer_storage_is_zero_initialised():
    # buffer-uninitialized: bufferData(size) gives zeros; growing a buffer gives zeros too.
    gl = context(version=2)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.full(8, 0xAB, np.uint8), gl.STATIC_DRAW)
    gl.bufferData(gl.ARRAY_BUFFER, 64, gl.STATIC_DRAW)
    out = np.full(64, 0xCD, np.uint8)
    gl.getBufferSubData(gl.ARRAY_BUFFER, 0, out)
    assert not out.any()
    assert error(gl) == gl.NO_ERROR


def test_uninitialised_index_buffer_draws_vertex_zero(version):
    # buffer-uninitialized (index part): an index buffer from bufferData(size) holds index 0
    # everywhere, so every triangle is degenerate and nothing is drawn, without error.
    gl = context(version=version)
    program(gl)
    attribute(gl, 0, QUAD, 2)
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, 12, gl.STATIC_DRAW)
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.NO_ERROR and not read(gl).any()


def test_deleted_array_buffer_pointed_to_by_an_attribute(version):
    # buffer-data-array-buffer-delete: deleting an ARRAY_BUFFER that attribute 1 points at is
    # safe. ES 2.0 §2.9: bindings in the current context (incl. the attribute's) reset to zero,
    # so bufferData has no buffer and a draw that uses the attribute is INVALID_OPERATION.
    gl = context(version=version)
    program(gl, locations={"aPos": 1})
    buf = attribute(gl, 1, QUAD, 2)
    gl.deleteBuffer(buf)
    assert gl.getParameter(gl.ARRAY_BUFFER_BINDING) is None
    assert gl.getVertexAttrib(1, gl.VERTEX_ATTRIB_ARRAY_BUFFER_BINDING) is None
    gl.bufferData(gl.ARRAY_BUFFER, 4, gl.STATIC_DRAW)
    assert error(gl) == gl.INVALID_OPERATION
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert error(gl) == gl.INVALID_OPERATION and not read(gl).any()


def test_element_array_buffer_delete_recreate(version):
    # element-array-buffer-delete-recreate: draw, delete the index buffer, make a new one with other
    # indices: the new indices are used.
    gl = context(version=version)
    program(gl)
    verts = np.float32([-1, -1, 1, -1, -1, 1, 1, 1])
    attribute(gl, 0, verts, 2)
    for k, idx in enumerate(([0, 1, 2], [1, 3, 2])):
        buf = array_buffer(gl, np.uint16(idx), gl.ELEMENT_ARRAY_BUFFER)
        gl.clear(gl.COLOR_BUFFER_BIT)
        gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)
        img = read(gl)
        # [0,1,2] covers the lower-left half only; [1,3,2] the upper-right half only
        assert (img[2, 2, 1], img[13, 13, 1]) == ((255, 0) if k == 0 else (0, 255))
        gl.deleteBuffer(buf)
    assert error(gl) == gl.NO_ERROR


def test_index_validation(version):
    # index-validation: indices out of range of any enabled attribute -> INVALID_OPERATION;
    # offsets that are not a multiple of the index size -> INVALID_OPERATION; negative count or
    # offset -> INVALID_VALUE; no ELEMENT_ARRAY_BUFFER -> INVALID_OPERATION; valid draws fine.
    gl = context(version=version)
    program(gl)
    attribute(gl, 0, np.float32([-1, -1, 1, -1, -1, 1, 1, 1]), 2)   # 4 vertices
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.INVALID_OPERATION
    array_buffer(gl, np.uint16([0, 1, 2, 3, 4, 1]), gl.ELEMENT_ARRAY_BUFFER)
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.NO_ERROR
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 4)            # 2, 3, 4: 4 out of range
    assert error(gl) == gl.INVALID_OPERATION
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 1)
    assert error(gl) == gl.INVALID_OPERATION
    gl.drawElements(gl.TRIANGLES, -1, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.INVALID_VALUE
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, -2)
    assert error(gl) == gl.INVALID_VALUE
    gl.drawElements(gl.TRIANGLES, 3, gl.FLOAT, 0)
    assert error(gl) == gl.INVALID_ENUM
    gl.drawElements(gl.TRIANGLES, 2, gl.UNSIGNED_BYTE, 1)             # bytes: any offset
    assert error(gl) == gl.NO_ERROR


def test_index_validation_counts_past_the_buffer(version):
    # index-validation-verifies-too-many-indices: count*size + offset beyond the buffer.
    gl = context(version=version)
    program(gl)
    attribute(gl, 0, QUAD, 2)
    array_buffer(gl, np.uint16([0, 1, 2, 3, 4, 5]), gl.ELEMENT_ARRAY_BUFFER)
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.NO_ERROR
    gl.drawElements(gl.TRIANGLES, 7, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.INVALID_OPERATION
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 2)
    assert error(gl) == gl.INVALID_OPERATION
    gl.drawElements(gl.TRIANGLES, 0xFFFFFFF, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.INVALID_OPERATION


def test_index_validation_with_resized_and_updated_buffers(version):
    # index-validation-with-resized-buffer, index-validation-crash-with-buffer-sub-data,
    # index-validation-copies-indices: validation follows the *current* vertex buffer size and
    # index contents; the index data was copied at bufferData time.
    gl = context(version=version)
    program(gl)
    vbuf = attribute(gl, 0, QUAD, 2)                                   # 6 vertices
    idx = np.uint16([0, 1, 2, 3, 4, 5])
    ibuf = array_buffer(gl, idx, gl.ELEMENT_ARRAY_BUFFER)
    idx[:] = 100                                                       # client copy changes
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.NO_ERROR
    gl.bindBuffer(gl.ARRAY_BUFFER, vbuf)
    gl.bufferData(gl.ARRAY_BUFFER, QUAD[:6], gl.STATIC_DRAW)          # now 3 vertices
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.INVALID_OPERATION
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.NO_ERROR
    gl.bufferSubData(gl.ELEMENT_ARRAY_BUFFER, 2, np.uint16([7]))      # index 1 -> 7
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.INVALID_OPERATION
    gl.bufferSubData(gl.ELEMENT_ARRAY_BUFFER, 2, np.uint16([1]))
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.NO_ERROR
    gl.bufferData(gl.ARRAY_BUFFER, QUAD, gl.STATIC_DRAW)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, 4, gl.STATIC_DRAW)        # 2 zero indices
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.INVALID_OPERATION
    gl.drawElements(gl.TRIANGLES, 2, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.NO_ERROR


def test_index_validation_large_buffer(version):
    # index-validation-large-buffer: a large index buffer whose used range is valid, with an
    # out-of-range index outside the drawn range.
    gl = context(version=version)
    program(gl)
    attribute(gl, 0, QUAD, 2)
    idx = np.zeros(65536 + 6, np.uint16)
    idx[:6] = np.arange(6)
    idx[-1] = 65534             # out of range, not drawn (65535 would be WebGL 2's restart index)
    array_buffer(gl, idx, gl.ELEMENT_ARRAY_BUFFER)
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.NO_ERROR and pixel(gl, 8, 8) == GREEN
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 2 * (len(idx) - 3))
    assert error(gl) == gl.INVALID_OPERATION


def test_vertex_buffer_updated_after_draw(version):
    # vertex-buffer-updated-after-draw: bufferSubData after a draw is seen by the next draw.
    gl = context(version=version)
    prog = program(gl, "attribute vec4 aPos; attribute vec4 aC; varying vec4 v; void main() { gl_Position = aPos; v = aC; }",
                   "precision mediump float; varying vec4 v; void main() { gl_FragColor = v; }",
                   {"aPos": 0, "aC": 1})
    attribute(gl, 0, QUAD, 2)
    cbuf = attribute(gl, 1, np.tile(np.float32([1, 0, 0, 1]), 6), 4)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 8, 8) == (255, 0, 0, 255)
    gl.bindBuffer(gl.ARRAY_BUFFER, cbuf)
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, np.tile(np.float32([0, 0, 1, 1]), 6))
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 8, 8) == (0, 0, 255, 255)
