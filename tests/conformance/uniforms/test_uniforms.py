"""conformance/uniforms: arrays, bools, matrices (transpose rule), unknown and null locations,
default values, locations across programs and relinks, per-program values, samplers.
WebGL 1.0 §5.14.10, ES 2.0 §2.10.4."""
import numpy as np
import pytest

from conformance.helpers import QUAD, attribute, context, error, pixel, program

VS = "attribute vec4 aPos; void main() { gl_Position = aPos; }"


def frag(decl, expr):
    return f"precision mediump float; {decl} void main() {{ gl_FragColor = {expr}; }}"


def test_uniform_arrays(version):
    # gl-uniform-arrays: element locations, setting from a[0] writes consecutive elements, extra
    # values past the end are ignored, getUniform per element; a too-short array is INVALID_VALUE.
    gl = context(version=version)
    p = program(gl, VS, frag("uniform float a[4];", "vec4(a[0], a[1], a[2], a[3])"))
    l0, l2 = gl.getUniformLocation(p, "a[0]"), gl.getUniformLocation(p, "a[2]")
    assert gl.getUniformLocation(p, "a") is not None and gl.getUniformLocation(p, "a[4]") is None
    gl.uniform1fv(gl.getUniformLocation(p, "a"), [0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    assert error(gl) == gl.NO_ERROR
    assert [round(float(gl.getUniform(p, gl.getUniformLocation(p, f"a[{i}]"))), 6)
            for i in range(4)] == [0.1, 0.2, 0.3, 0.4]
    gl.uniform1fv(l2, [0.9, 0.8, 0.7])                          # only 2 elements left
    assert [round(float(gl.getUniform(p, gl.getUniformLocation(p, f"a[{i}]"))), 6)
            for i in range(4)] == [0.1, 0.2, 0.9, 0.8]
    gl.uniform1fv(l0, [])
    assert error(gl) == gl.INVALID_VALUE
    gl.uniform1f(l0, 1.0)
    gl.uniform2fv(l0, [1, 2])                                  # wrong type
    assert error(gl) == gl.INVALID_OPERATION
    p = program(gl, VS, frag("uniform vec3 v[2];", "vec4(v[1], 1.0)"))
    gl.uniform3fv(gl.getUniformLocation(p, "v"), [0, 0, 0, 0.2, 0.4, 0.6, 9, 9])   # not a multiple of 3
    assert error(gl) == gl.INVALID_VALUE


def test_uniform_bool_from_every_setter(version):
    # gl-uniform-bool: bools may be set with uniform1i and uniform1f; non-zero is true.
    gl = context(version=version)
    p = program(gl, VS, frag("uniform bool b;", "b ? vec4(0, 1, 0, 1) : vec4(1, 0, 0, 1)"),
                {"aPos": 0})
    attribute(gl, 0, QUAD, 2)
    loc = gl.getUniformLocation(p, "b")
    for setter, val, want in ((gl.uniform1i, 1, True), (gl.uniform1i, 0, False),
                              (gl.uniform1f, 0.5, True), (gl.uniform1f, 0.0, False),
                              (gl.uniform1i, -7, True)):
        setter(loc, val)
        assert error(gl) == gl.NO_ERROR
        assert gl.getUniform(p, loc) is want
        gl.drawArrays(gl.TRIANGLES, 0, 6)
        assert pixel(gl, 8, 8)[1] == (255 if want else 0)


def test_uniform_matrix_transpose_rule(version):
    # gl-uniformmatrix4fv: transpose=true is INVALID_VALUE in WebGL 1, allowed in WebGL 2
    # (ES 3.0 §2.12.6); a wrong-length array is INVALID_VALUE; the matrix setters only fit
    # their own type.
    gl = context(version=version)
    p = program(gl, VS, frag("uniform mat4 m; uniform mat2 m2;", "m[0] + m2[0].xyxy"))
    m, m2 = gl.getUniformLocation(p, "m"), gl.getUniformLocation(p, "m2")
    vals = np.arange(16, dtype=np.float32)
    gl.uniformMatrix4fv(m, False, vals)
    assert error(gl) == gl.NO_ERROR
    np.testing.assert_array_equal(gl.getUniform(p, m), vals)
    gl.uniformMatrix4fv(m, True, vals)
    if version == 1:
        assert error(gl) == gl.INVALID_VALUE
        np.testing.assert_array_equal(gl.getUniform(p, m), vals)
    else:
        assert error(gl) == gl.NO_ERROR
        np.testing.assert_array_equal(gl.getUniform(p, m), vals.reshape(4, 4).T.ravel())
    gl.uniformMatrix4fv(m, False, vals[:15])
    assert error(gl) == gl.INVALID_VALUE
    gl.uniformMatrix2fv(m, False, vals[:4])
    assert error(gl) == gl.INVALID_OPERATION
    gl.uniformMatrix2fv(m2, False, vals[:4])
    assert error(gl) == gl.NO_ERROR


def test_unknown_and_null_locations(version):
    # gl-unknown-uniform, null-uniform-location: unknown names give None (no error); every
    # setter with None is a silent no-op.
    gl = context(version=version)
    p = program(gl, VS, frag("uniform vec4 u; uniform float unused;", "u"))
    assert gl.getUniformLocation(p, "nothere") is None
    assert gl.getUniformLocation(p, "unused") is None                  # optimised away / inactive
    assert error(gl) == gl.NO_ERROR
    for call, args in ((gl.uniform1f, (1.0,)), (gl.uniform4f, (1, 2, 3, 4)),
                       (gl.uniform1i, (1,)), (gl.uniform4fv, ([1, 2, 3, 4],)),
                       (gl.uniform2iv, ([1, 2],)),
                       (gl.uniformMatrix2fv, (False, [1, 2, 3, 4])),
                       (gl.uniformMatrix4fv, (False, np.zeros(16, np.float32)))):
        call(None, *args)
        assert error(gl) == gl.NO_ERROR, call


@pytest.mark.parametrize("decl,query,zero", [
    ("float u;", "u", 0.0), ("vec4 u;", "u", [0, 0, 0, 0]), ("int u;", "u", 0),
    ("ivec3 u;", "u", [0, 0, 0]), ("bool u;", "u", False), ("bvec2 u;", "u", [False, False]),
    ("mat3 u;", "u", [0] * 9), ("float u[3];", "u[2]", 0.0), ("sampler2D u;", "u", 0)])
def test_uniform_default_values(version, decl, query, zero):
    # uniform-default-values: every uniform starts at zero (ES 2.0 §2.10.4) and returns to zero
    # on relink.
    gl = context(version=version)
    use = {"sampler2D u;": "texture2D(u, vec2(0.5))", "mat3 u;": "vec4(u[0], 1.0)",
           "float u[3];": "vec4(u[2])", "bvec2 u;": "vec4(float(u.x))",
           "ivec3 u;": "vec4(float(u.x))", "int u;": "vec4(float(u))", "bool u;": "vec4(float(u))",
           "float u;": "vec4(u)", "vec4 u;": "u"}[decl]
    p = program(gl, VS, frag("uniform " + decl, use))
    v = gl.getUniform(p, gl.getUniformLocation(p, query))
    if isinstance(zero, list):
        assert list(v) == zero
    else:
        assert v == zero and type(v) is type(zero) if not isinstance(zero, float) else v == zero


def test_uniform_location_belongs_to_its_program_and_link(version):
    # uniform-location: a location used with another program, or after its program relinked,
    # is INVALID_OPERATION; locations are equal only to themselves.
    gl = context(version=version)
    fs = frag("uniform vec4 u;", "u")
    p1 = program(gl, VS, fs)
    p2 = program(gl, VS, fs)
    l1, l2 = gl.getUniformLocation(p1, "u"), gl.getUniformLocation(p2, "u")
    gl.useProgram(p2)
    gl.uniform4f(l1, 1, 2, 3, 4)
    assert error(gl) == gl.INVALID_OPERATION
    gl.getUniform(p2, l1)
    assert error(gl) == gl.INVALID_OPERATION
    gl.uniform4f(l2, 1, 2, 3, 4)
    assert error(gl) == gl.NO_ERROR
    gl.linkProgram(p2)
    gl.uniform4f(l2, 1, 2, 3, 4)
    assert error(gl) == gl.INVALID_OPERATION                         # stale after relink
    gl.uniform4f(gl.getUniformLocation(p2, "u"), 1, 2, 3, 4)
    assert error(gl) == gl.NO_ERROR


def test_uniform_values_are_per_program(version):
    # uniform-values-per-program
    gl = context(version=version)
    fs = frag("uniform vec4 u;", "u")
    p1, p2 = program(gl, VS, fs, {"aPos": 0}), program(gl, VS, fs, {"aPos": 0})
    attribute(gl, 0, QUAD, 2)
    gl.useProgram(p1)
    gl.uniform4f(gl.getUniformLocation(p1, "u"), 1, 0, 0, 1)
    gl.useProgram(p2)
    gl.uniform4f(gl.getUniformLocation(p2, "u"), 0, 0, 1, 1)
    gl.useProgram(p1)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 4, 4) == (255, 0, 0, 255)
    gl.useProgram(p2)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 4, 4) == (0, 0, 255, 255)


def test_sampler_uniform_rules(version):
    # uniform-samplers-test: samplers take uniform1i/1iv only (others INVALID_OPERATION) and a
    # unit outside [0, MAX_COMBINED_TEXTURE_IMAGE_UNITS) is INVALID_VALUE.
    gl = context(version=version)
    p = program(gl, VS, frag("uniform sampler2D s;", "texture2D(s, vec2(0.5))"))
    loc = gl.getUniformLocation(p, "s")
    n = gl.getParameter(gl.MAX_COMBINED_TEXTURE_IMAGE_UNITS)
    gl.uniform1i(loc, n - 1)
    assert error(gl) == gl.NO_ERROR and gl.getUniform(p, loc) == n - 1
    gl.uniform1iv(loc, [2])
    assert error(gl) == gl.NO_ERROR and gl.getUniform(p, loc) == 2
    for bad in (n, -1):
        gl.uniform1i(loc, bad)
        assert error(gl) == gl.INVALID_VALUE
    gl.uniform1f(loc, 1.0)
    assert error(gl) == gl.INVALID_OPERATION
    assert gl.getUniform(p, loc) == 2


def test_unused_array_elements_and_struct_uniforms(version):
    # gl-uniform-unused-array-elements-get-truncated, gl-uniform-struct-unused: the size reported
    # for an array is at least the highest used index + 1; elements past it have no location;
    # struct members are reported by their full name.
    gl = context(version=version)
    p = program(gl, VS, frag("uniform vec4 a[8]; struct S { float x; vec4 y; }; uniform S s;",
                             "a[3] + s.y"))
    infos = {gl.getActiveUniform(p, i).name: gl.getActiveUniform(p, i)
             for i in range(gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS))}
    assert 4 <= infos["a[0]"].size <= 8
    for i in range(infos["a[0]"].size):
        assert gl.getUniformLocation(p, f"a[{i}]") is not None
    assert gl.getUniformLocation(p, "a[8]") is None
    assert "s.y" in infos and gl.getUniformLocation(p, "s.y") is not None


def test_out_of_bounds_uniform_array_index_is_safe(version):
    # out-of-bounds-uniform-array-access: a dynamic index past the end must not crash; the value
    # read is undefined but must be one of the array's values or 0 (WebGL robust access).
    gl = context(version=version)
    p = program(gl, VS, frag("uniform vec4 a[2]; uniform int i;", "a[i]"), {"aPos": 0})
    attribute(gl, 0, QUAD, 2)
    gl.uniform4fv(gl.getUniformLocation(p, "a"), [0, 1, 0, 1, 0, 0, 1, 1])
    for i in (-1000000, -1, 2, 3, 1 << 30):
        gl.uniform1i(gl.getUniformLocation(p, "i"), i)
        gl.drawArrays(gl.TRIANGLES, 0, 6)
        assert error(gl) == gl.NO_ERROR
        assert pixel(gl, 4, 4) in ((0, 255, 0, 255), (0, 0, 255, 255), (0, 0, 0, 0))
