"""Run time against error (issue 6): transparency methods and fog methods on fixed scenes.

    python benchmarks/blend_lab.py            # writes benchmarks/results/blend_lab.{md,png}

Transparency: softgl.transparency.demo_scene() at 320x320; every method's error is measured
against the exact A-buffer (SOFTGL_exact_transparency) image, RGB, in [0, 1] units. Depth peeling
and WBOIT are computed from the A-buffer's per-sample lists (their arithmetic, not a multi-pass
GPU implementation), so their times are softgl's capture + resolve, not what a GPU would spend.

Fog: a 40 x 40 ground plane seen at a grazing angle, constant color, fog toward a sky color. The
reference is the GL fog formula evaluated in float64 per pixel centre with the eye distance from
an exact ray-plane intersection; pixels whose footprint leaves the plane are not compared. Methods:
SOFTGL_fog (per fragment, fixed function), the same formula in a GLSL fragment shader, and the
fog factor computed per vertex in GLSL and interpolated, on a fine (64x64) and a coarse (4x4) grid.

Times are the best of REPEAT runs of clear + draw (+ resolve), without readback or context
creation, at the machine's default thread count; errors are deterministic, times are not.
"""
from __future__ import annotations

import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

import softgl
from softgl import geometry, transparency as tr
from softgl.transforms import column_major, look_at, perspective

RESULTS = Path(__file__).resolve().parent / "results"
SIZE = 320
REPEAT = 5


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} hardware threads, Python {platform.python_version()}"


# ---------------------------------------------------------------------------------- transparency

def transparency_rows():
    scene = tr.demo_scene()
    kw = dict(width=SIZE, height=SIZE, repeat=REPEAT)
    results = tr.compare(scene, peeling_layers=(1, 2, 3, 4, 6, 8, 12, 16), wboit_weights=(7, 8, 9, 10), **kw)
    complexity = tr.depth_complexity(scene, width=SIZE, height=SIZE)
    rows = [(name, r.seconds, r.error.rmse, r.error.max, r.error.psnr) for name, r in results.items()]
    return rows, int(complexity.max()), float(complexity[complexity > 0].mean())


# ---------------------------------------------------------------------------------- fog

FOG_COLOR = (0.62, 0.72, 0.85)
BASE = (0.75, 0.55, 0.30)
FOGS = {"LINEAR": dict(start=2.0, end=30.0), "EXP": dict(density=0.09), "EXP2": dict(density=0.07)}
EYE, TARGET = (0.0, 1.2, 0.0), (0.0, 0.4, -12.0)
HALF = 20.0   # the plane spans [-20, 20]^2 at y = 0

VS_FRAG = """
attribute vec3 aPos; uniform mat4 uMV, uP; varying float vDist;
void main() { vec4 e = uMV * vec4(aPos, 1.0); vDist = -e.z; gl_Position = uP * e; }
"""
VS_VERT = """
attribute vec3 aPos; uniform mat4 uMV, uP; uniform int uMode; uniform float uA, uB; varying float vF;
float fogFactor(float c) {
    if (uMode == 0) return clamp((uB - c) / (uB - uA), 0.0, 1.0);
    if (uMode == 1) return clamp(exp(-uA * c), 0.0, 1.0);
    return clamp(exp(-(uA * c) * (uA * c)), 0.0, 1.0);
}
void main() { vec4 e = uMV * vec4(aPos, 1.0); vF = fogFactor(-e.z); gl_Position = uP * e; }
"""
FS_FRAG = """
precision highp float; uniform vec3 uBase, uFog; uniform int uMode; uniform float uA, uB; varying float vDist;
float fogFactor(float c) {
    if (uMode == 0) return clamp((uB - c) / (uB - uA), 0.0, 1.0);
    if (uMode == 1) return clamp(exp(-uA * c), 0.0, 1.0);
    return clamp(exp(-(uA * c) * (uA * c)), 0.0, 1.0);
}
void main() { float f = fogFactor(vDist); gl_FragColor = vec4(mix(uFog, uBase, f), 1.0); }
"""
FS_VERT = """
precision highp float; uniform vec3 uBase, uFog; varying float vF;
void main() { gl_FragColor = vec4(mix(uFog, uBase, vF), 1.0); }
"""
FS_PLAIN = """
precision highp float; uniform vec3 uBase; varying float vDist;
void main() { gl_FragColor = vec4(uBase, 1.0); }
"""


def fog_factor(mode, c):
    p = FOGS[mode]
    if mode == "LINEAR":
        f = (p["end"] - c) / (p["end"] - p["start"])
    elif mode == "EXP":
        f = np.exp(-p["density"] * c)
    else:
        f = np.exp(-(p["density"] * c) ** 2)
    return np.clip(f, 0, 1)


def fog_reference(view, proj, mode):
    """float64 fog per pixel centre (rows top-down) and the mask of pixels to compare."""
    inv = np.linalg.inv(np.asarray(proj, np.float64))
    vinv = np.linalg.inv(np.asarray(view, np.float64))

    def hit(px, py):
        ndc = np.stack([2 * px / SIZE - 1, 2 * py / SIZE - 1, np.ones_like(px), np.ones_like(px)], -1)
        d = ndc @ inv.T
        d = d[..., :3] / d[..., 3:]                  # a point on the far plane, eye space
        o_w = vinv[:3, 3]
        d_w = d @ vinv[:3, :3].T                     # ray direction in world space
        t = -o_w[1] / np.where(d_w[..., 1] < 0, d_w[..., 1], -1e-300)
        p_w = o_w + t[..., None] * d_w
        inside = (d_w[..., 1] < 0) & (np.abs(p_w[..., 0]) < HALF) & (np.abs(p_w[..., 2]) < HALF)
        eye_z = (np.c_[p_w.reshape(-1, 3), np.ones(p_w[..., 0].size)] @ np.asarray(view, np.float64).T)[:, 2]
        return inside, -eye_z.reshape(px.shape)

    ys, xs = np.mgrid[0:SIZE, 0:SIZE].astype(np.float64)
    inside, c = hit(xs + 0.5, ys + 0.5)
    for dx, dy in ((0, 0), (1, 0), (0, 1), (1, 1)):      # the whole pixel square on the plane
        inside &= hit(xs + dx, ys + dy)[0]
    f = fog_factor(mode, c)[..., None]
    ref = f * np.array(BASE) + (1 - f) * np.array(FOG_COLOR)
    return ref[::-1], inside[::-1]


def fog_rows():
    view = look_at(EYE, TARGET, (0, 1, 0))
    proj = perspective(0.9, 1.0, 0.3, 100.0)
    rows = []
    for mode in FOGS:
        ref, mask = fog_reference(view, proj, mode)
        for method, grid in (("SOFTGL_fog", 64), ("GLSL per fragment", 64), ("GLSL per vertex", 64),
                             ("GLSL per vertex", 4)):
            gl = softgl.Context(SIZE, SIZE, antialias=False, alpha=False, preserveDrawingBuffer=True, strict=True)
            plane = geometry.plane(2 * HALF, 2 * HALF, grid, grid)
            vs, fs = {"SOFTGL_fog": (VS_FRAG, FS_PLAIN), "GLSL per fragment": (VS_FRAG, FS_FRAG),
                      "GLSL per vertex": (VS_VERT, FS_VERT)}[method]
            prog = softgl.program(gl, vs, fs, {"aPos": 0})
            gl.useProgram(prog)
            u = lambda name: gl.getUniformLocation(prog, name)
            gl.uniformMatrix4fv(u("uMV"), False, column_major(view))
            gl.uniformMatrix4fv(u("uP"), False, column_major(proj))
            gl.uniform3f(u("uBase"), *BASE)
            p = FOGS[mode]
            if method == "SOFTGL_fog":
                ext = gl.getExtension("SOFTGL_fog")
                gl.enable(ext.FOG)
                ext.fogi(ext.FOG_MODE, getattr(ext, mode))
                for key, pname in (("start", ext.FOG_START), ("end", ext.FOG_END), ("density", ext.FOG_DENSITY)):
                    if key in p:
                        ext.fogf(pname, p[key])
                ext.fogfv(ext.FOG_COLOR, [*FOG_COLOR, 1.0])
            else:
                gl.uniform3f(u("uFog"), *FOG_COLOR)
                gl.uniform1i(u("uMode"), list(FOGS).index(mode))
                gl.uniform1f(u("uA"), p.get("start", p.get("density", 0.0)))
                gl.uniform1f(u("uB"), p.get("end", 0.0))
            buf, ibuf = gl.createBuffer(), gl.createBuffer()
            gl.bindBuffer(gl.ARRAY_BUFFER, buf)
            gl.bufferData(gl.ARRAY_BUFFER, plane.positions, gl.STATIC_DRAW)
            gl.enableVertexAttribArray(0)
            gl.vertexAttribPointer(0, 3, gl.FLOAT, False, 0, 0)
            gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibuf)
            gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, plane.indices, gl.STATIC_DRAW)
            gl.clearColor(*FOG_COLOR, 1.0)
            best = math.inf
            for _ in range(REPEAT):
                t0 = time.perf_counter()
                gl.clear(gl.COLOR_BUFFER_BIT)
                gl.drawElements(gl.TRIANGLES, plane.count, plane.index_type, 0)
                best = min(best, time.perf_counter() - t0)
            img = gl.readPixels(0, 0, SIZE, SIZE, gl.RGBA, gl.UNSIGNED_BYTE)[::-1, :, :3] / 255.0
            d = (img - ref)[mask]
            rmse = float(np.sqrt(np.mean(d * d)))
            rows.append((f"{mode} {method}" + (f" ({grid}x{grid} grid)" if "vertex" in method else ""),
                         best, rmse, float(np.abs(d).max()), math.inf if rmse == 0 else 20 * math.log10(1 / rmse)))
    return rows


# ---------------------------------------------------------------------------------- output

def markdown(rows) -> str:
    out = ["| method | time (ms) | RMSE | max | PSNR (dB) |", "|---|---:|---:|---:|---:|"]
    for name, t, rmse, mx, psnr in rows:
        out.append(f"| {name} | {t * 1e3:.2f} | {rmse:.5f} | {mx:.4f} | "
                   f"{'inf' if math.isinf(psnr) else f'{psnr:.2f}'} |")
    return "\n".join(out)


def pareto(rows):
    """Names of the rows no other row beats in both time and error."""
    return {r[0] for r in rows if not any(o[1] <= r[1] and o[2] <= r[2] and (o[1] < r[1] or o[2] < r[2])
                                         for o in rows)}


def plot(panels, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(panels), figsize=(7 * len(panels), 6))
    floor = 1e-5   # zero error (the reference itself) is drawn here, on a log axis
    for ax, (title, rows) in zip(axes, panels):
        front = pareto(rows)
        pts = sorted((r for r in rows if r[0] in front), key=lambda r: r[1])
        ax.plot([r[1] * 1e3 for r in pts], [max(r[2], floor) for r in pts], "-", color="0.7", zorder=1)
        for name, t, rmse, _, _ in rows:
            ax.scatter(t * 1e3, max(rmse, floor), s=36, zorder=2,
                       color="tab:red" if name in front else "tab:blue")
            ax.annotate(name + (" (0)" if rmse == 0 else ""), (t * 1e3, max(rmse, floor)), fontsize=7,
                        xytext=(4, 3), textcoords="offset points")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("run time (ms, best of %d)" % REPEAT)
        ax.set_ylabel("RMSE vs exact (RGB, [0, 1])")
        ax.set_title(title + "  (red: Pareto front)")
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    RESULTS.mkdir(exist_ok=True)
    t_rows, complexity, mean_complexity = transparency_rows()
    f_rows = fog_rows()
    md = [
        "# Blend lab: run time against error (transparency, fog)",
        "",
        f"Machine: {machine()}. softgl at its default thread count. Reproduce: `python benchmarks/blend_lab.py`.",
        "Errors are deterministic; times are the best of %d runs and vary from run to run." % REPEAT,
        "",
        f"## Transparency: `softgl.transparency.demo_scene()`, {SIZE}x{SIZE}, 1 sample",
        "",
        f"Reference: the exact A-buffer. Depth complexity: max {complexity}, mean {mean_complexity:.2f} "
        "transparent fragments per covered pixel. Peeling and WBOIT are computed from the A-buffer "
        "lists (their arithmetic), so their times include the capture.",
        "",
        markdown(t_rows),
        "",
        f"## Fog: ground plane at a grazing angle, {SIZE}x{SIZE}",
        "",
        "Reference: the GL 1.x fog formula in float64 at each pixel centre (exact ray-plane eye distance).",
        "",
        markdown(f_rows),
        "",
        "![run time against error](blend_lab.png)",
        "",
    ]
    (RESULTS / "blend_lab.md").write_text("\n".join(md))
    plot([("transparency", t_rows), ("fog", f_rows)], RESULTS / "blend_lab.png")
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
