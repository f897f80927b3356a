"""Two shortcuts of a texture lookup, against independent expected values:

- the last 1-7 lanes of a query, which the block loops filter as one padded block of 8 (the lanes
  beyond inactive, their results dropped; sampler.cpp, sample_2d): every lane count from 1 to 23
  against the spec's filters in float64 (test_sampler_shapes.spec_level) and against the general
  path lane by lane;
- a lookup whose result a Mov copies to an output or variable before any control flow, which
  writes that register itself (executor.cpp, fuse_texture_moves): drawn through the API with
  shaders where it applies and where it must not (a branch, the destination read before the
  copy, the coordinate overwritten by the result), each pixel the texel's bytes."""
import zlib

import numpy as np
import pytest

import softgl
from softgl import _core
from test_sampler_shapes import AVX2, AVX512, GL, assert_same_bits, mip_chain, shape_case, spec_level

T = _core.testing


@pytest.mark.parametrize("unorm8", [True, False], ids=["bytes", "floats"])
@pytest.mark.parametrize("wrap", ["REPEAT", "CLAMP_TO_EDGE"])
@pytest.mark.parametrize("filt", ["NEAREST", "LINEAR", "LINEAR_MIPMAP_LINEAR"])
def test_every_lane_count_is_the_spec_filters(unorm8, wrap, filt):
    rng = np.random.default_rng(23)
    levels = mip_chain(rng, 32, 16, unorm8)
    mip = "MIPMAP" in filt
    linear = filt.startswith("LINEAR")
    for n in range(1, 24):
        # Coordinates on a grid of 1/1024 (exact in float32 and float64), explicit LOD 1.25 on
        # mipmapped textures (levels 1 and 2 blended by 0.25, ES 3.0 §3.8.11.2).
        s = (rng.integers(-1024, 2048, n) / 1024).astype(np.float32)
        t = (rng.integers(-1024, 2048, n) / 1024).astype(np.float32)
        case = dict(levels=levels, unorm8=unorm8,
                    params={"min_filter": GL[filt], "mag_filter": GL["LINEAR" if linear else "NEAREST"],
                            "wrap_s": GL[wrap], "wrap_t": GL[wrap]},
                    coords=np.stack([s, t, np.zeros(n, np.float32)]), lod_mode="explicit",
                    lod=np.full(n, 1.25 if mip else 0.0, np.float32), ddx=np.zeros((2, n), np.float32),
                    ddy=np.zeros((2, n), np.float32), active=np.ones(n, np.uint8), offset=(0, 0))
        if mip:
            want = 0.75 * spec_level(levels[1], s, t, linear, wrap, unorm8) + 0.25 * spec_level(levels[2], s, t, linear, wrap, unorm8)
        else:
            want = spec_level(levels[0], s, t, linear, wrap, unorm8)
        for path, simd in (("avx2", AVX2), ("best", AVX512)):
            got, fast = T.sample_texture(path, simd, **case)
            assert fast
            if unorm8 and not mip:
                np.testing.assert_array_equal(got, want.astype(np.float32), err_msg=f"{path}, {n} lanes")
            else:
                np.testing.assert_allclose(got, want, rtol=0, atol=4e-7 * max(1.0, float(np.abs(want).max())),
                                           err_msg=f"{path}, {n} lanes")


@pytest.mark.parametrize("unorm8", [True, False], ids=["bytes", "floats"])
@pytest.mark.parametrize("filters", [("NEAREST", "NEAREST"), ("LINEAR_MIPMAP_LINEAR", "LINEAR"), ("LINEAR", "NEAREST")],
                         ids=lambda f: "/".join(f))
@pytest.mark.parametrize("mode", ["implicit", "bias", "explicit"])
def test_every_lane_count_equals_the_general_path(unorm8, filters, mode):
    """Random coordinates with NaN and infinities, inactive lanes, derivatives per lane or per quad."""
    rng = np.random.default_rng(zlib.crc32(repr((unorm8, filters, mode)).encode()))
    for n in list(range(1, 24)) + [37, 133]:
        for quad_derivatives in (True, False):
            case = shape_case(rng, unorm8, "REPEAT", filters, (32, 16), mode, n=n, quad_derivatives=quad_derivatives)
            general, _ = T.sample_texture("general", 0, **case)
            for path, simd in (("avx2", AVX2), ("best", AVX512)):
                got, fast = T.sample_texture(path, simd, **case)
                assert fast or not case["active"].any()   # (no active lane: no unit, the general path)
                assert_same_bits(got, general, f"{path}, {n} lanes")


# ---- the texture lookup written straight into the Mov's register

VS = """#version 300 es
in vec2 aPos;
out vec2 vUV;
void main() { vUV = aPos * 0.5 + 0.5; gl_Position = vec4(aPos, 0.0, 1.0); }
"""
FRAGMENT_BODIES = {
    # applies: the result copied to the output
    "copy": "fragColor = texture(uTex, vUV);",
    # applies: through a variable, swizzled back
    "variable": "vec4 c = texture(uTex, vUV).wzyx; fragColor = c.wzyx;",
    # not after control flow: under a branch the left half of the canvas skips (it keeps 0.5)
    "branch": "fragColor = vec4(0.5); if (vUV.x >= 0.5) { fragColor = texture(uTex, vUV); }",
    # the destination read between the lookup and the copy
    "read_between": "fragColor = vec4(0.25); vec4 c = texture(uTex, vUV); vec4 old = fragColor; fragColor = c + old - old;",
    # the coordinate variable overwritten by the lookup's result
    "coordinate": "vec2 uv = vUV; vec4 c = texture(uTex, uv); uv = c.xy; fragColor = vec4(uv, c.zw);",
}


@pytest.mark.parametrize("body", sorted(FRAGMENT_BODIES))
@pytest.mark.parametrize("simd", ["scalar", "sse2", "avx2", "avx512"])
def test_a_copied_lookup_gives_the_texels(body, simd):
    """A 16x16 canvas over a 16x16 NEAREST texture: pixel (x, y) samples texel (x, y) at its centre."""
    fs = f"""#version 300 es
precision highp float;
uniform sampler2D uTex;
in vec2 vUV;
out vec4 fragColor;
void main() {{ {FRAGMENT_BODIES[body]} }}
"""
    gl = softgl.Context(16, 16, threads=1, strict=True)
    T.set_tuning(gl, simd=simd)
    prog = gl.createProgram()
    for kind, src in ((gl.VERTEX_SHADER, VS), (gl.FRAGMENT_SHADER, fs)):
        sh = gl.createShader(kind)
        gl.shaderSource(sh, src)
        gl.compileShader(sh)
        assert gl.getShaderParameter(sh, gl.COMPILE_STATUS), gl.getShaderInfoLog(sh)
        gl.attachShader(prog, sh)
    gl.linkProgram(prog)
    assert gl.getProgramParameter(prog, gl.LINK_STATUS), gl.getProgramInfoLog(prog)
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 1, -1, 1, 1, -1, -1, 1, 1, -1, 1], np.float32), gl.STATIC_DRAW)
    loc = gl.getAttribLocation(prog, "aPos")
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    texels = np.random.default_rng(4).integers(0, 256, (16, 16, 4)).astype(np.uint8)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 16, 16, 0, gl.RGBA, gl.UNSIGNED_BYTE, texels)
    for pname in (gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER):
        gl.texParameteri(gl.TEXTURE_2D, pname, gl.NEAREST)
    gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 0)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    got = gl.readPixels(0, 0, 16, 16, gl.RGBA, gl.UNSIGNED_BYTE)
    # readPixels row 0 is the bottom row, as is texture row 0 (t = 0).
    want = texels.copy()
    if body == "branch":
        want[:, :8] = 128   # float_to_unorm8(0.5) = round(127.5)
    np.testing.assert_array_equal(got, want)
