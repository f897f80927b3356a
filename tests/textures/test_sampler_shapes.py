"""The sampler's block loops specialised by query shape (sampler.cpp, colour_blocks8_shaped and
colour_blocks16_shaped: storage bytes / floats, REPEAT of power-of-two sizes or CLAMP_TO_EDGE on
both axes, one fixed filter or levels chosen per block) against the general block loop, the fast
path's scalar reference and the general path (same bits, lane by lane), and against the spec's
filters computed here in float64 (ES 3.0 §3.8.10-11; 8-bit unorm LINEAR: the fixed-point rule of
README "Choices"). Every shape is covered for both storages: test_sampler_blocks' random cases
reach float textures only at sizes that are not powers of two."""
import zlib

import numpy as np
import pytest

from softgl import _core

T = _core.testing
GL = {"NEAREST": 0x2600, "LINEAR": 0x2601, "NEAREST_MIPMAP_NEAREST": 0x2700, "LINEAR_MIPMAP_NEAREST": 0x2701,
      "NEAREST_MIPMAP_LINEAR": 0x2702, "LINEAR_MIPMAP_LINEAR": 0x2703,
      "REPEAT": 0x2901, "CLAMP_TO_EDGE": 0x812F, "MIRRORED_REPEAT": 0x8370}
AVX2, AVX512 = 2, 3
# (min, mag): fixed NEAREST, fixed LINEAR, levels per block (trilinear, one filter each way, or the
# filter changing between magnified and minified blocks), and a nearest-level choice (lane by lane).
FILTERS = [("NEAREST", "NEAREST"), ("LINEAR", "LINEAR"), ("LINEAR_MIPMAP_LINEAR", "LINEAR"),
           ("NEAREST_MIPMAP_LINEAR", "NEAREST"), ("LINEAR", "NEAREST"), ("LINEAR_MIPMAP_NEAREST", "LINEAR")]
SPECIAL = np.array([np.nan, np.inf, -np.inf, 1e30, -3e9, 0.5, 1.0, 0.0, -0.0], np.float32)


def assert_same_bits(got, want, what):
    both_nan = np.isnan(got) & np.isnan(want)
    bad = (np.where(both_nan, 0, got.view(np.uint32)) != np.where(both_nan, 0, want.view(np.uint32))).any(axis=0)
    assert not bad.any(), f"{what}: lanes {np.nonzero(bad)[0][:8]} differ: {got[:, bad][:, :4]} vs {want[:, bad][:, :4]}"


def mip_chain(rng, w, h, unorm8):
    levels = []
    while True:
        if unorm8:
            levels.append(rng.integers(0, 256, (1, h, w, 4)).astype(np.float32))
        else:
            levels.append(rng.uniform(-2, 3, (1, h, w, 4)).astype(np.float32))
        if w == 1 and h == 1:
            return levels
        w, h = max(w // 2, 1), max(h // 2, 1)


def shape_case(rng, unorm8, wrap, filters, size, mode, n=133, quad_derivatives=True):
    w, h = size
    s = rng.uniform(-1.5, 2.5, n).astype(np.float32)
    t = rng.uniform(-1.5, 2.5, n).astype(np.float32)
    for c in (s, t):
        special = rng.random(n) < 0.06
        c[special] = rng.choice(SPECIAL, special.sum())
    # Derivatives from about 1/4 to 6 texels per pixel: magnified and minified blocks, 1-3 levels.
    scale = rng.choice([0.25, 0.7, 1.5, 3.0, 6.0]) / max(w, h)
    ddx = np.stack([np.full(n, scale), np.zeros(n)]).astype(np.float32)
    ddy = np.stack([np.zeros(n), np.full(n, scale)]).astype(np.float32)
    if not quad_derivatives:
        ddx[0] *= rng.uniform(0.5, 2.0, n).astype(np.float32)
        ddy[1] *= rng.uniform(0.5, 2.0, n).astype(np.float32)
    active = (rng.random(n) < 0.9).astype(np.uint8)
    active[16:32] = 0   # a whole block of 16 inactive
    return dict(levels=mip_chain(rng, w, h, unorm8), unorm8=unorm8,
                params={"min_filter": GL[filters[0]], "mag_filter": GL[filters[1]], "wrap_s": GL[wrap], "wrap_t": GL[wrap]},
                coords=np.stack([s, t, np.zeros(n, np.float32)]), lod_mode=mode,
                lod=rng.uniform(-1.0, 4.0, n).astype(np.float32), ddx=ddx, ddy=ddy, active=active,
                offset=(int(rng.integers(-2, 3)), int(rng.integers(-2, 3))) if rng.random() < 0.3 else (0, 0))


@pytest.mark.parametrize("unorm8", [True, False], ids=["bytes", "floats"])
@pytest.mark.parametrize("wrap,size", [("REPEAT", (32, 16)), ("REPEAT", (1, 64)), ("CLAMP_TO_EDGE", (32, 16)),
                                       ("CLAMP_TO_EDGE", (13, 6)), ("REPEAT", (12, 16)), ("MIRRORED_REPEAT", (16, 16))])
@pytest.mark.parametrize("filters", FILTERS, ids=["/".join(f) for f in FILTERS])
@pytest.mark.parametrize("mode", ["implicit", "bias", "explicit"])
def test_shaped_blocks_equal_the_scalar_reference_and_the_general_path(unorm8, wrap, size, filters, mode):
    """REPEAT (12, 16) and MIRRORED_REPEAT take the general block loop: the same comparison."""
    rng = np.random.default_rng(zlib.crc32(repr((unorm8, wrap, size, filters, mode)).encode()))
    for quad_derivatives in (True, False):
        case = shape_case(rng, unorm8, wrap, filters, size, mode, quad_derivatives=quad_derivatives)
        scalar, fast = T.sample_texture("scalar", 0, **case)
        assert fast
        general, _ = T.sample_texture("general", 0, **case)
        assert_same_bits(scalar, general, "fast scalar vs general")
        avx2, fast = T.sample_texture("avx2", AVX2, **case)
        assert fast
        assert_same_bits(avx2, scalar, "AVX2 blocks vs scalar")
        best, _ = T.sample_texture("best", AVX512, **case)
        assert_same_bits(best, scalar, f"best ({T.simd_level()}) vs scalar")
        off = case["active"] == 0
        np.testing.assert_array_equal(best[:, off], np.array([[0], [0], [0], [1]], np.float32).repeat(off.sum(), 1))


def wrapped(i, size, wrap):
    """ES 3.0 table 3.19 for REPEAT and CLAMP_TO_EDGE."""
    return np.mod(i, size) if wrap == "REPEAT" else np.clip(i, 0, size - 1)


def spec_level(level, s, t, linear, wrap, unorm8):
    """One level filtered in float64 (ES 3.0 §3.8.11, eq. 3.20): u = s w, i = floor(u) (NEAREST),
    i0 = floor(u - 1/2) and weights from the fractions (LINEAR); 8-bit unorm LINEAR by the
    fixed-point rule (weights round(256 a), exact integer sum / (255 * 65536))."""
    tex = level[0].astype(np.float64)
    h, w = tex.shape[:2]
    u = s.astype(np.float64) * w   # exact: s float32 times a small power of two or integer
    v = t.astype(np.float64) * h
    if not linear:
        k = tex[wrapped(np.floor(v).astype(np.int64), h, wrap), wrapped(np.floor(u).astype(np.int64), w, wrap)]
        return (k / 255 if unorm8 else k).T
    u0, v0 = u - 0.5, v - 0.5
    i0, j0 = np.floor(u0).astype(np.int64), np.floor(v0).astype(np.int64)
    a, b = (u0 - np.floor(u0))[:, None], (v0 - np.floor(v0))[:, None]
    i1, j1 = wrapped(i0 + 1, w, wrap), wrapped(j0 + 1, h, wrap)
    i0, j0 = wrapped(i0, w, wrap), wrapped(j0, h, wrap)
    t00, t10, t01, t11 = tex[j0, i0], tex[j0, i1], tex[j1, i0], tex[j1, i1]
    if unorm8:
        A, B = np.clip(np.round(a * 256), 0, 256), np.clip(np.round(b * 256), 0, 256)
        total = (256 - A) * (256 - B) * t00 + A * (256 - B) * t10 + (256 - A) * B * t01 + A * B * t11
        return (total / (255 * 65536)).T
    return ((1 - a) * (1 - b) * t00 + a * (1 - b) * t10 + (1 - a) * b * t01 + a * b * t11).T


@pytest.mark.parametrize("unorm8", [True, False], ids=["bytes", "floats"])
@pytest.mark.parametrize("wrap", ["REPEAT", "CLAMP_TO_EDGE"])
@pytest.mark.parametrize("filt", ["NEAREST", "LINEAR", "LINEAR_MIPMAP_LINEAR", "NEAREST_MIPMAP_LINEAR"])
def test_shaped_blocks_are_the_spec_filters(unorm8, wrap, filt):
    """Finite coordinates, explicit LOD (lambda 1.25 on mipmapped textures: levels 1 and 2 blended
    by 0.25, ES 3.0 §3.8.11.2), every lane active, 128 lanes (blocks of 16 and 8)."""
    rng = np.random.default_rng(11)
    n = 128
    levels = mip_chain(rng, 32, 16, unorm8)
    # Coordinates on a grid of 1/1024: u = s w and the fractions are exact in float32 and float64.
    s = (rng.integers(-1024, 2048, n) / 1024).astype(np.float32)
    t = (rng.integers(-1024, 2048, n) / 1024).astype(np.float32)
    mip = "MIPMAP" in filt
    lam = 1.25 if mip else 0.0
    case = dict(levels=levels, unorm8=unorm8,
                params={"min_filter": GL[filt], "mag_filter": GL["NEAREST" if filt == "NEAREST" else "LINEAR"],
                        "wrap_s": GL[wrap], "wrap_t": GL[wrap]},
                coords=np.stack([s, t, np.zeros(n, np.float32)]), lod_mode="explicit",
                lod=np.full(n, lam, np.float32), ddx=np.zeros((2, n), np.float32), ddy=np.zeros((2, n), np.float32),
                active=np.ones(n, np.uint8), offset=(0, 0))
    linear = filt.startswith("LINEAR")
    if mip:
        want = 0.75 * spec_level(levels[1], s, t, linear, wrap, unorm8) + 0.25 * spec_level(levels[2], s, t, linear, wrap, unorm8)
    else:
        want = spec_level(levels[0], s, t, linear, wrap, unorm8)
    for path, simd in (("scalar", 0), ("avx2", AVX2), ("best", AVX512)):
        got, fast = T.sample_texture(path, simd, **case)
        assert fast
        if unorm8 and not mip:
            # One correctly rounded division of an exact integer sum (NEAREST: k / 255).
            np.testing.assert_array_equal(got, want.astype(np.float32), err_msg=path)
        else:
            # Float32 products, sums and the level blend: a few ulps of the float64 values.
            np.testing.assert_allclose(got, want, rtol=0, atol=4e-7 * max(1.0, float(np.abs(want).max())), err_msg=path)
