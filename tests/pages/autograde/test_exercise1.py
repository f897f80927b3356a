"""Autograding example: a folder of student pages for one exercise, one test each, every page
checked against the teacher's reference image (here drawn with softgl's Python API, so it does
not come from the JavaScript path under test). In a course, each student's test passes or fails
on its own; here the expected verdict of each example student is asserted too."""
from pathlib import Path

import numpy as np
import pytest

import softgl
from softgl.page import PageError
from softgl.testing import assert_page_frame

STUDENTS = Path(__file__).parent / "students"


def reference():
    """Exercise 1's expected canvas: a red triangle on dark grey, 64x48."""
    gl = softgl.Context(64, 48, version=1, antialias=False)
    prog = softgl.program(gl, "attribute vec2 aPos; void main() { gl_Position = vec4(aPos, 0.0, 1.0); }",
                          "precision mediump float; void main() { gl_FragColor = vec4(1.0, 0.0, 0.0, 1.0); }")
    gl.useProgram(prog)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-0.5, -0.5, 0.5, -0.5, 0.0, 0.5], np.float32), gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
    gl.clearColor(0.1, 0.1, 0.1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    return gl.readPixels(0, 0, 64, 48, gl.RGBA, gl.UNSIGNED_BYTE)


VERDICTS = {"ada": "pass", "bob": "wrong picture", "cy": "JavaScript error"}


@pytest.mark.parametrize("student", sorted(p.stem for p in STUDENTS.glob("*.html")))
def test_student_page(student, tmp_path):
    page = STUDENTS / f"{student}.html"
    verdict = VERDICTS[student]
    if verdict == "pass":
        assert_page_frame(page, reference(), out_dir=tmp_path)
    elif verdict == "wrong picture":
        with pytest.raises(AssertionError, match="pixels beyond atol"):
            assert_page_frame(page, reference(), out_dir=tmp_path)
        assert (tmp_path / f"{student}" / "diff.png").is_file()
    else:
        with pytest.raises(PageError, match="gl.drawArays is not a function"):
            assert_page_frame(page, reference())
