"""An independent reference of the diamond-exit rule for width-1 lines (ES 3.0 §3.5.1), in exact
rational arithmetic with a concrete, tiny perturbation eps (the spec's "(x, y) - (eps, eps^2)" with
an eps small enough that any smaller one gives the same fragments), and Liang-Barsky clipping of the
segment against the four open half-planes of each diamond. It shares no code or method with the C++
rasterizer (which resolves eps symbolically and tests only the end columns).

Coordinates are fixed point (1/256 pixel, as setup snaps them); pixel (px, py) has its centre at
(256 px + 128, 256 py + 128) and its diamond is |x - xc| + |y - yc| < 128.
"""
from fractions import Fraction

import numpy as np

EPS = Fraction(1, 2 ** 64)   # far below any critical value for coordinates < 2^20 (roots of the
                             # degree-2 comparisons are at least ~2^-42 away from 0)
R = 128


def _segment_meets_open_diamond(p, q, c):
    """Does the closed segment p-q meet the open diamond of radius R around c? (Fractions.)"""
    lo, hi = Fraction(0), Fraction(1)
    lo_open = hi_open = False
    d = (q[0] - p[0], q[1] - p[1])
    for s1 in (1, -1):
        for s2 in (1, -1):
            # s1 (x - cx) + s2 (y - cy) < R along x = p + t d:  alpha + beta t < R
            alpha = s1 * (p[0] - c[0]) + s2 * (p[1] - c[1])
            beta = s1 * d[0] + s2 * d[1]
            if beta == 0:
                if not alpha < R:
                    return False
                continue
            t = (R - alpha) / beta
            if beta > 0:      # t < bound
                if t < hi or (t == hi and not hi_open):
                    hi, hi_open = t, True
            else:             # t > bound
                if t > lo or (t == lo and not lo_open):
                    lo, lo_open = t, True
    return lo < hi or (lo == hi and not lo_open and not hi_open)


def _inside_open_diamond(p, c):
    return abs(p[0] - c[0]) + abs(p[1] - c[1]) < R


def diamond_exit_fragments(a, b, width, height):
    """(height, width) uint32 mask of the fragments the segment a -> b (fixed-point int pairs)
    produces under the diamond-exit rule."""
    pa = (Fraction(a[0]) - EPS, Fraction(a[1]) - EPS * EPS)
    pb = (Fraction(b[0]) - EPS, Fraction(b[1]) - EPS * EPS)
    out = np.zeros((height, width), np.uint32)
    # Only pixels whose centre is within 1 pixel (L-inf) of the segment's bounding box can qualify.
    x0 = max(0, (min(a[0], b[0]) - 384) // 256)
    x1 = min(width - 1, (max(a[0], b[0]) + 384) // 256)
    y0 = max(0, (min(a[1], b[1]) - 384) // 256)
    y1 = min(height - 1, (max(a[1], b[1]) + 384) // 256)
    dx, dy = b[0] - a[0], b[1] - a[1]
    length = max(abs(dx), abs(dy), 1)
    for py in range(y0, y1 + 1):
        for px in range(x0, x1 + 1):
            c = (256 * px + 128, 256 * py + 128)
            # Cheap float prefilter: the centre's distance to the segment's line is below 1 px.
            if abs(dx * (c[1] - a[1]) - dy * (c[0] - a[0])) > 2 * 256 * length:
                continue
            if _inside_open_diamond(pb, c):
                continue
            if _segment_meets_open_diamond(pa, pb, c):
                out[py, px] = 1
    return out


def wide_line_fragments(a, b, line_width, width, height):
    """ES 3.0 §3.5.2 for non-antialiased wide lines, built from the width-1 rule: round the width
    (0 -> 1), offset the segment by -(w-1)/2 in the minor direction, and replace each fragment by a
    column (x-major) or row (y-major) of w fragments starting at it."""
    w = max(1, int(np.floor(line_width + 0.5)))
    x_major = abs(b[0] - a[0]) >= abs(b[1] - a[1])
    shift = (w - 1) * 128
    if x_major:
        sa, sb = (a[0], a[1] - shift), (b[0], b[1] - shift)
    else:
        sa, sb = (a[0] - shift, a[1]), (b[0] - shift, b[1])
    # Compute on a target padded by w on every side, so offset fragments are not lost at borders.
    pad = w + 1
    base = diamond_exit_fragments((sa[0] + 256 * pad, sa[1] + 256 * pad),
                                  (sb[0] + 256 * pad, sb[1] + 256 * pad),
                                  width + 2 * pad, height + 2 * pad)
    out = np.zeros_like(base)
    for k in range(w):
        out |= np.roll(base, k, axis=0 if x_major else 1)
    return out[pad:pad + height, pad:pad + width]
