"""Primitive assembly against the vertex lists of ES 3.0 §2.6.1 written out by hand."""
import pytest

import softgl
from softgl import _core


def prims(mode, count):
    flat = _core.testing.assemble(getattr(softgl, mode), count)
    k = {"POINTS": 1, "LINES": 2, "LINE_STRIP": 2, "LINE_LOOP": 2}.get(mode, 3)
    return [tuple(flat[i:i + k]) for i in range(0, len(flat), k)]


@pytest.mark.parametrize("mode, count, expected", [
    ("POINTS", 3, [(0,), (1,), (2,)]),
    ("LINES", 5, [(0, 1), (2, 3)]),                       # the odd vertex is dropped
    ("LINE_STRIP", 4, [(0, 1), (1, 2), (2, 3)]),
    ("LINE_STRIP", 1, []),
    ("LINE_LOOP", 3, [(0, 1), (1, 2), (2, 0)]),
    ("LINE_LOOP", 1, []),
    ("TRIANGLES", 7, [(0, 1, 2), (3, 4, 5)]),
    ("TRIANGLE_STRIP", 5, [(0, 1, 2), (2, 1, 3), (2, 3, 4)]),   # odd triangles swap: same winding
    ("TRIANGLE_FAN", 5, [(0, 1, 2), (0, 2, 3), (0, 3, 4)]),
    ("TRIANGLE_FAN", 2, []),
])
def test_assembly(mode, count, expected):
    assert prims(mode, count) == expected


def test_strip_triangles_keep_the_first_triangles_winding():
    # Vertices on a zigzag: every assembled triangle must have the same signed area sign.
    xs = [(i // 2, i % 2) for i in range(8)]
    for a, b, c in prims("TRIANGLE_STRIP", 8):
        (x0, y0), (x1, y1), (x2, y2) = xs[a], xs[b], xs[c]
        assert (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0) < 0
