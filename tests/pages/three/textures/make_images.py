"""Writes the images the three.js pages load (committed; rerun only to change them):
tiles.png, 64 x 64 RGB, power-of-two (three.js uploads it as it is, with mipmaps): 8 x 8 tiles
in four colours with a dark grout line and a diagonal gradient, so that filtering, orientation
and mipmaps all show.

    python tests/pages/three/textures/make_images.py
"""
from pathlib import Path

import numpy as np

import softgl.io

HERE = Path(__file__).parent


def tiles(size=64):
    y, x = np.mgrid[0:size, 0:size]
    palette = np.array([[200, 70, 50], [230, 190, 80], [60, 140, 200], [90, 170, 90]], np.float64)
    tile = ((x // 8) + 2 * (y // 8)) % 4
    rgb = palette[tile] * (0.75 + 0.25 * (x + y) / (2 * size - 2))[..., None]
    grout = (x % 8 == 0) | (y % 8 == 0)
    rgb[grout] = [40, 35, 30]
    return np.round(rgb).astype(np.uint8)


if __name__ == "__main__":
    softgl.io.save(tiles(), HERE / "tiles.png")
