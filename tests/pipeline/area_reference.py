"""Independent references for area coverage (pipeline/coverage): exact rational clipping of a
polygon by the pixel square (the opposite direction from the C++ code, which clips the square by
the primitive's edges, in double), and disk ∩ rectangle by Gauss-Legendre quadrature in the angle
(the integrand is analytic between its kinks, so the quadrature is exact to rounding)."""
from fractions import Fraction

import numpy as np


def _clip(poly, keep, cut):
    out = []
    for i, p in enumerate(poly):
        q = poly[(i + 1) % len(poly)]
        kp, kq = keep(p), keep(q)
        if kp:
            out.append(p)
        if kp != kq:
            out.append(cut(p, q))
    return out


def _shoelace(poly):
    s = 0
    for i, p in enumerate(poly):
        q = poly[(i + 1) % len(poly)]
        s += p[0] * q[1] - q[0] * p[1]
    return abs(s) / 2


def polygon_square_area(poly, px, py):
    """Exact area (Fraction) of the convex polygon (list of (Fraction, Fraction)) ∩ [px,px+1]x[py,py+1]."""
    for axis, bound, side in ((0, px, 1), (0, px + 1, -1), (1, py, 1), (1, py + 1, -1)):
        def keep(p, axis=axis, bound=bound, side=side):
            return (p[axis] - bound) * side >= 0

        def cut(p, q, axis=axis, bound=bound):
            t = (bound - p[axis]) / (q[axis] - p[axis])
            return (p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]))
        poly = _clip(poly, keep, cut)
        if len(poly) < 3:
            return Fraction(0)
    return _shoelace(poly)


def polygon_pixel_areas(poly, width, height):
    """(height, width) float64 exact areas of the polygon (Fractions or floats) per pixel."""
    poly = [(Fraction(x), Fraction(y)) for x, y in poly]
    out = np.zeros((height, width))
    xs = [p[0] for p in poly]
    ys = [p[1] for p in poly]
    for py in range(max(0, int(np.floor(min(ys)))), min(height, int(np.floor(max(ys))) + 1)):
        for px in range(max(0, int(np.floor(min(xs)))), min(width, int(np.floor(max(xs))) + 1)):
            out[py, px] = float(polygon_square_area(poly, px, py))
    return out


def snapped_polygon(fixed):
    """Fractions of pixels from fixed-point (1/256) integer vertices."""
    return [(Fraction(int(x), 256), Fraction(int(y), 256)) for x, y in fixed]


_GL_X, _GL_W = np.polynomial.legendre.leggauss(40)


def disk_rect_area_quadrature(cx, cy, r, x0, y0, x1, y1):
    """∫ |[y0, y1] ∩ [cy - s(x), cy + s(x)]| dx over [x0, x1], s = sqrt(r^2 - (x - cx)^2), with
    x = cx + r sin(theta), split where the chord ends cross y0 or y1."""
    t0 = np.arcsin(np.clip((x0 - cx) / r, -1, 1))
    t1 = np.arcsin(np.clip((x1 - cx) / r, -1, 1))
    if t1 <= t0:
        return 0.0
    cuts = {t0, t1}
    for y in (y0, y1):
        if abs(y - cy) < r:
            k = np.arccos(abs(y - cy) / r)
            cuts.update(v for v in (-k, k) if t0 < v < t1)
    cuts = sorted(cuts)
    total = 0.0
    for a, b in zip(cuts[:-1], cuts[1:]):
        th = 0.5 * (b - a) * _GL_X + 0.5 * (a + b)
        c = r * np.cos(th)
        length = np.maximum(0.0, np.minimum(y1, cy + c) - np.maximum(y0, cy - c))
        total += 0.5 * (b - a) * np.sum(_GL_W * length * c)
    return total
