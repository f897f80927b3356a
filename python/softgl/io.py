"""Image files through OpenImageIO: PNG, EXR, TIFF, JPEG, HDR ..."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def _oiio():
    import OpenImageIO
    return OpenImageIO


def save(image, path, *, background=None) -> Path:
    """Write a context's canvas or an image array to `path` (format from the extension).

    Arrays are (h, w), (h, w, 3|4), top row first; the numbers are written exactly as given:
    4-channel arrays are straight (unassociated) alpha, uint8/uint16 are written as they are,
    float arrays as float (EXR, TIFF) or converted by OpenImageIO for 8-bit formats.

    A context is saved as it displays (display.canvas_image): with `background`, composited
    over it (RGB); without, as a straight-alpha RGBA image that a viewer composites over its
    page the way a browser shows the canvas. A ``premultipliedAlpha: false`` canvas is its
    drawing buffer's bytes; a premultiplied canvas is un-premultiplied (C / A, rounded); a
    canvas with ``alpha: false`` is opaque.
    """
    path = Path(path)
    if hasattr(image, "drawingBufferWidth"):
        image = _canvas_pixels(image, background)
    array = np.ascontiguousarray(image)
    if array.ndim == 2:
        array = array[..., None]
    if array.ndim != 3 or array.shape[2] not in (1, 2, 3, 4):
        raise ValueError(f"save: expected an (h, w[, channels]) image, got shape {array.shape}")
    oiio = _oiio()
    pixel_type = {np.dtype(np.uint8): oiio.UINT8, np.dtype(np.uint16): oiio.UINT16,
                  np.dtype(np.float16): oiio.HALF, np.dtype(np.float32): oiio.FLOAT}.get(array.dtype)
    if pixel_type is None:
        array = array.astype(np.float32)
        pixel_type = oiio.FLOAT
    h, w, channels = array.shape
    spec = oiio.ImageSpec(w, h, channels, pixel_type)
    # The data is straight alpha: without this, OpenImageIO takes it as premultiplied and
    # divides by alpha on writing formats that store straight alpha (PNG).
    spec.attribute("oiio:UnassociatedAlpha", 1)
    path.parent.mkdir(parents=True, exist_ok=True)
    out = oiio.ImageOutput.create(str(path))
    if out is None:
        raise ValueError(f"save: OpenImageIO cannot write {path}: {oiio.geterror()}")
    try:
        if not out.open(str(path), spec) or not out.write_image(array):
            raise OSError(f"save: writing {path} failed: {out.geterror()}")
    finally:
        out.close()
    return path


def _canvas_pixels(gl, background) -> np.ndarray:
    from .display import composite
    attrs = gl.getContextAttributes()
    pixels = gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight,
                           gl.RGBA, gl.UNSIGNED_BYTE)[::-1]
    if background is not None:
        return composite(pixels, premultiplied=attrs["premultipliedAlpha"], alpha=attrs["alpha"],
                         background=background)
    pixels = pixels.copy()
    if not attrs["alpha"]:
        pixels[..., 3] = 255
    elif attrs["premultipliedAlpha"]:
        a = pixels[..., 3:4].astype(np.float64)
        straight = np.where(a > 0, pixels[..., :3] * 255.0 / np.maximum(a, 1), 0)
        pixels[..., :3] = np.clip(np.floor(straight + 0.5), 0, 255)
    return pixels


def load_image(path, dtype=None) -> np.ndarray:
    """Read an image file into an (h, w, channels) array, top row first (its stored pixel type
    unless `dtype` is given: np.uint8 or np.float32). The numbers are the file's: straight
    alpha stays straight (not multiplied by alpha)."""
    oiio = _oiio()
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    inp = oiio.ImageInput.open(str(path), config)
    if inp is None:
        raise FileNotFoundError(f"load_image: cannot open {path}: {oiio.geterror()}")
    try:
        fmt = oiio.UNKNOWN if dtype is None else {np.dtype(np.uint8): oiio.UINT8,
                                                   np.dtype(np.float32): oiio.FLOAT}[np.dtype(dtype)]
        pixels = inp.read_image(fmt)
    finally:
        inp.close()
    if pixels is None:
        raise OSError(f"load_image: reading {path} failed")
    return np.asarray(pixels)
