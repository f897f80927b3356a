"""Seconds per work-budget unit (docs/reliability.md, "Work budget and Ctrl-C"): the calibration of
the rollback threshold (pipeline/draw_rollback.h, kRollbackWorkThreshold). Each case is one draw
at 1 thread; it prints the units the draw charged (gl.work_budget()["last_call_used"]), its CPU
time (the best of `repeat`) and the time 2^28 units take at that rate.

    python benchmarks/work_units.py [repeat]
"""
import sys
import time

import numpy as np

import softgl

VS = "#version 300 es\nin vec2 p;\nvoid main() { gl_Position = vec4(p, 0.0, 1.0); gl_PointSize = 1.0; }"


def fs(body):
    return ("#version 300 es\nprecision highp float;\nuniform int n;\nout vec4 o;\nvoid main() {\n"
            "    float x = gl_FragCoord.x * 1e-6;\n" + body + "\n    o = vec4(x, 0.5, 0.0, 0.5);\n}\n")


def quad_layers(k):
    return np.tile(np.array([-1, -1, 1, -1, -1, 1, -1, 1, 1, -1, 1, 1], np.float32), k)


def small_triangles(side, n):
    rng = np.random.default_rng(1)
    c = rng.uniform(-1, 1, (n, 1, 2))
    return (c + rng.uniform(-2.0 / side, 2.0 / side, (n, 3, 2))).astype(np.float32).ravel()


CASES = {
    # name: (canvas side, fragment body, uniform n, vertices, mode, blend)
    # A uniform bound keeps copies for a rollback (rule 2); the same loop with a constant bound
    # keeps none: the difference is what the copies cost.
    "fragment loop (n=16), 512^2": (512, "for (int i = 0; i < n; i++) x = x * 0.999 + 0.001;", 16, quad_layers(1), "TRIANGLES", False),
    "fragment loop (16), 512^2": (512, "for (int i = 0; i < 16; i++) x = x * 0.999 + 0.001;", 0, quad_layers(1), "TRIANGLES", False),
    "fragment loop (n=64), 512^2": (512, "for (int i = 0; i < n; i++) x = x * 0.999 + 0.001;", 64, quad_layers(1), "TRIANGLES", False),
    "fragment loop (n=1000)": (256, "for (int i = 0; i < n; i++) x = x * 0.999 + 0.001;", 1000, quad_layers(1), "TRIANGLES", False),
    "32 blended full-screen layers": (512, "x += 0.25;", 0, quad_layers(32), "TRIANGLES", True),
    "200,000 small triangles": (512, "x += 0.25;", 0, small_triangles(512, 200_000), "TRIANGLES", False),
    "10^6 points": (512, "x += 0.25;", 0, np.random.default_rng(2).uniform(-1, 1, 2_000_000).astype(np.float32), "POINTS", False),
}


def run(name, repeat):
    side, body, n, verts, mode, blend = CASES[name]
    gl = softgl.Context(side, side, threads=1, antialias=False)
    prog = softgl.program(gl, VS, fs(body), {"p": 0})
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "n"), n)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, verts, gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
    if blend:
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    count = len(verts) // 2
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        gl.drawArrays(getattr(gl, mode), 0, count)
        best = min(best, time.process_time() - t0)
    units = gl.work_budget()["last_call_used"]
    gl.stats(reset=True)
    gl.drawArrays(getattr(gl, mode), 0, count)
    return units, best, gl.stats()["draws_with_rollback"]


def main():
    repeat = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    print("| draw (1 thread) | keeps copies | units | CPU s | ns per unit | 2^28 units take |")
    print("|---|---|---:|---:|---:|---:|")
    for name in CASES:
        units, s, copies = run(name, repeat)
        print(f"| {name} | {'yes' if copies else 'no'} | {units:,} | {s:.4f} | {1e9 * s / units:.2f} | {s / units * 2**28:.2f} s |")


if __name__ == "__main__":
    main()
