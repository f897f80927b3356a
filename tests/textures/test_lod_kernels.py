"""The fast path's LOD (ES 3.0 eq. 3.17-3.19): lambda = float(log2(rho)), rho = sqrt(rho²) with
rho² the larger squared length of the footprint, computed in double. The AVX2 (4 per vector) and
AVX-512 (8 per vector) kernels approximate log2 and keep a value only when a rounding test shows
that float() of the exact value is that float (else LambdaMemo, libm's log2): every SIMD level
must give the float64 formula's bits, and the vector kernels must vouch for nearly every value
themselves (else the test would only exercise the fallback). Then whole trilinear lookups with
per-lane (perspective) derivatives, through softgl._core.testing.sample_texture: every path and
SIMD level the same bits as the general path."""
import math

import numpy as np
import pytest

from softgl import _core

T = _core.testing
SIMD_LEVELS = [0, 1, 2, 3]   # scalar, sse2, avx2, avx512 (capped at what the CPU runs)
GL = {"LINEAR": 0x2601, "LINEAR_MIPMAP_LINEAR": 0x2703, "NEAREST_MIPMAP_LINEAR": 0x2702, "REPEAT": 0x2901,
      "CLAMP_TO_EDGE": 0x812F}


def reference_lambda(rho2: float) -> np.float32:
    """ES 3.0 eq. 3.18-3.19 in float64: log2(sqrt(rho²)); rho = 0 or NaN gives -inf (rho > 0 fails:
    magnification), as the general path."""
    if not rho2 > 0:
        return np.float32(-np.inf)
    return np.float32(math.log2(math.sqrt(rho2)))


def rho2_values(seed: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    parts = [
        np.exp2(rng.uniform(-290, 250, n)),                       # every exponent a footprint can have
        np.exp2(rng.uniform(-4, 24, n)),                          # the usual range (lambda -2 .. 12)
        4.0 ** rng.integers(-20, 20, n) * (1 + rng.uniform(-1e-12, 1e-12, n)),   # at level boundaries
        2.0 ** rng.integers(-40, 40, n) * (1 + rng.uniform(-1e-9, 1e-9, n)),     # at half levels
        1 + rng.uniform(-1e-7, 1e-7, n // 8),                     # lambda near 0
        np.array([0.0, -0.0, np.inf, np.nan, 1.0, 2.0, 0.5, 4.0, 5e-324, 1e308, 2.0 ** -298]),
    ]
    # Squares of float products summed in double, as the kernels form rho².
    x = rng.uniform(-70, 70, (2, n)).astype(np.float32).astype(np.float64)
    parts.append(x[0] ** 2 + x[1] ** 2)
    return np.concatenate(parts)


@pytest.mark.parametrize("simd", SIMD_LEVELS)
@pytest.mark.parametrize("seed", range(4))
def test_lambda_kernels_give_the_float64_formula_bits(simd, seed):
    rho2 = rho2_values(seed, 20000)
    want = np.array([reference_lambda(float(v)) for v in rho2], np.float32)
    got, _ = T.lod_lambdas(simd, rho2)
    bad = np.nonzero(got.view(np.uint32) != want.view(np.uint32))[0]
    assert bad.size == 0, f"simd {simd}: rho² {rho2[bad[:4]]} gave {got[bad[:4]]}, want {want[bad[:4]]}"


@pytest.mark.parametrize("simd", [2, 3])
def test_vector_kernels_vouch_for_nearly_every_value(simd):
    if T.simd_level() < simd:
        pytest.skip("the CPU does not run this SIMD level")
    rng = np.random.default_rng(7)
    rho2 = np.exp2(rng.uniform(-60, 60, 80000))
    got, sure = T.lod_lambdas(simd, rho2)
    assert sure >= 0.999 * rho2.size, f"only {sure} of {rho2.size} vouched for"
    # Not vouched for: values whose rounding the test cannot settle (lambda near 0 here).
    _, sure_near_one = T.lod_lambdas(simd, 1 + rng.uniform(-1e-9, 1e-9, 800))
    assert sure_near_one < 800


def perspective_case(seed, min_filter, wrap, mode):
    """Lanes in quads of a perspective view of a textured plane (the terrain scene's kind): per
    quad the executor's fine derivatives, different in every lane, lambda from -1 to 9."""
    rng = np.random.default_rng(seed)
    quads = 1200
    # Each quad: a screen position, texture coordinates s = a x / w, t = b y / w of the pixel.
    # Depth growing along the lanes, as along a row of a scene: neighbouring quads mostly on the
    # same levels, some blocks across a level boundary (halves of a block on different levels).
    depth = np.sort(np.exp2(rng.uniform(-1, 8, quads)))
    base = np.cumsum(rng.uniform(0, 0.02, (2, quads)), axis=1) - 1
    scale = rng.uniform(0.5, 2, (2, quads))
    px, py = np.array([0, 1, 0, 1]), np.array([0, 0, 1, 1])
    s = (base[0][:, None] + scale[0][:, None] * depth[:, None] * (px + rng.uniform(0, 1, (quads, 1))) / 512)
    t = (base[1][:, None] + scale[1][:, None] * depth[:, None] * (py + rng.uniform(0, 1, (quads, 1))) / 512)
    s = (s * (1 + 0.01 * py * rng.uniform(-1, 1, (quads, 1)))).astype(np.float32).ravel()
    t = (t * (1 + 0.01 * px * rng.uniform(-1, 1, (quads, 1)))).astype(np.float32).ravel()
    n = s.size

    def fine(v):
        q = v.reshape(-1, 4)
        dx = np.stack([q[:, 1] - q[:, 0], q[:, 1] - q[:, 0], q[:, 3] - q[:, 2], q[:, 3] - q[:, 2]], 1)
        dy = np.stack([q[:, 2] - q[:, 0], q[:, 3] - q[:, 1], q[:, 2] - q[:, 0], q[:, 3] - q[:, 1]], 1)
        return dx.ravel().astype(np.float32), dy.ravel().astype(np.float32)

    dsx, dsy = fine(s)
    dtx, dty = fine(t)
    levels, size = [], 64
    while size >= 1:
        levels.append(rng.integers(0, 256, (1, size, size, 4)).astype(np.float32))
        size //= 2
    active = (rng.random(n) < 0.95).astype(np.uint8)
    return dict(levels=levels, unorm8=True,
                params={"min_filter": GL[min_filter], "mag_filter": GL["LINEAR"], "wrap_s": GL[wrap], "wrap_t": GL[wrap]},
                coords=np.stack([s, t, np.zeros(n, np.float32)]), lod_mode=mode,
                lod=np.full(n, 0.37, np.float32),   # a bias, as a uniform gives it
                ddx=np.stack([dsx, dtx]), ddy=np.stack([dsy, dty]), active=active, offset=(0, 0))


@pytest.mark.parametrize("min_filter", ["LINEAR_MIPMAP_LINEAR", "NEAREST_MIPMAP_LINEAR"])
@pytest.mark.parametrize("wrap", ["REPEAT", "CLAMP_TO_EDGE"])
@pytest.mark.parametrize("mode", ["implicit", "bias"])
def test_perspective_trilinear_blocks_equal_the_general_path(min_filter, wrap, mode):
    case = perspective_case(3, min_filter, wrap, mode)
    general, _ = T.sample_texture("general", 0, **case)
    for path, simd in (("scalar", 0), ("avx2", 2), ("best", 2), ("best", 3)):
        got, fast = T.sample_texture(path, simd, **case)
        assert fast, f"{path} {simd}: the fast path must serve the query"
        bad = (got.view(np.uint32) != general.view(np.uint32)).any(axis=0)
        assert not bad.any(), f"{path} simd {simd}: lanes {np.nonzero(bad)[0][:8]} differ from the general path"
