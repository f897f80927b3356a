"""Non-antialiased lines by the diamond-exit rule (ES 3.0 §3.5.1) and wide lines (§3.5.2), against
the independent exact-rational reference in diamond_reference.py."""
import numpy as np
import pytest

from conftest import clip_from_window, coverage, snap, window_from_clip
from diamond_reference import diamond_exit_fragments, wide_line_fragments

W = H = 24


def fixed_ends(clip):
    f = snap(window_from_clip(clip, W, H))
    return tuple(int(v) for v in f[0]), tuple(int(v) for v in f[1])


def line_mask(xy, **kw):
    clip = clip_from_window(xy, W, H)
    return coverage(W, H, clip, primitive="lines", **kw)["count"][..., 0], fixed_ends(clip)


def random_segments(seed, n, grid):
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-2, W + 2, (n, 2, 2))
    if grid:
        xy = np.round(xy * grid) / grid
    return xy


@pytest.mark.parametrize("grid", [0, 16, 2, 1])       # 0: 1/256 grid (float input); 2: half pixels
@pytest.mark.parametrize("seed", range(4))
def test_width1_lines_match_diamond_exit(seed, grid):
    for xy in random_segments(seed, 40, grid):
        if grid == 1:
            xy = xy + 0.5      # pixel centres: end points exactly at diamond centres
        got, (a, b) = line_mask(xy)
        np.testing.assert_array_equal(got, diamond_exit_fragments(a, b, W, H), err_msg=str(xy.tolist()))


def test_diamond_boundary_end_points():
    """End points exactly on diamond boundaries (corners and sides), every direction: the eps
    perturbation decides."""
    c = 10.5
    pts = [(c + dx, c + dy) for dx, dy in [(0.5, 0), (-0.5, 0), (0, 0.5), (0, -0.5), (0.25, 0.25),
                                           (-0.25, 0.25), (0.25, -0.25), (-0.25, -0.25)]]
    for p in pts:
        for q in [(3.0, 4.0), (18.0, 5.0), (17.0, 19.0), (4.0, 18.0), (10.5, 2.0), (2.0, 10.5),
                  (p[0] + 3, p[1] + 3), (p[0] - 3, p[1] + 3), (p[0] + 0.75, p[1]), (p[0], p[1] - 0.75)]:
            for xy in ([p, q], [q, p]):
                got, (a, b) = line_mask(np.array(xy))
                np.testing.assert_array_equal(got, diamond_exit_fragments(a, b, W, H), err_msg=str(xy))


def test_short_lines_inside_one_pixel():
    rng = np.random.default_rng(7)
    for _ in range(200):
        p = rng.integers(3, 20, 2) + rng.uniform(0, 1, 2)
        q = p + rng.uniform(-0.7, 0.7, 2)
        got, (a, b) = line_mask(np.array([p, q]))
        assert got.sum() <= 2
        np.testing.assert_array_equal(got, diamond_exit_fragments(a, b, W, H))


@pytest.mark.parametrize("seed", range(3))
def test_one_fragment_per_major_column_and_no_gaps(seed):
    """§3.5.1 rule 3: an x-major line has at most one fragment per column (y-major: per row), and
    the columns it covers are contiguous."""
    for xy in random_segments(100 + seed, 60, 0):
        got, (a, b) = line_mask(xy)
        x_major = abs(b[0] - a[0]) >= abs(b[1] - a[1])
        per = got.sum(axis=0 if x_major else 1)
        assert per.max() <= 1
        idx = np.nonzero(per)[0]
        if len(idx):
            assert idx[-1] - idx[0] + 1 == len(idx)


def test_connected_strip_has_no_duplicates_or_gaps():
    """§3.5.1 rule 4: x-major segments sharing end points, all left to right: no pixel twice, one
    pixel in every column from the first to the last."""
    rng = np.random.default_rng(11)
    for _ in range(30):
        xs = np.sort(rng.uniform(1, W - 1, 5))
        ys = np.empty(5)
        ys[0] = rng.uniform(4, H - 4)
        for i in range(1, 5):     # slopes in (-1, 1): every segment x-major
            ys[i] = ys[i - 1] + rng.uniform(-0.95, 0.95) * (xs[i] - xs[i - 1])
        total = np.zeros((H, W), np.uint32)
        for i in range(4):
            total += line_mask(np.array([[xs[i], ys[i]], [xs[i + 1], ys[i + 1]]]))[0]
        assert total.max() <= 1
        cols = np.nonzero(total.sum(axis=0))[0]
        assert cols[-1] - cols[0] + 1 == len(cols) == total.sum()


@pytest.mark.parametrize("width", [2, 3, 4, 5, 2.4, 2.6, 0.3])
def test_wide_lines_match_spec(width):
    """§3.5.2: width rounded to the nearest integer (0 -> 1); the width-1 line of the segment offset
    by -(w-1)/2 in the minor direction, each fragment replicated w times in the minor direction."""
    for xy in random_segments(int(width * 10), 30, 16):
        got, (a, b) = line_mask(xy, line_width=width)
        np.testing.assert_array_equal(got, wide_line_fragments(a, b, width, W, H),
                                      err_msg=f"{width} {xy.tolist()}")


def test_half_open_rule_agrees_between_the_ends():
    """The Chromium-compatible rule differs from diamond exit only at the first/last major pixel."""
    for xy in random_segments(5, 80, 16):
        d, (a, b) = line_mask(xy)
        h, _ = line_mask(xy, line_rule="half_open")
        x_major = abs(b[0] - a[0]) >= abs(b[1] - a[1])
        axis = 1 if x_major else 0
        ends = [v // 256 for v in ((a[0], b[0]) if x_major else (a[1], b[1]))]
        for pix in np.argwhere(d != h):
            assert min(abs(int(pix[axis]) - e) for e in ends) <= 1
