"""The sampler's SIMD blocks (AVX2 blocks of 8, AVX-512 blocks of 16: channel-major results
straight into the registers, byte texels gathered) must give, lane by lane, the same bits as the
fast path's scalar reference (Fast2D::filter one lane at a time) and as the general path, for
random coordinates including NaN, infinities and huge values, every wrap mode, power-of-two and
other sizes, 2D arrays, every filter, mip levels chosen per lane, inactive lanes, and both
storages (8-bit unorm textures as bytes, their only storage; float textures as floats).
The lookups run through softgl._core.testing.sample_texture (one query, one TextureUnitSampler)."""
import numpy as np
import pytest

from softgl import _core

T = _core.testing
GL = {"NEAREST": 0x2600, "LINEAR": 0x2601, "NEAREST_MIPMAP_NEAREST": 0x2700, "LINEAR_MIPMAP_NEAREST": 0x2701,
      "NEAREST_MIPMAP_LINEAR": 0x2702, "LINEAR_MIPMAP_LINEAR": 0x2703,
      "REPEAT": 0x2901, "CLAMP_TO_EDGE": 0x812F, "MIRRORED_REPEAT": 0x8370}
MIN_FILTERS = ["NEAREST", "LINEAR", "NEAREST_MIPMAP_NEAREST", "LINEAR_MIPMAP_NEAREST",
               "NEAREST_MIPMAP_LINEAR", "LINEAR_MIPMAP_LINEAR"]
WRAPS = ["REPEAT", "CLAMP_TO_EDGE", "MIRRORED_REPEAT"]
SIZES = [(16, 16), (13, 7), (1, 5), (64, 32), (6, 1)]
SPECIAL = np.array([np.nan, np.inf, -np.inf, 1e30, -3e9, 0.5, 1.0, 0.0, -0.0], np.float32)
AVX2, AVX512 = 2, 3


def assert_same_bits(got, want, what):
    """Equal bits; a NaN equals any NaN (which NaN an operation on NaNs returns is unspecified)."""
    both_nan = np.isnan(got) & np.isnan(want)
    bad = (np.where(both_nan, 0, got.view(np.uint32)) != np.where(both_nan, 0, want.view(np.uint32))).any(axis=0)
    assert not bad.any(), f"{what}: lanes {np.nonzero(bad)[0][:8]} differ: {got[:, bad][:, :4]} vs {want[:, bad][:, :4]}"


def mip_chain(rng, w, h, layers, unorm8):
    levels = []
    while True:
        if unorm8:
            levels.append(rng.integers(0, 256, (layers, h, w, 4)).astype(np.float32))
        else:
            levels.append(rng.uniform(-2, 3, (layers, h, w, 4)).astype(np.float32))
        if w == 1 and h == 1:
            return levels
        w, h = max(w // 2, 1), max(h // 2, 1)


def lanes(rng, n, scale):
    """Coordinates in about [-1.5, 2.5] with some specials; derivatives of every size."""
    s = rng.uniform(-1.5, 2.5, n).astype(np.float32)
    special = rng.random(n) < 0.08
    s[special] = rng.choice(SPECIAL, special.sum())
    d = (rng.choice([0.0, 1e-3, 0.02, 0.3, 3.0], n) * rng.uniform(-scale, scale, n)).astype(np.float32)
    return s, d


def run(path, simd, case):
    out, fast = T.sample_texture(path, simd, **case)
    return out, fast


def random_case(seed):
    rng = np.random.default_rng(seed)
    w, h = SIZES[seed % len(SIZES)]
    layers = 3 if seed % 4 == 3 else 1
    unorm8 = seed % 5 != 4
    n = int(rng.choice([8, 16, 61, 128, 133]))
    s, dsx = lanes(rng, n, 1.0)
    t, dty = lanes(rng, n, 1.0)
    layer = rng.uniform(-1, 4, n).astype(np.float32)
    # Derivatives: per quad as the executor makes them, or per lane (gradients).
    ddx = np.stack([dsx, rng.uniform(-0.05, 0.05, n).astype(np.float32)])
    ddy = np.stack([rng.uniform(-0.05, 0.05, n).astype(np.float32), dty])
    if seed % 3 == 0:   # one derivative for every lane of a block: blocks that share their levels
        ddx[:] = ddx[:, :1]
        ddy[:] = ddy[:, :1]
    active = rng.random(n) < (0.9 if seed % 2 else 1.0)
    if n >= 16 and seed % 7 == 0:
        active[:16] = False   # a whole block inactive
    params = {"min_filter": GL[MIN_FILTERS[seed % 6]], "mag_filter": GL["LINEAR" if seed % 12 < 6 else "NEAREST"],
              "wrap_s": GL[WRAPS[seed % 3]], "wrap_t": GL[WRAPS[(seed // 3) % 3]]}
    if seed % 8 == 5:
        params.update(min_lod=0.75, max_lod=2.5)
    mode = ["implicit", "bias", "explicit", "gradient"][(seed // 2) % 4]
    lod = rng.uniform(-1.5, 4.5, n).astype(np.float32)
    if mode == "explicit" and seed % 3 == 0:
        lod[:] = lod[0]
    offset = (int(rng.integers(-3, 4)), int(rng.integers(-3, 4))) if seed % 5 == 1 else (0, 0)
    return dict(levels=mip_chain(rng, w, h, layers, unorm8), unorm8=unorm8, params=params,
                coords=np.stack([s, t, layer]), lod_mode=mode, lod=lod, ddx=ddx, ddy=ddy,
                active=active.astype(np.uint8), offset=offset)


@pytest.mark.parametrize("seed", range(240))
def test_simd_blocks_equal_the_scalar_reference_lane_by_lane(seed):
    case = random_case(seed)
    scalar, fast = run("scalar", 0, case)
    # (A query without active lanes goes to the general path.)
    assert fast or not case["active"].any(), "the fast path must serve the query"
    general, _ = run("general", 0, case)
    assert_same_bits(scalar, general, "fast scalar vs general")
    avx2, fast = run("avx2", AVX2, case)
    assert fast or not case["active"].any()
    assert_same_bits(avx2, scalar, "AVX2 blocks vs scalar")
    best, _ = run("best", AVX512, case)
    assert_same_bits(best, scalar, f"best ({T.simd_level()}) vs scalar")
    # Inactive lanes give (0, 0, 0, 1) on every path.
    off = case["active"] == 0
    np.testing.assert_array_equal(avx2[:, off], np.array([[0], [0], [0], [1]], np.float32).repeat(off.sum(), 1))


@pytest.mark.parametrize("min_filter", ["NEAREST", "LINEAR", "LINEAR_MIPMAP_LINEAR"])
def test_unorm8_blocks_are_the_fixed_point_rule(min_filter):
    """Bilinear of bytes k: ((256-A)(256-B) k00 + A(256-B) k10 + (256-A)B k01 + AB k11) / (255 * 65536)
    with A = round(256 a), B = round(256 b) (README "Choices"), NEAREST k / 255, computed here in
    float64 (exact) and rounded once; trilinear blends two such levels in float32."""
    rng = np.random.default_rng(5)
    w = h = 8
    levels = mip_chain(rng, w, h, 1, True)
    n = 64
    s = rng.uniform(-0.5, 1.5, n).astype(np.float32)
    t = rng.uniform(-0.5, 1.5, n).astype(np.float32)
    filt = GL[min_filter]
    case = dict(levels=levels, unorm8=True,
                params={"min_filter": filt, "mag_filter": filt if filt < 0x2700 else GL["LINEAR"],
                        "wrap_s": GL["REPEAT"], "wrap_t": GL["REPEAT"]},
                coords=np.stack([s, t, np.zeros(n, np.float32)]), lod_mode="explicit",
                lod=np.full(n, 0.375 if filt > 0x2700 else 0.0, np.float32),
                ddx=np.zeros((2, n), np.float32), ddy=np.zeros((2, n), np.float32),
                active=np.ones(n, np.uint8), offset=(0, 0))

    def level_value(k, lvl):
        size = levels[lvl].shape[1]
        u = s.astype(np.float32) * np.float32(size)
        v = t.astype(np.float32) * np.float32(size)
        tex = levels[lvl][0].astype(np.float64)
        if filt == GL["NEAREST"]:
            i, j = np.floor(u).astype(int) % size, np.floor(v).astype(int) % size
            return (tex[j, i] / 255).astype(np.float32).T
        u0, v0 = (u - np.float32(0.5)).astype(np.float32), (v - np.float32(0.5)).astype(np.float32)
        i0, j0 = np.floor(u0).astype(int), np.floor(v0).astype(int)
        A = np.clip(np.round((u0 - np.floor(u0)) * 256), 0, 256)[:, None]
        B = np.clip(np.round((v0 - np.floor(v0)) * 256), 0, 256)[:, None]
        t00, t10 = tex[j0 % size, i0 % size], tex[j0 % size, (i0 + 1) % size]
        t01, t11 = tex[(j0 + 1) % size, i0 % size], tex[(j0 + 1) % size, (i0 + 1) % size]
        total = (256 - A) * (256 - B) * t00 + A * (256 - B) * t10 + (256 - A) * B * t01 + A * B * t11
        return (total / (255 * 65536)).astype(np.float32).T

    want = level_value(None, 0)
    if filt == GL["LINEAR_MIPMAP_LINEAR"]:
        g = np.float32(0.375)
        want = (np.float32(1) - g) * want + g * level_value(None, 1)
    for path, simd in (("scalar", 0), ("avx2", AVX2), ("best", AVX512)):
        got, fast = run(path, simd, case)
        assert fast
        np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32), err_msg=path)
