"""The showcase: renders softgl's gallery into a folder and prints where it is.

    python -m softgl.showcase [folder]        (default: ./showcase)
"""
from __future__ import annotations

import html
import sys
from pathlib import Path

import numpy as np

import softgl
from softgl import io


def scissor_mosaic(gl):
    """Clears only: scissored rectangles, a color-masked band, composited over the page."""
    w, h = gl.drawingBufferWidth, gl.drawingBufferHeight
    gl.clearColor(0.08, 0.09, 0.12, 1.0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    rng = np.random.default_rng(7)
    for _ in range(60):
        x, y = int(rng.integers(0, w)), int(rng.integers(0, h))
        gl.scissor(x, y, int(rng.integers(8, w // 3)), int(rng.integers(8, h // 3)))
        r, g, b = rng.random(3)
        gl.clearColor(float(r), float(g), float(b), 1.0)
        gl.clear(gl.COLOR_BUFFER_BIT)
    # A band where only the red channel is written: what colorMask does.
    gl.colorMask(True, False, False, False)
    gl.scissor(0, h // 2 - 20, w, 40)
    gl.clearColor(1, 1, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.colorMask(True, True, True, True)
    gl.disable(gl.SCISSOR_TEST)


def translucent_canvas(gl):
    """A half-transparent drawing buffer: the page shows through, as in a browser."""
    w, h = gl.drawingBufferWidth, gl.drawingBufferHeight
    gl.enable(gl.SCISSOR_TEST)
    for i, alpha in enumerate(np.linspace(0.0, 1.0, 8)):
        gl.scissor(i * w // 8, 0, w // 8 + 1, h)
        a = float(alpha)
        gl.clearColor(0.1 * a, 0.4 * a, 0.9 * a, a)   # premultiplied, like WebGL's default
        gl.clear(gl.COLOR_BUFFER_BIT)


GALLERY = [
    ("scissor_mosaic", "Scissored clears and a red-only color mask", scissor_mosaic, {}),
    ("translucent_canvas", "Premultiplied alpha canvas over a white page", translucent_canvas, {}),
]


def render(folder: Path, width: int = 480, height: int = 320) -> list[tuple[str, str, Path]]:
    folder.mkdir(parents=True, exist_ok=True)
    items = []
    for name, title, scene, attrs in GALLERY:
        gl = softgl.Context(width, height, antialias=False, preserveDrawingBuffer=True, **attrs)
        scene(gl)
        path = io.save(softgl.display.canvas_image(gl, present=False), folder / f"{name}.png")
        items.append((name, title, path))
        print(f"  rendered {path}")
    cards = "\n".join(
        f'<figure><img src="{p.name}" width="{width}"><figcaption>{html.escape(t)}</figcaption></figure>'
        for _, t, p in items)
    (folder / "index.html").write_text(
        "<!doctype html><meta charset=utf-8><title>softgl showcase</title>"
        "<style>body{font-family:sans-serif}figure{display:inline-block;margin:8px}</style>"
        f"<h1>softgl showcase</h1>\n{cards}\n")
    return items


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    folder = Path(argv[0] if argv else "showcase").resolve()
    items = render(folder)
    print(f"softgl showcase: {len(items)} images in {folder} (open {folder / 'index.html'})")


if __name__ == "__main__":
    main()
