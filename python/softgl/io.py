"""Image files through OpenImageIO: PNG, EXR, TIFF, JPEG, HDR ..."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def _oiio():
    import OpenImageIO
    return OpenImageIO


def save(image, path, *, background=None) -> Path:
    """Write a context's canvas or an image array to `path` (format from the extension).

    A context is saved as its drawing buffer, top row first, RGBA (or composited over
    `background` when one is given, as display.show does). Arrays are (h, w), (h, w, 3|4),
    top row first; uint8/uint16 are written as is, float arrays as float (EXR, TIFF) or
    converted by OpenImageIO for 8-bit formats.
    """
    from .display import composite
    path = Path(path)
    if hasattr(image, "drawingBufferWidth"):
        gl = image
        pixels = gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight,
                               gl.RGBA, gl.UNSIGNED_BYTE)[::-1]
        if background is not None:
            attrs = gl.getContextAttributes()
            pixels = composite(pixels, premultiplied=attrs["premultipliedAlpha"],
                               alpha=attrs["alpha"], background=background)
        image = pixels
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


def load_image(path, dtype=None) -> np.ndarray:
    """Read an image file into an (h, w, channels) array, top row first (its stored pixel type
    unless `dtype` is given: np.uint8 or np.float32)."""
    oiio = _oiio()
    inp = oiio.ImageInput.open(str(path))
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
