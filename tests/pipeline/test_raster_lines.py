"""Line end pixels (setup.cpp's diamond-exit span search, with its cheap pre-tests) against the
exact-rational reference in diamond_reference.py, on the cases the pre-tests are borderline for:
slopes of exactly +-1, end points on pixel and diamond boundaries, ends beyond the framebuffer."""
import numpy as np
import pytest

from conftest import clip_from_window, coverage, snap, window_from_clip
from diamond_reference import diamond_exit_fragments

W = H = 20


def check(xy):
    clip = clip_from_window(np.asarray(xy, np.float64), W, H)
    got = coverage(W, H, clip, primitive="lines")["count"][..., 0]
    f = snap(window_from_clip(clip, W, H))
    a, b = tuple(int(v) for v in f[0]), tuple(int(v) for v in f[1])
    np.testing.assert_array_equal(got, diamond_exit_fragments(a, b, W, H), err_msg=str(np.asarray(xy).tolist()))


@pytest.mark.parametrize("seed", range(3))
def test_diagonal_lines(seed):
    """|dx| == |dy|: the largest slope the minor-distance pre-test allows."""
    rng = np.random.default_rng(seed)
    for _ in range(40):
        p = np.round(rng.uniform(-1, W + 1, 2) * 16) / 16
        d = np.round(rng.uniform(0.1, 6) * 16) / 16 * rng.choice([-1, 1], 2)
        check([p, p + d])


@pytest.mark.parametrize("seed", range(3))
def test_ends_on_boundaries(seed):
    """End points on pixel edges, pixel centres and diamond corners (quarter-pixel grid)."""
    rng = np.random.default_rng(10 + seed)
    for _ in range(60):
        p = rng.integers(-4, 4 * W + 4, 2) / 4
        q = p + rng.integers(-24, 25, 2) / 4
        if (q != p).any():
            check([p, q])


def test_long_lines_leaving_the_framebuffer():
    rng = np.random.default_rng(5)
    for _ in range(40):
        p = rng.uniform(-0.5 * W, 1.5 * W, 2)
        q = rng.uniform(-0.5 * W, 1.5 * W, 2)
        check([p, q])
