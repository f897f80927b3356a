"""Animations: frames (contexts or images) to an animated GIF, and inline display in Jupyter.

    frames = [render(angle) for angle in np.linspace(0, 2 * np.pi, 12, endpoint=False)]
    animation.frames_to_gif(frames, "light.gif", fps=8)     # through OpenImageIO or matplotlib
    animation.show(frames, fps=8)                            # inline: the GIF, and a filmstrip PNG

A frame is a softgl Context (its canvas, composited over a white page as a browser shows it) or
an (h, w, 3|4) uint8 image, top row first. All frames must have the same size.
"""
from __future__ import annotations

import base64
import os
import tempfile
from pathlib import Path

import numpy as np

from . import display


def frame_image(frame) -> np.ndarray:
    """A frame as (h, w, 3) uint8, top row first."""
    if hasattr(frame, "drawingBufferWidth"):
        return display.canvas_image(frame, present=False)
    image = np.asarray(frame)
    if image.dtype != np.uint8:
        image = np.floor(np.clip(image.astype(np.float64), 0, 1) * 255 + 0.5).astype(np.uint8)
    if image.ndim == 2:
        image = np.repeat(image[..., None], 3, axis=2)
    if image.shape[2] == 4:
        image = display.composite(image, premultiplied=False)
    return np.ascontiguousarray(image[..., :3])


def _images(frames) -> list[np.ndarray]:
    images = [frame_image(f) for f in frames]
    if not images:
        raise ValueError("no frames")
    if len({im.shape for im in images}) != 1:
        raise ValueError(f"frames differ in size: {sorted({im.shape for im in images})}")
    return images


def label_frames(images, labels, font_size: float = 9) -> list[np.ndarray]:
    """Each image with its label written above it (matplotlib, the ``lab`` extra), (h', w, 3) uint8.

    The labels are rendered at the images' own pixel scale, so a frame keeps its size and only
    gains a strip of text on top."""
    if len(labels) != len(images):
        raise ValueError(f"label_frames: {len(labels)} labels for {len(images)} frames")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    h, w, _ = images[0].shape
    dpi = 100
    strip = int(round(font_size * dpi / 72 * 1.8))
    out = []
    for image, label in zip(images, labels):
        fig = Figure(figsize=(w / dpi, (h + strip) / dpi), dpi=dpi)
        canvas = FigureCanvasAgg(fig)
        fig.text(0.5, 1 - strip / 2 / (h + strip), str(label), ha="center", va="center", fontsize=font_size)
        ax = fig.add_axes((0, 0, 1, h / (h + strip)))
        ax.imshow(image, interpolation="nearest")
        ax.set_axis_off()
        canvas.draw()
        out.append(np.asarray(canvas.buffer_rgba())[..., :3].copy())
    return out


def _gif_oiio(images, path: Path, fps: float, loop: int):
    import OpenImageIO as oiio
    h, w, _ = images[0].shape
    out = oiio.ImageOutput.create(str(path))
    if out is None or not out.supports("multiimage"):
        raise RuntimeError("OpenImageIO cannot write animated GIFs here")
    specs = []
    for _ in images:
        spec = oiio.ImageSpec(w, h, 3, oiio.UINT8)
        spec.attribute("FramesPerSecond", oiio.TypeDesc("rational"), (int(round(fps * 100)), 100))
        spec.attribute("oiio:LoopCount", loop)
        spec.attribute("gif:LoopCount", loop)
        specs.append(spec)
    if not out.open(str(path), specs):
        raise RuntimeError(f"OpenImageIO: {out.geterror()}")
    for i, image in enumerate(images):
        if i and not out.open(str(path), specs[i], "AppendSubimage"):
            raise RuntimeError(f"OpenImageIO: {out.geterror()}")
        if not out.write_image(image):
            raise RuntimeError(f"OpenImageIO: {out.geterror()}")
    out.close()


def _gif_matplotlib(images, path: Path, fps: float, loop: int):
    import matplotlib
    import matplotlib.pyplot as plt
    from matplotlib.animation import ArtistAnimation, PillowWriter
    h, w, _ = images[0].shape
    dpi = 100
    fig = plt.figure(figsize=(w / dpi, h / dpi), dpi=dpi)
    ax = fig.add_axes([0, 0, 1, 1])
    ax.set_axis_off()
    artists = [[ax.imshow(im, interpolation="nearest", animated=True)] for im in images]
    anim = ArtistAnimation(fig, artists, interval=1000 / fps)
    anim.save(str(path), writer=PillowWriter(fps=fps), dpi=dpi)
    plt.close(fig)


def frames_to_gif(frames, path, fps: float = 10, loop: int = 0, backend: str = "auto") -> Path:
    """Write `frames` as an animated GIF at `path` (`loop` 0: forever). `backend` is "oiio"
    (OpenImageIO), "matplotlib" (its Pillow writer) or "auto" (OpenImageIO if it can, else
    matplotlib). Returns the path."""
    path = Path(path)
    images = _images(frames)
    if fps <= 0:
        raise ValueError("fps must be positive")
    if backend not in ("auto", "oiio", "matplotlib"):
        raise ValueError("backend is 'auto', 'oiio' or 'matplotlib'")
    if backend in ("auto", "oiio"):
        try:
            _gif_oiio(images, path, fps, loop)
            return path
        except (ImportError, RuntimeError):
            if backend == "oiio":
                raise
    _gif_matplotlib(images, path, fps, loop)
    return path


def gif_bytes(frames, fps: float = 10, loop: int = 0, backend: str = "auto") -> bytes:
    """The animated GIF of `frames` as bytes."""
    fd, name = tempfile.mkstemp(suffix=".gif")
    os.close(fd)
    try:
        frames_to_gif(frames, name, fps, loop, backend)
        return Path(name).read_bytes()
    finally:
        os.unlink(name)


def filmstrip(frames, columns: int | None = None, gap: int = 4) -> np.ndarray:
    """The frames side by side (wrapping after `columns`) on white, (h, w, 3) uint8."""
    images = _images(frames)
    h, w, _ = images[0].shape
    columns = columns or len(images)
    rows = -(-len(images) // columns)
    sheet = np.full((rows * h + (rows - 1) * gap, columns * w + (columns - 1) * gap, 3), 255, np.uint8)
    for i, im in enumerate(images):
        r, c = divmod(i, columns)
        sheet[r * (h + gap):r * (h + gap) + h, c * (w + gap):c * (w + gap) + w] = im
    return sheet


class Animation:
    """Frames shown inline: the animated GIF (HTML) where HTML is rendered, a filmstrip PNG
    elsewhere. ``.gif`` holds the GIF's bytes; ``.save(path)`` writes them. With `labels`, each
    frame shows its label above it."""

    def __init__(self, frames, fps: float = 10, loop: int = 0, columns: int | None = None, labels=None):
        self.frames = _images(frames)
        if labels is not None:
            self.frames = label_frames(self.frames, list(labels))
        self.fps = fps
        self.gif = gif_bytes(self.frames, fps, loop)
        self.columns = columns

    def save(self, path) -> Path:
        path = Path(path)
        path.write_bytes(self.gif)
        return path

    def _repr_html_(self):
        data = base64.b64encode(self.gif).decode("ascii")
        return f'<img src="data:image/gif;base64,{data}" alt="softgl animation ({len(self.frames)} frames)">'

    def _repr_png_(self):
        return display.encode_png(filmstrip(self.frames, self.columns))

    def __len__(self):
        return len(self.frames)


def show(frames, fps: float = 10, loop: int = 0, columns: int | None = None,
         labels=None) -> Animation:
    """An Animation of `frames`, to display inline (the last expression of a cell); `labels` (one
    string per frame) are written above the frames, in the GIF and in the filmstrip."""
    return Animation(frames, fps, loop, columns, labels)
