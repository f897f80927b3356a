"""Cost of WebGL state-setting calls from Python, in ns per call (issue 2).

    python benchmarks/call_overhead.py

The floor is the cheapest possible pybind11 call on the same object (a no-argument method that
returns a constant, isContextLost); the target is gl.blendFunc < 300 ns and within 2x of that floor.
Results are medians over repeated timing runs and are written to benchmarks/results/call_overhead.md.
"""
from __future__ import annotations

import platform
import statistics
import timeit
from pathlib import Path

import softgl

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


def machine_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def measure(statement: str, gl, number: int = 100_000, repeat: int = 9) -> float:
    times = timeit.repeat(statement, globals={"gl": gl}, number=number, repeat=repeat)
    return statistics.median(times) / number * 1e9


def main():
    gl = softgl.Context(64, 64, antialias=False)
    rows = [(name, measure(stmt, gl, number=20_000 if "clear(" in name else 100_000))
            for name, stmt in CALLS.items()]
    floor = rows[0][1]
    machine = f"{machine_name()}, Python {platform.python_version()}"
    lines = [f"# Python call overhead ({machine})", "",
             "| call | ns/call | x floor |", "|---|---:|---:|"]
    lines += [f"| `{name}` | {ns:.0f} | {ns / floor:.2f} |" for name, ns in rows]
    blend = rows[1][1]
    verdict = "met" if blend < 300 and blend < 2 * floor else "MISSED"
    lines += ["", f"Target `blendFunc` < 300 ns and < 2x floor: {verdict} ({blend:.0f} ns, "
              f"{blend / floor:.2f}x)."]
    text = "\n".join(lines) + "\n"
    out = Path(__file__).parent / "results" / "call_overhead.md"
    out.write_text(text)
    print(text)


if __name__ == "__main__":
    main()
