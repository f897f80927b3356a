"""Setup::triangles (a block of triangles at a time, as draws set up triangles) against
Setup::triangle called per triangle (the reference) and against a NumPy int64/float64 computation of
facing, culling, edges, bounding boxes and the small-triangle drop."""
import numpy as np
import pytest
from softgl import _core

from conftest import (GL_BACK, GL_CCW, GL_CW, GL_FRONT, GL_FRONT_AND_BACK, ref_triangle_coverage, snap,
                      window_from_clip)

W, H = 96, 80


def mixed_mesh(seed, n_vertices=400, n_triangles=1499):   # blocks of 256 and a tail of 3
    """Clip-space vertices of every kind setup meets: small and large triangles, vertices behind the
    eye (w < 0), beyond the guard band, outside the frustum, NaN and infinite ones, repeated ones."""
    rng = np.random.default_rng(seed)
    w = rng.uniform(0.5, 4.0, n_vertices)
    xy = rng.uniform(-1.3, 1.3, (n_vertices, 2))
    z = rng.uniform(-1.2, 1.2, n_vertices)
    pos = np.column_stack([xy * w[:, None], z * w, w]).astype(np.float32)
    kind = rng.integers(0, 40, n_vertices)
    pos[kind == 0, 3] *= -1                       # behind the eye
    pos[kind == 1, 0] *= 3e6                      # beyond the guard band
    pos[kind == 2, 1] = np.nan
    pos[kind == 3, 0] = np.inf
    pos[kind == 4] = pos[0]                       # repeats: zero-area triangles
    tris = rng.integers(0, n_vertices, (n_triangles, 3)).astype(np.uint32)
    # Small triangles: a vertex and two neighbours within a pixel or two.
    small = rng.integers(0, n_vertices, n_triangles // 2)
    for t, v in zip(tris[: n_triangles // 2], small):
        t[0] = v
    base = pos[tris[: n_triangles // 2, 0]].astype(np.float64)
    extra = np.empty((2 * (n_triangles // 2), 4), np.float64)
    for k in range(2):
        d = rng.uniform(-3, 3, (n_triangles // 2, 2)) / np.array([W, H]) * 2 * base[:, 3:4]
        e = base.copy()
        e[:, :2] += d
        extra[k::2] = e
    first = len(pos)
    pos = np.concatenate([pos, extra.astype(np.float32)])
    tris[: n_triangles // 2, 1] = first + 2 * np.arange(n_triangles // 2)
    tris[: n_triangles // 2, 2] = first + 2 * np.arange(n_triangles // 2) + 1
    return pos, tris


CASES = [dict(cull=0, front_face=GL_CCW), dict(cull=GL_BACK, front_face=GL_CCW),
         dict(cull=GL_FRONT, front_face=GL_CW), dict(cull=GL_FRONT_AND_BACK, front_face=GL_CCW),
         dict(cull=GL_BACK, front_face=GL_CW, polygon_offset=True, factor=1.5, units=2.0),
         dict(cull=0, front_face=GL_CCW, samples=4),
         dict(cull=GL_BACK, front_face=GL_CCW, sample_bounds=True),
         dict(cull=0, front_face=GL_CW, sample_bounds=True, polygon_offset=True, factor=-1.0, units=1.0)]


LEVELS = ["scalar", "sse2", "avx2", "avx512"]


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("case", range(len(CASES)))
@pytest.mark.parametrize("seed", range(3))
def test_batched_setup_gives_the_reference_records(case, seed, level):
    if LEVELS.index(level) > _core.testing.simd_level():
        pytest.skip(f"this CPU has no {level}")
    pos, tris = mixed_mesh(seed)
    kw = CASES[case]
    ints, bits, stats = _core.testing.setup_triangles(pos, tris, W, H, first_primitive=7 + seed, batched=True,
                                                      level=LEVELS.index(level), **kw)
    ref_ints, ref_bits, ref_stats = _core.testing.setup_triangles(pos, tris, W, H, first_primitive=7 + seed,
                                                                   batched=False, **kw)
    assert stats == ref_stats
    assert stats["clipped"] > 0 and stats["invalid"] > 0 and stats["zero_area"] > 0
    assert stats["emitted"] > 100 if kw["cull"] != GL_FRONT_AND_BACK else stats["culled"] > 100
    np.testing.assert_array_equal(ints, ref_ints)
    np.testing.assert_array_equal(bits, ref_bits)


def unclipped_mesh(seed, n_triangles=1499):
    """mixed_mesh's triangles whose vertices all project without clipping, so that whole groups of
    them take the AVX2 record kernel (a group with a triangle to clip goes triangle by triangle),
    with tiny triangles, edges along the axes (tie rule) and triangles across the canvas border."""
    pos, tris = mixed_mesh(seed, n_triangles=3 * n_triangles)
    tris = tris[unclipped(pos)[tris].all(1)][:n_triangles]
    rng = np.random.default_rng(100 + seed)
    # Right triangles with axis-aligned legs on whole and half pixels (edges with a == 0 or b == 0).
    k = 300
    corner = np.column_stack([rng.integers(-4, W + 4, k), rng.integers(-4, H + 4, k)]) + 0.5 * rng.integers(0, 2, (k, 2))
    size = rng.integers(1, 4, (k, 2)) * rng.choice([-1, 1], (k, 2)) * 0.5
    xy = np.stack([corner, corner + np.column_stack([size[:, 0], 0 * size[:, 1]]),
                   corner + np.column_stack([0 * size[:, 0], size[:, 1]])], axis=1).reshape(-1, 2)
    clip = np.column_stack([xy / [W, H] * 2 - 1, rng.uniform(-0.9, 0.9, len(xy)), np.ones(len(xy))]).astype(np.float32)
    first = len(pos)
    pos = np.concatenate([pos, clip])
    axis = (first + np.arange(3 * k)).reshape(k, 3).astype(np.uint32)
    tris = np.concatenate([tris, axis])
    return pos, tris[rng.permutation(len(tris))]


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("case", range(len(CASES)))
@pytest.mark.parametrize("seed", range(2))
def test_batched_setup_of_unclipped_triangles_gives_the_reference_records(case, seed, level):
    if LEVELS.index(level) > _core.testing.simd_level():
        pytest.skip(f"this CPU has no {level}")
    pos, tris = unclipped_mesh(seed)
    kw = CASES[case]
    ints, bits, stats = _core.testing.setup_triangles(pos, tris, W, H, first_primitive=3 + seed, batched=True,
                                                      level=LEVELS.index(level), **kw)
    ref_ints, ref_bits, ref_stats = _core.testing.setup_triangles(pos, tris, W, H, first_primitive=3 + seed,
                                                                   batched=False, **kw)
    assert stats == ref_stats
    assert stats["clipped"] == 0 and stats["zero_area"] > 0
    if kw["cull"] != GL_FRONT_AND_BACK:
        assert stats["emitted"] > 400 and stats["outside"] > 10
    np.testing.assert_array_equal(ints, ref_ints)
    np.testing.assert_array_equal(bits, ref_bits)


def unclipped(pos):
    """Vertices setup projects without clipping (finite, inside the frustum)."""
    p = pos.astype(np.float64)
    with np.errstate(invalid="ignore"):
        return (np.isfinite(p).all(1) & (p[:, 3] > 0) & (np.abs(p[:, :3]) <= p[:, 3:4]).all(1))


@pytest.mark.parametrize("cull,front_face", [(0, GL_CCW), (GL_BACK, GL_CCW), (GL_FRONT, GL_CCW), (GL_BACK, GL_CW)])
@pytest.mark.parametrize("sample_bounds", [False, True])
def test_batched_setup_against_int64_and_float64(cull, front_face, sample_bounds):
    pos, tris = mixed_mesh(11)
    keep = unclipped(pos)[tris].all(1)
    tris = tris[keep]
    ints, bits, stats = _core.testing.setup_triangles(pos, tris, W, H, cull=cull, front_face=front_face,
                                                      sample_bounds=sample_bounds,
                                                      level=_core.testing.simd_level())
    with np.errstate(invalid="ignore"):   # the clipped vertices' rows are not used
        fixed = snap(window_from_clip(pos, W, H))
    emitted = []
    culled = zero = 0
    for k, t in enumerate(tris):
        v = fixed[t]
        area2 = (v[1, 0] - v[0, 0]) * (v[2, 1] - v[0, 1]) - (v[2, 0] - v[0, 0]) * (v[1, 1] - v[0, 1])
        if area2 == 0:
            zero += 1
            continue
        front = (area2 > 0) == (front_face == GL_CCW)
        if cull and (cull == GL_FRONT_AND_BACK or (cull == GL_FRONT) == front):
            culled += 1
            continue
        lo, hi = v.min(0), v.max(0)
        if sample_bounds:   # pixels whose centre lies within the extent
            x0, y0 = (lo[0] + 127) // 256, (lo[1] + 127) // 256
            x1, y1 = (hi[0] - 128) // 256 + 1, (hi[1] - 128) // 256 + 1
        else:
            x0, y0, x1, y1 = lo[0] // 256, lo[1] // 256, hi[0] // 256 + 1, hi[1] // 256 + 1
        x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, W), min(y1, H)
        if x0 >= x1 or y0 >= y1:
            continue
        if sample_bounds and (x1 - x0) * (y1 - y0) <= 4:
            if not ref_triangle_coverage(v, W, H)[y0:y1, x0:x1].any():
                continue
        emitted.append((k, area2, front, (x0, y0, x1, y1)))
    assert stats["culled"] == culled and stats["zero_area"] == zero and stats["emitted"] == len(emitted)
    assert len(emitted) > 50
    for row, (k, area2, front, box) in enumerate(emitted):
        assert ints[row, 21] == k and ints[row, 24] == int(front)
        assert tuple(ints[row, 12:16]) == box
        v = fixed[tris[k]]
        order = [0, 1, 2] if area2 > 0 else [0, 2, 1]
        v = v[order]
        for i in range(3):   # edge i opposite vertex i, E >= 0 inside, tie rule in c
            (xj, yj), (xk, yk) = v[(i + 1) % 3], v[(i + 2) % 3]
            a, b = yj - yk, xk - xj
            excluded = not (a > 0 or (a == 0 and b > 0))
            assert (ints[row, i], ints[row, 4 + i], ints[row, 8 + i]) == (a, b, -(a * xj + b * yj) - excluded)
        # The 1/w and weight planes reproduce 1/w and the unit weights at the vertices (float64).
        planes = bits[row].view(np.float64)
        w = pos[tris[k][order], 3].astype(np.float64)
        for j in range(3):
            dx, dy = (v[j] - v[0]) / 256.0
            inv_w = planes[15] + planes[13] * dx + planes[14] * dy
            assert inv_w == pytest.approx(1 / w[j], rel=1e-9)
            for m in range(3):
                wk = planes[6 + 3 * m] + planes[4 + 3 * m] * dx + planes[5 + 3 * m] * dy
                assert wk == pytest.approx((order[j] == m) / w[j], abs=1e-9 / w[j])
