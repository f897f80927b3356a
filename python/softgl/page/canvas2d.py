"""The part of canvas 2D (`canvas.getContext('2d')`) that pages and three.js use to make texture
images, with exact rules (docs/pages.md, "Canvas 2D"): fillRect / clearRect on whole pixels,
drawImage with or without scaling, getImageData / putImageData. Pixels are RGBA8, not
premultiplied, top row first (as an <img> is). What would need antialiasing or a path (a
rectangle edge between pixels, transforms, paths, text) is refused by browser.js by name.
"""
from __future__ import annotations

import re

import numpy as np

# CSS named colours pages use for fills (CSS Color 4); others are refused by name.
_NAMED = {"black": (0, 0, 0), "white": (255, 255, 255), "red": (255, 0, 0), "lime": (0, 255, 0),
          "green": (0, 128, 0), "blue": (0, 0, 255), "yellow": (255, 255, 0), "cyan": (0, 255, 255),
          "aqua": (0, 255, 255), "magenta": (255, 0, 255), "fuchsia": (255, 0, 255),
          "gray": (128, 128, 128), "grey": (128, 128, 128), "silver": (192, 192, 192),
          "orange": (255, 165, 0), "purple": (128, 0, 128), "navy": (0, 0, 128), "maroon": (128, 0, 0),
          "olive": (128, 128, 0), "teal": (0, 128, 128)}


class Canvas2DError(ValueError):
    """A canvas 2D call outside what softgl.page does exactly: browser.js throws it to the page as
    NotSupportedError ("softgl.page does not provide canvas 2D ...")."""

    def __init__(self, what: str):
        super().__init__("canvas 2D " + what)


def parse_color(text: str) -> tuple[float, float, float, float]:
    """A CSS colour as (r, g, b) in 0..255 and alpha in 0..1 (CSS Color 4: hex, rgb(a), names)."""
    s = str(text).strip().lower()
    if s == "transparent":
        return (0.0, 0.0, 0.0, 0.0)
    if s in _NAMED:
        return (*map(float, _NAMED[s]), 1.0)
    m = re.fullmatch(r"#([0-9a-f]{3,8})", s)
    if m and len(m.group(1)) in (3, 4, 6, 8):
        h = m.group(1)
        if len(h) in (3, 4):
            h = "".join(c * 2 for c in h)
        values = [int(h[i:i + 2], 16) for i in range(0, len(h), 2)]
        alpha = values[3] / 255 if len(values) == 4 else 1.0
        return (float(values[0]), float(values[1]), float(values[2]), alpha)
    m = re.fullmatch(r"rgba?\(\s*([^)]*)\)", s)
    if m:
        parts = [p for p in re.split(r"[\s,/]+", m.group(1).strip()) if p]
        if len(parts) in (3, 4):
            def channel(p):
                return float(p[:-1]) * 2.55 if p.endswith("%") else float(p)
            rgb = [min(255.0, max(0.0, channel(p))) for p in parts[:3]]
            alpha = 1.0
            if len(parts) == 4:
                p = parts[3]
                alpha = float(p[:-1]) / 100 if p.endswith("%") else float(p)
            return (*rgb, min(1.0, max(0.0, alpha)))
    raise Canvas2DError(f"the fillStyle {text!r} (softgl.page's canvas 2D takes CSS colours: "
                        "#rgb, #rrggbb, rgb(), rgba(), basic names)")


def _whole(value, what: str) -> int:
    v = float(value)
    if not np.isfinite(v) or v != np.floor(v):
        raise Canvas2DError(f"{what} at {value} (softgl.page's canvas 2D draws whole pixels only: "
                            "an edge between pixel boundaries needs antialiasing)")
    return int(v)


def _rect(x, y, w, h, call: str):
    x, y, w, h = (_whole(v, f"{call} with an edge") for v in (x, y, w, h))
    if w < 0:
        x, w = x + w, -w
    if h < 0:
        y, h = y + h, -h
    return x, y, w, h


class Canvas2D:
    """One canvas's 2D pixels (height, width, 4) uint8, not premultiplied, top row first."""

    def __init__(self, width: int, height: int):
        self.pixels = np.zeros((max(0, int(height)), max(0, int(width)), 4), np.uint8)

    @property
    def width(self):
        return self.pixels.shape[1]

    @property
    def height(self):
        return self.pixels.shape[0]

    def resize(self, width, height):
        """Setting a canvas's width or height clears it (HTML canvas: "set bitmap dimensions")."""
        self.pixels = np.zeros((max(0, int(height)), max(0, int(width)), 4), np.uint8)

    def _clip(self, x, y, w, h):
        x0, y0 = max(0, x), max(0, y)
        x1, y1 = min(self.width, x + w), min(self.height, y + h)
        return x0, y0, max(x0, x1), max(y0, y1)

    def _composite(self, x0, y0, src_rgb, src_alpha):
        """Source-over (the default globalCompositeOperation) of float64 colours (0..255) and
        alphas (0..1) onto the canvas, not premultiplied, rounded to nearest once."""
        h, w = src_alpha.shape
        dst = self.pixels[y0:y0 + h, x0:x0 + w].astype(np.float64)
        da = dst[..., 3] / 255
        out_a = src_alpha + da * (1 - src_alpha)
        with np.errstate(invalid="ignore", divide="ignore"):
            rgb = (src_rgb * src_alpha[..., None] + dst[..., :3] * (da * (1 - src_alpha))[..., None]) / out_a[..., None]
        rgb = np.where(out_a[..., None] > 0, rgb, 0.0)
        out = np.concatenate([rgb, (out_a * 255)[..., None]], axis=2)
        self.pixels[y0:y0 + h, x0:x0 + w] = np.clip(np.floor(out + 0.5), 0, 255).astype(np.uint8)

    def fill_rect(self, x, y, w, h, style: str, global_alpha: float):
        x0, y0, x1, y1 = self._clip(*_rect(x, y, w, h, "fillRect"))
        if x1 == x0 or y1 == y0:
            return
        r, g, b, a = parse_color(style)
        a *= float(global_alpha)
        if a >= 1.0:   # opaque: the colour itself, exactly
            self.pixels[y0:y1, x0:x1] = np.array([round(r), round(g), round(b), 255], np.uint8)
            return
        shape = (y1 - y0, x1 - x0)
        self._composite(x0, y0, np.broadcast_to(np.array([r, g, b]), shape + (3,)), np.full(shape, a))

    def clear_rect(self, x, y, w, h):
        x0, y0, x1, y1 = self._clip(*_rect(x, y, w, h, "clearRect"))
        self.pixels[y0:y1, x0:x1] = 0

    def draw_image(self, source, sx, sy, sw, sh, dx, dy, dw, dh, smoothing: bool, global_alpha: float):
        """drawImage(source, sx, sy, sw, sh, dx, dy, dw, dh). Destination pixel centre (x + 1/2,
        y + 1/2) takes the source point sx + (x + 1/2 - dx) * sw / dw (and so for y): with
        smoothing, bilinear over the source rectangle's texels (clamped to its edge), weighted in
        float64 on alpha-premultiplied values; without, the texel under the point. A copy
        without scaling from whole-pixel offsets is the texels themselves."""
        src = np.asarray(source)
        if src.ndim != 3 or src.shape[2] != 4 or src.dtype != np.uint8:
            raise Canvas2DError("drawImage of a source that is not an image or a canvas")
        dx, dy, dw, dh = _rect(dx, dy, dw, dh, "drawImage with a destination edge")
        sx, sy, sw, sh = (float(v) for v in (sx, sy, sw, sh))
        if sw < 0:
            sx, sw = sx + sw, -sw
        if sh < 0:
            sy, sh = sy + sh, -sh
        # The source rectangle clipped to the source (HTML canvas drawImage), the destination
        # shrunk in proportion.
        cx0, cy0 = max(sx, 0.0), max(sy, 0.0)
        cx1, cy1 = min(sx + sw, float(src.shape[1])), min(sy + sh, float(src.shape[0]))
        if cx1 <= cx0 or cy1 <= cy0 or dw == 0 or dh == 0:
            return
        if (cx0, cy0, cx1, cy1) != (sx, sy, sx + sw, sy + sh):
            kx, ky = dw / sw, dh / sh
            ndx, ndy = dx + (cx0 - sx) * kx, dy + (cy0 - sy) * ky
            ndw, ndh = (cx1 - cx0) * kx, (cy1 - cy0) * ky
            dx, dy, dw, dh = _rect(ndx, ndy, ndw, ndh, "drawImage with a clipped destination edge")
            sx, sy, sw, sh = cx0, cy0, cx1 - cx0, cy1 - cy0
        x0, y0, x1, y1 = self._clip(dx, dy, dw, dh)
        if x1 == x0 or y1 == y0:
            return
        xs = sx + (np.arange(x0, x1) + 0.5 - dx) * (sw / dw)
        ys = sy + (np.arange(y0, y1) + 0.5 - dy) * (sh / dh)
        ga = float(global_alpha)
        if sw == dw and sh == dh and sx == np.floor(sx) and sy == np.floor(sy):
            block = src[int(sy) + y0 - dy:int(sy) + y1 - dy, int(sx) + x0 - dx:int(sx) + x1 - dx]
            if ga >= 1.0 and (block[..., 3] == 255).all():
                self.pixels[y0:y1, x0:x1] = block
                return
            rgb, alpha = block[..., :3].astype(np.float64), block[..., 3] / 255
        elif not smoothing:
            ix = np.clip(np.floor(xs).astype(int), int(np.floor(sx)), int(np.ceil(sx + sw)) - 1)
            iy = np.clip(np.floor(ys).astype(int), int(np.floor(sy)), int(np.ceil(sy + sh)) - 1)
            block = src[iy][:, ix]
            rgb, alpha = block[..., :3].astype(np.float64), block[..., 3] / 255
        else:
            lo_x, hi_x = int(np.floor(sx)), int(np.ceil(sx + sw)) - 1
            lo_y, hi_y = int(np.floor(sy)), int(np.ceil(sy + sh)) - 1
            u, v = xs - 0.5, ys - 0.5
            i0, j0 = np.floor(u).astype(int), np.floor(v).astype(int)
            fu, fv = (u - i0)[None, :, None], (v - j0)[:, None, None]
            i1, j1 = np.clip(i0 + 1, lo_x, hi_x), np.clip(j0 + 1, lo_y, hi_y)
            i0, j0 = np.clip(i0, lo_x, hi_x), np.clip(j0, lo_y, hi_y)
            pm = src.astype(np.float64)
            pm[..., :3] *= pm[..., 3:4] / 255   # premultiplied, so transparent texels add no colour
            top = pm[j0][:, i0] * (1 - fu) + pm[j0][:, i1] * fu
            bottom = pm[j1][:, i0] * (1 - fu) + pm[j1][:, i1] * fu
            mixed = top * (1 - fv) + bottom * fv
            alpha = mixed[..., 3] / 255
            with np.errstate(invalid="ignore", divide="ignore"):
                rgb = np.where(alpha[..., None] > 0, mixed[..., :3] / alpha[..., None], 0.0)
        self._composite(x0, y0, rgb, alpha * ga)

    def draw(self, source, args, smoothing, global_alpha):
        """drawImage(source, ...args) with its three arities (dx, dy | dx, dy, dw, dh |
        sx, sy, sw, sh, dx, dy, dw, dh); the source's size from its pixels."""
        src = np.asarray(source)
        a = [float(v) for v in args]
        h, w = src.shape[:2]
        if len(a) == 2:
            a = [0, 0, w, h, a[0], a[1], w, h]
        elif len(a) == 4:
            a = [0, 0, w, h, *a]
        elif len(a) != 8:
            raise TypeError("Failed to execute 'drawImage': valid arities are 3, 5 and 9")
        self.draw_image(src, *a, smoothing=bool(smoothing), global_alpha=float(global_alpha))

    def get_image_data_bytes(self, x, y, w, h) -> str:
        """get_image_data's bytes as one Latin-1 character each (how bytes cross to JavaScript)."""
        return self.get_image_data(x, y, w, h).tobytes().decode("latin-1")

    def get_image_data(self, x, y, w, h) -> np.ndarray:
        """The (h, w, 4) block at (x, y); outside the canvas transparent black."""
        x, y, w, h = (_whole(v, "getImageData with an edge") for v in (x, y, w, h))
        if w <= 0 or h <= 0:
            raise Canvas2DError("getImageData with a width or height of 0 or less (IndexSizeError)")
        out = np.zeros((h, w, 4), np.uint8)
        x0, y0, x1, y1 = self._clip(x, y, w, h)
        out[y0 - y:y1 - y, x0 - x:x1 - x] = self.pixels[y0:y1, x0:x1]
        return out

    def put_image_data(self, data, width, height, dx, dy):
        """putImageData(imageData, dx, dy): the bytes replace the canvas's, no compositing."""
        block = np.asarray(data, np.uint8).reshape(int(height), int(width), 4)
        dx, dy = _whole(dx, "putImageData at"), _whole(dy, "putImageData at")
        x0, y0, x1, y1 = self._clip(dx, dy, block.shape[1], block.shape[0])
        self.pixels[y0:y1, x0:x1] = block[y0 - dy:y1 - dy, x0 - dx:x1 - dx]
