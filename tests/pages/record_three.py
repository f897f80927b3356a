"""Record the Chromium references of the three.js pages in tests/pages/three/: each page runs in
headless Chromium (SwiftShader, tests/webgl/chromium.py's flags) for the same frames at the same
clock as softgl.page.run(page, frames=N) gives it, and its canvas is saved as
tests/pages/three/reference/<page>.png (top row first). Needs `apt-get install chromium
libjs-three`; the tests only read the PNGs.

    python tests/pages/record_three.py            # every page
    python tests/pages/record_three.py lambert    # one page
"""
from __future__ import annotations

import base64
import html
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE.parent / "webgl"))
from chromium import CHROMIUM_FLAGS, chromium_binary, chromium_version  # noqa: E402

import softgl.io  # noqa: E402
from softgl.page import LIBRARY_PATH  # noqa: E402

PAGES = HERE / "three"
REFERENCES = PAGES / "reference"
FRAMES = {}            # page name -> frames (default 1)
TIME_STEP = 1000 / 60  # softgl.page.run's default

# Runs before the page's scripts: animation frames wait until the page has loaded, then run at
# the clock softgl.page uses; the canvas is read right after the last frame's callbacks.
HARNESS = """<script>
(function () {
  let callbacks = [];
  window.requestAnimationFrame = (fn) => { callbacks.push(fn); return callbacks.length; };
  let clock = 0;
  const realNow = performance.now.bind(performance);
  performance.now = () => clock;
  // Images the page creates load at time 0 in softgl.page, before its first frame: here the
  // frames wait until every image the page made has loaded (Chromium may fire 'load' earlier).
  const images = [];
  const track = (el) => { if (el && el.tagName === 'IMG') images.push(el); return el; };
  const createElement = document.createElement.bind(document), createElementNS = document.createElementNS.bind(document);
  document.createElement = (...a) => track(createElement(...a));
  document.createElementNS = (...a) => track(createElementNS(...a));
  const RealImage = window.Image;
  window.Image = function (...a) { return track(new RealImage(...a)); };
  const whenImagesLoaded = (fn) => () => {
    const wait = () => (images.every((i) => i.complete) ? fn() : setTimeout(wait, 10));
    wait();
  };
  window.addEventListener('load', whenImagesLoaded(() => {
    for (let i = 1; i <= %(frames)d; i++) {
      clock = i * %(step)r;
      const now = callbacks; callbacks = [];
      for (const fn of now) fn(clock);
    }
    const canvas = document.querySelector('canvas');
    const gl = canvas.getContext('%(kind)s');
    const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    let timed = '';
    if (%(timed)d > 0) {   // time per further frame, finished by a 1-pixel readPixels
      const t0 = realNow();
      for (let i = 1; i <= %(timed)d; i++) {
        clock += %(step)r;
        const now = callbacks; callbacks = [];
        for (const fn of now) fn(clock);
      }
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
      timed = ' ' + (realNow() - t0) / %(timed)d;
    }
    const px = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    let s = '';
    for (let i = 0; i < px.length; i++) s += String.fromCharCode(px[i]);
    const out = document.createElement('pre');
    out.id = 'out';
    out.textContent = w + ' ' + h + ' ' + btoa(s) + timed;
    document.body.appendChild(out);
  }));
})();
</script>"""


def harness_page(page: Path, timed: int = 0) -> str:
    text = page.read_text()
    frames = FRAMES.get(page.stem, 1)
    kind = "webgl2" if "webgl2" in text else "webgl"
    # <script src> relative to the library path, as softgl.page resolves it.
    def absolute(m):
        src = m.group(1)
        for base in [page.parent, *LIBRARY_PATH]:
            if (base / src).is_file():
                return f'src="{(base / src).resolve().as_uri()}"'
        raise FileNotFoundError(src)
    text = re.sub(r'src="([^":]+)"', absolute, text)
    # The page is run from a temporary copy: its relative URLs (images) resolve from its folder.
    base = f'<base href="{page.parent.resolve().as_uri()}/">'
    return text.replace("<head>", "<head>" + base + HARNESS % {"frames": frames, "step": TIME_STEP, "kind": kind,
                                                        "timed": timed}, 1)


def run_in_chromium(page: Path, timed: int = 0):
    """The page's canvas after its frames ((h, w, 4), row 0 at the bottom) and, with `timed`,
    Chromium's milliseconds per further frame."""
    text = harness_page(page, timed)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / page.name
        path.write_text(text)
        proc = subprocess.run([chromium_binary(), *CHROMIUM_FLAGS, "--allow-file-access-from-files",
                               path.as_uri()], capture_output=True, text=True, timeout=300)
    m = re.search(r'<pre id="out">(\d+) (\d+) (\S*)( [0-9.e+-]+)?</pre>', proc.stdout, re.S)
    if m is None:
        raise RuntimeError(f"{page.name}: Chromium gave no image\n{proc.stderr[-3000:]}")
    w, h = int(m.group(1)), int(m.group(2))
    pixels = np.frombuffer(base64.b64decode(html.unescape(m.group(3))), np.uint8).reshape(h, w, 4)
    return pixels, (float(m.group(4)) if m.group(4) else None)


def record(page: Path) -> Path:
    pixels, _ = run_in_chromium(page)
    REFERENCES.mkdir(exist_ok=True)
    out = REFERENCES / f"{page.stem}.png"
    softgl.io.save(pixels[::-1], out)
    return out


def main(names):
    pages = sorted(PAGES.glob("*.html"))
    if names:
        pages = [p for p in pages if p.stem in names]
    print(chromium_version())
    for page in pages:
        print(page.name, "->", record(page))


if __name__ == "__main__":
    main(sys.argv[1:])
