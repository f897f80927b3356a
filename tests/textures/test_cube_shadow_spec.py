"""The sampler's block paths for cube maps (cube_block8: faces of 8 lanes at once, one level choice
per block, each face filtered by the shaped block filter, 8-bit unorm faces by the fixed-point
rule) and for depth comparison (depth_block8: LINEAR = four compares and the bilinear weights of
8 lanes at once) against expectations computed here in float64 from the specification, lane by
lane, independently of softgl's code: ES 3.0 §3.8.10 (table 3.21, cube face selection and the
face coordinates s = (sc / |ma| + 1) / 2, t = (tc / |ma| + 1) / 2), eq. 3.20 (LINEAR), §3.8.11
(a level blend at lambda), §3.8.16 (the comparison, fixed-point references clamped to [0, 1]),
eq. 2.1 (fixed-point depths), and the README's fixed-point rule for 8-bit unorm LINEAR (8-bit
weights round(256 a), integer sums divided by 255 * 65536). Every image is also drawn by every
sampler path (general, fast scalar, AVX2 blocks, best SIMD) and compared bit for bit
(test_sampling_simd_lanes.render_all_paths)."""
import numpy as np
import pytest

import softgl
from helpers import float_target
from test_sampling_fast_path import set_params
from test_sampling_simd_lanes import H, W, face_spec, lanes_fs, render_all_paths

RNG = np.random.default_rng(3810)
SIZE = 16   # the cube's level 0: 16 x 16 per face


def cube_rgba8(gl, size, levels):
    """A cube map of random RGBA8 texels, `levels` levels; returns [level][face] (size, size, 4) uint8."""
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, tex)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    images = []
    for level in range(levels):
        s = size >> level
        faces = [RNG.integers(0, 256, (s, s, 4), dtype=np.uint8) for _ in range(6)]
        for face, data in enumerate(faces):
            gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, level, gl.RGBA8, s, s, 0, gl.RGBA, gl.UNSIGNED_BYTE, data)
        images.append(faces)
    return images


def interior_directions(n, size):
    """Random directions (x, y, z, inactive) whose LINEAR footprint on a size x size face lies
    inside the face (no seams), on all six faces, a few lanes inactive."""
    face = RNG.integers(0, 6, n)
    # Face coordinates away from the edges by more than a texel, and a random |ma|.
    s = RNG.uniform(1.5 / size, 1 - 1.5 / size, n)
    t = RNG.uniform(1.5 / size, 1 - 1.5 / size, n)
    ma = RNG.uniform(0.3, 4.0, n)
    sc, tc = (2 * s - 1) * ma, (2 * t - 1) * ma
    # Table 3.21 inverted: (sc, tc, ma) -> (rx, ry, rz) per face.
    x = np.choose(face, [ma, -ma, sc, sc, sc, -sc])
    y = np.choose(face, [-tc, -tc, ma, -ma, -tc, -tc])
    z = np.choose(face, [-sc, sc, tc, -tc, ma, -ma])
    inactive = (RNG.integers(0, 17, n) == 0).astype(np.float64)
    return np.stack([x, y, z, inactive], -1).astype(np.float32).reshape(H, W, 4)


def fixed_point_linear(img, s, t):
    """The README's 8-bit unorm LINEAR rule in float64 / exact integers: eq. 3.20's texels and
    fractions, weights A = round(256 a), B = round(256 b) (ties to even), the integer sum divided
    by 255 * 65536 and rounded to float32 (CLAMP_TO_EDGE within the face)."""
    size = img.shape[0]
    u, v = s * size - 0.5, t * size - 0.5
    i0, j0 = np.floor(u).astype(np.int64), np.floor(v).astype(np.int64)
    a, b = u - i0, v - j0
    A, B = np.round(256 * a), np.round(256 * b)
    c = lambda k: np.clip(k, 0, size - 1)
    k = img.astype(np.float64)
    total = ((256 - A) * (256 - B))[:, None] * k[c(j0), c(i0)] + (A * (256 - B))[:, None] * k[c(j0), c(i0 + 1)] + \
            ((256 - A) * B)[:, None] * k[c(j0 + 1), c(i0)] + (A * B)[:, None] * k[c(j0 + 1), c(i0 + 1)]
    return (total / (255 * 65536)).astype(np.float32), A, B


def cube_expectation(images, level, lanes):
    """Per lane: the face by table 3.21 (float64), s and t, the filtered value on that face."""
    x, y, z = (lanes[..., k].reshape(-1).astype(np.float64) for k in range(3))
    face, s, t = face_spec(x, y, z)
    out = np.zeros((x.size, 4), np.float32)
    weights = np.zeros((x.size, 2))
    for f in range(6):
        sel = face == f
        out[sel], A, B = fixed_point_linear(images[level][f], s[sel], t[sel])
        weights[sel] = np.stack([A, B], -1)
    return out.reshape(H, W, 4), face.reshape(H, W)


def test_cube_linear_rgba8_against_the_spec():
    # LINEAR without mipmaps: one fixed filter (cube_block8's FixedLinear blocks).
    gl = softgl.Context(8, 8, antialias=False)
    float_target(gl, W, H)
    images = cube_rgba8(gl, SIZE, 1)
    set_params(gl, gl.TEXTURE_CUBE_MAP, "LINEAR", "LINEAR", "CLAMP_TO_EDGE", "CLAMP_TO_EDGE")
    lanes = interior_directions(W * H, SIZE)
    img = render_all_paths(gl, lanes_fs("samplerCube", "texture(tex, c.xyz)"), lanes)
    expected, face = cube_expectation(images, 0, lanes)
    active = lanes[..., 3] < 0.5
    assert len(np.unique(face[active])) == 6
    # softgl's s, t (float32, 1 / |ma| then a product) may round a fraction differently from
    # float64 at a weight's rounding tie: then one weight differs by 1/256 (at most 1/256 in the
    # value). Everywhere else the same integer sum: the same float32.
    diff = np.abs(img[active] - expected[active])
    assert diff.max() <= 1 / 256 + 1e-7
    exact = (img[active] == expected[active]).all(-1).mean()
    assert exact > 0.99, exact


def test_cube_trilinear_rgba8_against_the_spec():
    # LINEAR_MIPMAP_LINEAR at an explicit lambda of 0.25: levels 0 and 1 blended 3 : 1
    # ((1 - f) a + f b in float32, §3.8.11), one level choice for each block of 8 lanes
    # (cube_block8's PerBlock blocks).
    gl = softgl.Context(8, 8, antialias=False)
    float_target(gl, W, H)
    images = cube_rgba8(gl, SIZE, 2)
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAX_LEVEL, 1)
    set_params(gl, gl.TEXTURE_CUBE_MAP, "LINEAR_MIPMAP_LINEAR", "LINEAR", "CLAMP_TO_EDGE", "CLAMP_TO_EDGE")
    lanes = interior_directions(W * H, SIZE // 2)   # inside the face at both levels
    img = render_all_paths(gl, lanes_fs("samplerCube", "textureLod(tex, c.xyz, 0.25)"), lanes)
    level0, _ = cube_expectation(images, 0, lanes)
    level1, _ = cube_expectation(images, 1, lanes)
    f = np.float32(0.25)
    expected = (np.float32(1) - f) * level0 + f * level1
    active = lanes[..., 3] < 0.5
    diff = np.abs(img[active] - expected[active])
    assert diff.max() <= 1 / 256 + 1e-6
    assert (diff <= 1e-7).all(-1).mean() > 0.98


# ---------------------------------------------------------------------------- LINEAR depth compare

TS = 32   # the depth texture: 32 x 32 DEPTH_COMPONENT24


@pytest.mark.parametrize("func", ["LEQUAL", "GREATER"])
def test_shadow_linear_against_the_spec(func):
    gl = softgl.Context(8, 8, antialias=False)
    float_target(gl, W, H)
    words = RNG.integers(0, 2 ** 24, (TS, TS), dtype=np.uint64)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.DEPTH24_STENCIL8, TS, TS, 0, gl.DEPTH_STENCIL, gl.UNSIGNED_INT_24_8,
                  (words << np.uint64(8)).astype(np.uint32))
    depths = (words.astype(np.float64) / (2 ** 24 - 1)).astype(np.float32).astype(np.float64)   # eq. 2.1
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_FUNC, getattr(gl, func))
    set_params(gl, gl.TEXTURE_2D, "LINEAR", "LINEAR", "CLAMP_TO_EDGE", "CLAMP_TO_EDGE")
    n = W * H
    s, t = RNG.uniform(-0.1, 1.1, n), RNG.uniform(-0.1, 1.1, n)
    ref = RNG.uniform(-0.2, 1.2, n)
    inactive = (RNG.integers(0, 17, n) == 0).astype(np.float64)
    lanes = np.stack([s, t, ref, inactive], -1).astype(np.float32).reshape(H, W, 4)
    img = render_all_paths(gl, lanes_fs("sampler2DShadow", "texture(tex, c.xyz)"), lanes)
    # Eq. 3.20 with each texel replaced by its comparison's 1 or 0 (§3.8.16; the reference of a
    # fixed-point format clamped to [0, 1]), CLAMP_TO_EDGE, in float64.
    s, t, ref = (lanes[..., k].reshape(-1).astype(np.float64) for k in range(3))
    u, v = s * TS - 0.5, t * TS - 0.5
    i0, j0 = np.floor(u).astype(np.int64), np.floor(v).astype(np.int64)
    a, b = u - i0, v - j0
    r = np.clip(ref, 0, 1)
    c = lambda k: np.clip(k, 0, TS - 1)
    passes = lambda j, i: (r <= depths[c(j), c(i)] if func == "LEQUAL" else r > depths[c(j), c(i)]).astype(np.float64)
    expected = ((1 - a) * (1 - b) * passes(j0, i0) + a * (1 - b) * passes(j0, i0 + 1) +
                (1 - a) * b * passes(j0 + 1, i0) + a * b * passes(j0 + 1, i0 + 1)).reshape(H, W)
    active = lanes[..., 3] < 0.5
    got = img[..., 0][active]
    assert 0.2 < (got == 1).mean() < 0.8 and ((got > 0) & (got < 1)).mean() > 0.1   # lit, shadowed, partial
    np.testing.assert_allclose(got, expected[active], rtol=0, atol=1e-6)
    # texture() of a shadow sampler is a float: vec4(r) in every channel.
    assert all(np.array_equal(img[..., 0][active], img[..., k][active]) for k in (1, 2, 3))
