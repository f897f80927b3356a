"""What a JavaScript page pays to reach softgl through softgl.page's bridge (STPyV8):

- a WebGL call from JavaScript (gl.blendFunc, gl.uniform4fv with a 4-element array,
  gl.uniformMatrix4fv with a Float32Array) against the same call made from Python;
- bufferData of 1 MiB (a Float32Array of 262,144 elements) from JavaScript against Python.

    python benchmarks/page_bridge.py            # writes benchmarks/results/page_bridge.md

Best of several repeats (wall clock; the load average is printed with the table).
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

import softgl
import softgl.page

REPEATS = 7
CALLS = 20000

PAGE = """<!DOCTYPE html><html><body><canvas id="c" width="64" height="64"></canvas><script>
const gl = document.getElementById('c').getContext('webgl2');
const program = gl.createProgram();
function compile(type, source) { const s = gl.createShader(type); gl.shaderSource(s, source); gl.compileShader(s); gl.attachShader(program, s); }
compile(gl.VERTEX_SHADER, 'uniform mat4 m; void main() { gl_Position = m * vec4(0.0); }');
compile(gl.FRAGMENT_SHADER, 'precision mediump float; uniform vec4 c; void main() { gl_FragColor = c; }');
gl.linkProgram(program); gl.useProgram(program);
const uc = gl.getUniformLocation(program, 'c'), um = gl.getUniformLocation(program, 'm');
const matrix = new Float32Array(16), big = new Float32Array(262144);
for (let i = 0; i < big.length; i++) big[i] = i;
const buffer = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
function timeIt(label, n, fn) {
  // performance.now() is the page's frame clock; real time comes from Python.
  const t0 = __now(); fn(n); const t1 = __now();
  console.log(label + ' ' + ((t1 - t0) / n * 1e6));
}
window.onload = () => {
  for (let r = 0; r < %(repeats)d; r++) {
    timeIt('blendFunc', %(calls)d, (n) => { for (let i = 0; i < n; i++) gl.blendFunc(gl.ONE, gl.ZERO); });
    timeIt('uniform4fv', %(calls)d, (n) => { for (let i = 0; i < n; i++) gl.uniform4fv(uc, [1, 0, 0, 1]); });
    timeIt('uniformMatrix4fv', %(calls)d, (n) => { for (let i = 0; i < n; i++) gl.uniformMatrix4fv(um, false, matrix); });
    timeIt('bufferData_1MiB', 20, (n) => { for (let i = 0; i < n; i++) gl.bufferData(gl.ARRAY_BUFFER, big, gl.STATIC_DRAW); });
  }
};
</script></body></html>"""


def javascript_costs(tmp: Path) -> dict:
    path = tmp / "bridge.html"
    path.write_text(PAGE % {"repeats": REPEATS, "calls": CALLS})
    from softgl.page import browser

    original = browser.Browser.__init__

    def init(self, *args, **kwargs):   # a real-time clock for this measurement only
        original(self, *args, **kwargs)
        setattr(self.ctx.locals, "__now", time.perf_counter)
    browser.Browser.__init__ = init
    try:
        result = softgl.page.run(path, frames=0)
    finally:
        browser.Browser.__init__ = original
    best = {}
    for _, line in result.console:
        name, us = line.split()
        best[name] = min(best.get(name, float("inf")), float(us))
    return best


def python_costs() -> dict:
    gl = softgl.Context(64, 64)
    prog = softgl.program(gl, "uniform mat4 m; void main() { gl_Position = m * vec4(0.0); }",
                          "precision mediump float; uniform vec4 c; void main() { gl_FragColor = c; }")
    gl.useProgram(prog)
    uc, um = gl.getUniformLocation(prog, "c"), gl.getUniformLocation(prog, "m")
    matrix, big = np.zeros(16, np.float32), np.arange(262144, dtype=np.float32)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    cases = {"blendFunc": (CALLS, lambda: gl.blendFunc(gl.ONE, gl.ZERO)),
             "uniform4fv": (CALLS, lambda: gl.uniform4fv(uc, [1, 0, 0, 1])),
             "uniformMatrix4fv": (CALLS, lambda: gl.uniformMatrix4fv(um, False, matrix)),
             "bufferData_1MiB": (20, lambda: gl.bufferData(gl.ARRAY_BUFFER, big, gl.STATIC_DRAW))}
    best = {}
    for name, (n, fn) in cases.items():
        for _ in range(REPEATS):
            t0 = time.perf_counter()
            for _ in range(n):
                fn()
            best[name] = min(best.get(name, float("inf")), (time.perf_counter() - t0) / n * 1e6)
    return best


def main():
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        js = javascript_costs(Path(tmp))
    py = python_costs()
    load = os.getloadavg()
    lines = ["# softgl.page bridge cost", "",
             f"`python benchmarks/page_bridge.py`, best of {REPEATS}; load average {load[0]:.1f} "
             f"(wall clock: under load every number grows).", "",
             "| call | from JavaScript (µs) | from Python (µs) |", "|---|---:|---:|"]
    for name in ("blendFunc", "uniform4fv", "uniformMatrix4fv", "bufferData_1MiB"):
        lines.append(f"| {name.replace('_1MiB', ' (1 MiB Float32Array)')} | {js[name]:.1f} | {py[name]:.1f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if "--no-write" not in sys.argv:
        out = Path(__file__).parent / "results" / "page_bridge.md"
        out.write_text(text)


if __name__ == "__main__":
    main()
