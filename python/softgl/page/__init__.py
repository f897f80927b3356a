"""Run a real WebGL page — an HTML file with its scripts, shaders and images — headless on softgl.

    result = softgl.page.run("exercise.html", frames=3)
    result.frames[-1]      # (h, w, 4) uint8 as readPixels returns it (row 0 = bottom)
    result.console         # [(level, text), ...] from console.log/warn/error
    result.errors          # GL errors (softgl's warnings) and uncaught JavaScript exceptions
    result                 # in Jupyter: the last frame

The page runs in V8 (the STPyV8 wheel) over a small deterministic browser: the DOM from a real
HTML parser, canvas.getContext('webgl' | 'experimental-webgl' | 'webgl2') returning a context
whose methods are softgl's, requestAnimationFrame, setTimeout and setInterval on a frame clock
that advances only by `time_step` per frame, Image, fetch and XMLHttpRequest over local files,
and console to Python logging. What a page may use, and what happens when it uses something
else: docs/pages.md.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import display as _display
from ..errors import GLWarning
from .browser import LIBRARY_PATH, Browser, PageError

__all__ = ["run", "PageResult", "PageError", "LIBRARY_PATH"]


@dataclass
class PageResult:
    """What a page did: the canvas after each frame, its console lines and its errors."""
    path: Path
    frames: list = field(default_factory=list)      # (h, w, 4) uint8 per frame, row 0 = bottom
    times: list = field(default_factory=list)       # the clock (ms) of each frame
    console: list = field(default_factory=list)     # (level, text)
    errors: list = field(default_factory=list)      # "GL: ..." and "JavaScript: <stack>"
    contexts: list = field(default_factory=list)    # the softgl Contexts the page made

    @property
    def image(self) -> np.ndarray:
        """The last frame, top row first (as it shows), composited on white like a browser page."""
        if not self.frames:
            raise ValueError(f"{self.path.name} drew no frame (it made no WebGL context)")
        return _display.composite(self.frames[-1][::-1])

    def _repr_png_(self):
        return _display.encode_png(self.image) if self.frames else None

    def __repr__(self):
        shape = "x".join(map(str, self.frames[-1].shape[1::-1])) if self.frames else "no canvas"
        return (f"<PageResult {self.path.name}: {len(self.frames)} frame(s) {shape}, "
                f"{len(self.console)} console line(s), {len(self.errors)} error(s)>")


def run(path, frames: int = 1, *, time_step: float = 1000 / 60, canvas: str | None = None,
        raise_errors: bool = True, window_size=(800, 600), library_path=LIBRARY_PATH,
        context_options: dict | None = None) -> PageResult:
    """Load the page at `path`, run `frames` animation frames and return a PageResult.

    The clock starts at 0 ms; frame i (from 1) runs at i * `time_step` ms: first the timers due
    by then, then the requestAnimationFrame callbacks, then the canvas is read (before a browser
    would composite it, i.e. clear it unless preserveDrawingBuffer). `canvas` picks the canvas by
    id (default: the first one that got a WebGL context). An uncaught JavaScript exception raises
    PageError with its JavaScript stack after the step it happened in (`raise_errors=False`
    keeps it in `.errors` instead). `library_path` is where `<script src>` and other URLs are
    looked for after the page's folder (Debian's /usr/share/javascript). `context_options` go to
    every softgl.Context the page makes (e.g. ``{"threads": 1}``).
    """
    if not isinstance(frames, int) or frames < 0:
        raise ValueError("run: frames must be an int >= 0")
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"softgl.page.run: no page at {path}")
    result = PageResult(path.resolve())
    browser = Browser(path, window_size=window_size, library_path=library_path,
                      context_options=context_options)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", GLWarning)

            def settle(step: str):
                for w in caught:
                    if issubclass(w.category, GLWarning):
                        result.errors.append(f"GL: {w.message}")
                    else:   # not ours to swallow
                        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
                caught.clear()
                if browser.js_errors:
                    stacks = browser.js_errors[:]
                    browser.js_errors.clear()
                    result.errors.extend(f"JavaScript: {s}" for s in stacks)
                    if raise_errors:
                        raise PageError(f"{path.name}, {step}: uncaught JavaScript exception\n{stacks[0]}")

            browser.load()
            settle("while loading")
            for i in range(1, frames + 1):
                t = i * time_step
                browser.js.runFrame(t)
                settle(f"frame {i}")
                target = _target(browser, canvas)
                if target is None:
                    continue
                gl = target.gl
                w, h = gl.drawingBufferWidth, gl.drawingBufferHeight
                result.frames.append(gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE))
                result.times.append(t)
                _display.present(gl)
            settle("after the last frame")
    finally:
        result.console = list(browser.console_lines)
        result.contexts = [c.gl for c in browser.contexts]
        browser.close()
    return result


def _target(browser: Browser, canvas_id: str | None):
    for c in browser.contexts:
        if canvas_id is None or c.canvas_element.id == canvas_id:
            return c
    return None
