"""Cost of WebGL calls from Python, in ns per call (issues 2 and 7).

    python benchmarks/call_overhead.py

The floor is the cheapest possible pybind11 call on the same object (a no-argument method that
returns a constant, isContextLost). Targets: gl.blendFunc < 300 ns and within 2x of that floor
(issue 2); a small draw call < 5 us (issue 7), timed as a whole drawArrays of one point or one
small triangle with the program, buffer and a uniform change that precede it in a real loop.
Results are medians over repeated timing runs and are written to benchmarks/results/call_overhead.md.
"""
from __future__ import annotations

import platform
import statistics
import timeit
from pathlib import Path

import numpy as np

import softgl
import softgl.programs

CALLS = {
    "isContextLost()  [pybind11 floor]": "gl.isContextLost()",
    "blendFunc(SRC_ALPHA, ONE_MINUS_SRC_ALPHA)": "gl.blendFunc(770, 771)",
    "enable(BLEND)": "gl.enable(3042)",
    "depthFunc(LEQUAL)": "gl.depthFunc(515)",
    "clearColor(r, g, b, a)": "gl.clearColor(0.1, 0.2, 0.3, 1.0)",
    "viewport(0, 0, 64, 64)": "gl.viewport(0, 0, 64, 64)",
    "getParameter(BLEND_SRC_RGB)": "gl.getParameter(32969)",
    "getError()": "gl.getError()",
    "clear(COLOR) 64x64": "gl.clear(16384)",
}

# Small draws on the 64x64 context prepared by prepare_draws: (name, statement).
DRAWS = {
    "drawArrays(POINTS, 0, 1), 4 px point": "gl.drawArrays(gl.POINTS, 0, 1)",
    "drawArrays(TRIANGLES, 0, 3), 8 px triangle": "gl.drawArrays(gl.TRIANGLES, 1, 3)",
    "uniform4f + drawArrays(POINTS, 0, 1)":
        "gl.uniform4f(loc, 0.2, 0.4, 0.6, 1.0); gl.drawArrays(gl.POINTS, 0, 1)",
}

DRAW_VS = """#version 300 es
in vec2 aPos;
void main() { gl_Position = vec4(aPos, 0.0, 1.0); gl_PointSize = 2.0; }
"""
DRAW_FS = """#version 300 es
precision mediump float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; }
"""


def machine_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def measure(statement: str, gl, number: int = 100_000, repeat: int = 9, **names) -> float:
    times = timeit.repeat(statement, globals={"gl": gl, **names}, number=number, repeat=repeat)
    return statistics.median(times) / number * 1e9


def prepare_draws(gl):
    """Bind a uniform-colour program and a buffer holding one point (vertex 0) and one small
    triangle (vertices 1-3, about 8 px across on 64x64); return the uColor location."""
    prog = softgl.programs.program(gl, DRAW_VS, DRAW_FS)
    gl.useProgram(prog)
    vertices = np.array([0.0, 0.0, -0.1, -0.1, 0.15, -0.1, 0.0, 0.15], np.float32)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, vertices, gl.STATIC_DRAW)
    loc = gl.getAttribLocation(prog, "aPos")
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    color = gl.getUniformLocation(prog, "uColor")
    gl.uniform4f(color, 1.0, 0.5, 0.25, 1.0)
    return color


def main():
    gl = softgl.Context(64, 64, antialias=False)
    rows = [(name, measure(stmt, gl, number=20_000 if "clear(" in name else 100_000))
            for name, stmt in CALLS.items()]
    color = prepare_draws(gl)
    draws = [(name, measure(stmt, gl, number=20_000, loc=color)) for name, stmt in DRAWS.items()]
    assert gl.getError() == gl.NO_ERROR
    floor = rows[0][1]
    machine = f"{machine_name()}, Python {platform.python_version()}"
    lines = [f"# Python call overhead ({machine})", "",
             "| call | ns/call | x floor |", "|---|---:|---:|"]
    lines += [f"| `{name}` | {ns:.0f} | {ns / floor:.2f} |" for name, ns in rows + draws]
    blend = rows[1][1]
    verdict = "met" if blend < 300 and blend < 2 * floor else "MISSED"
    lines += ["", f"Target `blendFunc` < 300 ns and < 2x floor: {verdict} ({blend:.0f} ns, "
              f"{blend / floor:.2f}x)."]
    slowest = max(draws, key=lambda row: row[1])
    verdict = "met" if slowest[1] < 5000 else "MISSED"
    lines += ["", f"Target small draw call < 5 us: {verdict} (slowest: `{slowest[0]}`, "
              f"{slowest[1] / 1000:.2f} us)."]
    text = "\n".join(lines) + "\n"
    out = Path(__file__).parent / "results" / "call_overhead.md"
    out.write_text(text)
    print(text)


if __name__ == "__main__":
    main()
