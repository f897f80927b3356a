"""Deterministic cases the command-stream fuzzer covers at random: objects of another context
(alive or destroyed), objects deleted while bound or in use, and GLWarning handlers that call
back into the context while the failing call is on the stack."""
import gc
import warnings

import numpy as np
import pytest

import softgl

VS = "attribute vec4 aPos; void main() { gl_Position = aPos; gl_PointSize = 1.0; }"
FS = "precision mediump float; void main() { gl_FragColor = vec4(1.0); }"


def drawable(gl):
    prog = softgl.program(gl, VS, FS, {"aPos": 0})
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([[-1, -1, 0, 1], [3, -1, 0, 1], [-1, 3, 0, 1]], np.float32),
                  gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    return prog, buf


def test_objects_of_another_live_context_are_invalid_operation(quiet):
    a, b = softgl.Context(4, 4), softgl.Context(4, 4)
    prog, buf = drawable(a)
    vao = a.createVertexArray()
    shader = a.createShader(a.VERTEX_SHADER)
    for call, args in [("bindBuffer", (b.ARRAY_BUFFER, buf)), ("useProgram", (prog,)),
                       ("bindVertexArray", (vao,)), ("deleteBuffer", (buf,)), ("deleteProgram", (prog,)),
                       ("attachShader", (b.createProgram(), shader)), ("compileShader", (shader,)),
                       ("getUniformLocation", (prog, "x"))]:
        getattr(b, call)(*args)
        assert b.getError() == b.INVALID_OPERATION, call
    assert not b.isBuffer(buf) and not b.isProgram(prog) and not b.isVertexArray(vao) and not b.isShader(shader)
    a.drawArrays(a.TRIANGLES, 0, 3)                   # untouched in its own context
    assert a.getError() == a.NO_ERROR and a.readPixels(1, 1, 1, 1, a.RGBA, a.UNSIGNED_BYTE)[0, 0, 0] == 255


def test_objects_of_a_destroyed_context_are_invalid_operation(quiet):
    for attempt in range(50):
        a = softgl.Context(4, 4)
        prog, buf = drawable(a)
        del a
        gc.collect()
        c = softgl.Context(4, 4)
        c.bindBuffer(c.ARRAY_BUFFER, buf)
        assert c.getError() == c.INVALID_OPERATION, f"attempt {attempt}: a dead context's buffer was accepted"
        c.useProgram(prog)
        assert c.getError() == c.INVALID_OPERATION, f"attempt {attempt}: a dead context's program was accepted"
        assert not c.isBuffer(buf) and not c.isProgram(prog)


def test_deleting_bound_and_current_objects(quiet):
    gl = softgl.Context(4, 4, antialias=False)
    prog, buf = drawable(gl)
    gl.deleteBuffer(buf)            # unbinds it from ARRAY_BUFFER; the attribute keeps it (ES 3.0 §2.10.1)
    assert gl.getParameter(gl.ARRAY_BUFFER_BINDING) is None
    gl.deleteProgram(prog)          # flagged, still current and usable
    assert gl.getProgramParameter(prog, gl.DELETE_STATUS) is True
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    assert gl.getError() in (gl.NO_ERROR, gl.INVALID_OPERATION)
    gl.useProgram(None)             # now it really goes
    assert not gl.isProgram(prog)
    gl.useProgram(prog)
    assert gl.getError() == gl.INVALID_OPERATION
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    assert gl.getError() == gl.INVALID_OPERATION


@pytest.mark.parametrize("action", ["delete_program", "redefine_buffer", "draw", "get_error", "use_null"])
def test_warning_handler_that_calls_back_into_the_context(action):
    gl = softgl.Context(8, 8, antialias=False)
    prog, buf = drawable(gl)
    seen = []

    def handler(message, category, filename, lineno, file=None, line=None):
        seen.append(str(message))
        if len(seen) > 1:
            return
        if action == "delete_program":
            gl.deleteProgram(prog)
            gl.useProgram(None)
        elif action == "redefine_buffer":
            gl.bufferData(gl.ARRAY_BUFFER, 0, gl.STATIC_DRAW)
        elif action == "draw":
            gl.drawArrays(gl.TRIANGLES, 0, 3)
            gl.drawArrays(gl.TRIANGLES, 0, 99)        # a nested error, reported again
        elif action == "get_error":
            seen.append(gl.getError())
        elif action == "use_null":
            gl.useProgram(None)
    with warnings.catch_warnings():
        warnings.simplefilter("always", softgl.GLWarning)
        old, warnings.showwarning = warnings.showwarning, handler
        try:
            gl.drawArrays(gl.TRIANGLES, 0, 99)       # out of range: INVALID_OPERATION -> handler
            gl.drawArrays(gl.TRIANGLES, 0, 3)
        finally:
            warnings.showwarning = old
    assert seen and "drawArrays" in seen[0]
    if action == "get_error":
        assert seen[1] == gl.INVALID_OPERATION and gl.getError() == gl.NO_ERROR
    if action == "draw":
        assert len(seen) == 2
    gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.UNSIGNED_BYTE)   # the context still works


def test_strict_error_raised_inside_a_nested_call_propagates_cleanly():
    gl = softgl.Context(4, 4, strict=True)
    drawable(gl)
    with pytest.raises(softgl.GLError):
        gl.drawArrays(gl.TRIANGLES, 0, 99)
    with pytest.raises(softgl.GLError):
        gl.blendFunc(gl.CONSTANT_COLOR, gl.CONSTANT_ALPHA)
    assert gl.getError() == gl.INVALID_OPERATION     # recorded before raising
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    assert gl.getError() == gl.NO_ERROR
