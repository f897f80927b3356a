"""Run JavaScript in real WebGL (headless Chromium + SwiftShader) and get a JSON result back.

Used only to (re)generate the reference files under tests/webgl/reference/; the test suite reads
those files and never needs Chromium.  Install with `apt-get install chromium`.
"""
from __future__ import annotations

import html
import json
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--use-angle=swiftshader",
                  "--enable-unsafe-swiftshader", "--dump-dom"]


def chromium_binary() -> str:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        raise RuntimeError("headless Chromium is needed to regenerate WebGL references: "
                           "apt-get install chromium")
    return exe


def chromium_version() -> str:
    return subprocess.run([chromium_binary(), "--version"], capture_output=True,
                          text=True, check=True).stdout.strip()


def run_script(script: str, timeout: float = 120.0):
    """Run `script` in a page; it must assign its JSON-serialisable answer to `result`."""
    page = ("<html><body><pre id=out></pre><script>\nlet result = null;\n" + script +
            "\ndocument.getElementById('out').textContent = JSON.stringify(result);\n"
            "</script></body></html>")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "page.html"
        path.write_text(page)
        proc = subprocess.run([chromium_binary(), *CHROMIUM_FLAGS, path.as_uri()],
                              capture_output=True, text=True, timeout=timeout)
    match = re.search(r'<pre id="out">(.*?)</pre>', proc.stdout, re.S)
    if match is None or not match.group(1):
        raise RuntimeError("Chromium gave no result:\n" + proc.stderr[-2000:])
    return json.loads(html.unescape(match.group(1)))
