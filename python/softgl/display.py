"""Showing a canvas the way a browser does: the drawing buffer composited over the page.

WebGL 1.0 §2.2 and the HTML canvas rules: with ``premultipliedAlpha`` the buffer's colors are
taken as premultiplied (shown = C + (1 - A) * page), without it as straight alpha
(shown = A * C + (1 - A) * page); a context with ``alpha: false`` is opaque.

Showing a canvas (Jupyter's display of ``gl``, ``show``, ``canvas_image``) never clears it: you
can show it twice, or read it after showing it. Only ``present(gl)``, the end of a browser
frame, follows the browser's rule: a drawing buffer without ``preserveDrawingBuffer`` is then
cleared (WebGL 1.0 §2.2).
"""
from __future__ import annotations

import struct
import zlib

import numpy as np

WHITE = (255, 255, 255)


def composite(rgba: np.ndarray, *, premultiplied: bool = True, alpha: bool = True,
              background=WHITE) -> np.ndarray:
    """Composite an (h, w, 4) uint8 image (any row order) over `background`; (h, w, 3) uint8."""
    rgba = np.asarray(rgba)
    if rgba.dtype != np.uint8:
        rgba = np.clip(np.nan_to_num(rgba.astype(np.float64)) * 255.0 + 0.5, 0, 255).astype(np.uint8)
    if not alpha:
        return rgba[..., :3].copy()
    c = rgba[..., :3].astype(np.float64) / 255.0
    a = rgba[..., 3:4].astype(np.float64) / 255.0
    page = np.asarray(background, np.float64).reshape(1, 1, 3) / 255.0
    shown = (c if premultiplied else c * a) + (1.0 - a) * page
    return np.clip(np.floor(shown * 255.0 + 0.5), 0, 255).astype(np.uint8)


def present(gl) -> None:
    """End a frame as a browser does after compositing the canvas: a drawing buffer without
    ``preserveDrawingBuffer`` is cleared to its initial contents (WebGL 1.0 §2.2)."""
    gl._present()


def canvas_image(gl, background=WHITE, present: bool = False) -> np.ndarray:
    """The canvas as a person sees it: (h, w, 3) uint8, top row first. The canvas is left as
    it is, unless ``present=True``: then the frame ends as in ``present(gl)``."""
    w, h = gl.drawingBufferWidth, gl.drawingBufferHeight
    attrs = gl.getContextAttributes()
    # A float drawing buffer (color_format rgba16f/rgba32f) is shown the way browsers show a
    # float canvas on an 8-bit display: its values are taken as the canvas's (sRGB-encoded)
    # values, clamped to [0, 1] and rounded to 8 bits (composite() does both), then composited.
    float_buffer = attrs.get("color_format", "rgba8") != "rgba8"
    pixels = gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT if float_buffer else gl.UNSIGNED_BYTE)
    if pixels is None:  # a pending error made the read fail: read with a clean state
        raise RuntimeError("could not read the drawing buffer")
    shown = composite(pixels[::-1], premultiplied=attrs["premultipliedAlpha"],
                      alpha=attrs["alpha"], background=background)
    if present:
        gl._present()
    return shown


def encode_png(image: np.ndarray) -> bytes:
    """PNG bytes for an (h, w, 3|4) or (h, w) uint8 image, top row first."""
    image = np.ascontiguousarray(image, dtype=np.uint8)
    if image.ndim == 2:
        image = image[..., None]
    h, w, channels = image.shape
    color_type = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    raw = np.concatenate([np.zeros((h, 1), np.uint8), image.reshape(h, w * channels)], axis=1)

    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    header = struct.pack(">IIBBBBB", w, h, 8, color_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
            chunk(b"IDAT", zlib.compress(raw.tobytes(), 6)) + chunk(b"IEND", b""))


def canvas_png(gl, background=WHITE) -> bytes:
    return encode_png(canvas_image(gl, background))


class _Image:
    def __init__(self, png: bytes):
        self._png = png

    def _repr_png_(self):
        return self._png


def show(obj, background=WHITE):
    """Display a context (composited like a browser canvas) or an image array inline in Jupyter.

    Arrays are (h, w, 3|4) uint8 or float in [0, 1], top row first; RGBA arrays are shown as
    straight alpha over the page background.
    """
    from IPython.display import display
    if hasattr(obj, "drawingBufferWidth"):
        png = canvas_png(obj, background)
    else:
        image = np.asarray(obj)
        if image.ndim == 3 and image.shape[2] == 4:
            image = composite(image, premultiplied=False, background=background)
        elif image.dtype != np.uint8:
            image = np.clip(np.nan_to_num(image.astype(np.float64)) * 255.0 + 0.5, 0, 255).astype(np.uint8)
        png = encode_png(image)
    display(_Image(png))
