"""Time per frame of the three.js pages (tests/pages/three/) on softgl.page against the same page
in headless Chromium (SwiftShader), and their agreement with the committed Chromium references.

    python benchmarks/three_frames.py     # writes benchmarks/results/three_frames.md

softgl: N frames after a first one, each the page's animation frame then a 1-pixel readPixels;
Chromium: N further frames timed in
the page (performance.now before and after, finished by a 1-pixel readPixels). Wall clock; the
load average is printed with the table. Needs chromium and libjs-three.
"""
from __future__ import annotations

import logging
import os
import sys
import time
from pathlib import Path

import numpy as np

import softgl.io
import softgl.page

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "pages"))
from record_three import PAGES, run_in_chromium  # noqa: E402

N = 20


def softgl_frame_ms(page: Path) -> float:
    """softgl.page.run's frame loop after a first (warm-up) frame: the page's animation frame
    callbacks, then the 1-pixel read that ends Chromium's timing too."""
    from softgl.page.browser import Browser
    browser = Browser(page)
    try:
        browser.load()
        step = 1000 / 60
        browser.js.runFrame(step)
        gl = browser.contexts[0].gl
        t0 = time.perf_counter()
        for i in range(2, N + 2):
            browser.js.runFrame(i * step)
            gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)
        return (time.perf_counter() - t0) / N * 1e3
    finally:
        browser.close()


def main():
    logging.disable(logging.WARNING)
    rows = []
    for page in sorted(PAGES.glob("*.html")):
        frame = softgl.page.run(page, frames=1).frames[-1][::-1].astype(int)
        reference = softgl.io.load_image(PAGES / "reference" / f"{page.stem}.png", np.uint8).astype(int)
        d = np.abs(frame - reference).max(axis=2)
        _, chromium_ms = run_in_chromium(page, timed=N)
        rows.append((page.stem, (d <= 1).mean(), (d <= 4).mean(), softgl_frame_ms(page), chromium_ms))
    load = os.getloadavg()[0]
    lines = ["# three.js pages: softgl.page against Chromium (SwiftShader)", "",
             f"`python benchmarks/three_frames.py`; 160x120, load average {load:.1f} on 2 cores "
             f"(wall clock: under load both columns grow).", "",
             "| scene | within 1/255 | within 4/255 | softgl ms/frame | Chromium SwiftShader ms/frame |",
             "|---|---:|---:|---:|---:|"]
    for name, w1, w4, ms, cms in rows:
        lines.append(f"| {name} | {w1:.2%} | {w4:.2%} | {ms:.1f} | {cms:.1f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if "--no-write" not in sys.argv:
        (Path(__file__).parent / "results" / "three_frames.md").write_text(text)


if __name__ == "__main__":
    main()
