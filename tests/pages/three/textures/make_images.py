"""Writes the images the three.js pages load (committed; rerun only to change them):
tiles.png, 64 x 64 RGB, power-of-two (three.js uploads it as it is, with mipmaps): 8 x 8 tiles
in four colours with a dark grout line and a diagonal gradient, so that filtering, orientation
and mipmaps all show; tiles_npot.png, 48 x 40 RGBA, the same pattern with a transparent corner, not
a power of two (three.js on WebGL 1 resizes it to 32 x 32 through a canvas 2D drawImage).

    python tests/pages/three/textures/make_images.py
"""
from pathlib import Path

import numpy as np

import softgl.io

HERE = Path(__file__).parent


def tiles(size=64, height=None):
    height = size if height is None else height
    y, x = np.mgrid[0:height, 0:size]
    palette = np.array([[200, 70, 50], [230, 190, 80], [60, 140, 200], [90, 170, 90]], np.float64)
    tile = ((x // 8) + 2 * (y // 8)) % 4
    rgb = palette[tile] * (0.75 + 0.25 * (x + y) / (size + height - 2))[..., None]
    grout = (x % 8 == 0) | (y % 8 == 0)
    rgb[grout] = [40, 35, 30]
    return np.round(rgb).astype(np.uint8)


if __name__ == "__main__":
    softgl.io.save(tiles(), HERE / "tiles.png")
    npot = np.concatenate([tiles(48, 40), np.full((40, 48, 1), 255, np.uint8)], axis=2)
    npot[:12, :12, 3] = 0          # a transparent corner (its colour must not bleed when filtered)
    npot[:12, :12, :3] = 255
    softgl.io.save(npot, HERE / "tiles_npot.png")
