"""softgl vs Mesa llvmpipe, side by side: the scenes of issue 7 and the executor benchmark of issue 3.

    python benchmarks/suite.py [--quick] [--size N] [--threads 1,2] [--only key,key] [--out FILE]

Every scene (benchmarks/scenes.py) is built once as a scene description and rendered by softgl
(through its WebGL API, from Python) and by llvmpipe (EGL + GLES 3, ctypes, in a worker process
with LP_NUM_THREADS = threads), with the same shaders, state and thread count. Timing alternates
A/B rounds (softgl, llvmpipe, llvmpipe, softgl, ...) so that load changes hit both sides alike;
each side reports the median frame (clear + uniforms + draws; llvmpipe also glFinish and, with
MSAA, its resolve blit, which softgl does at readPixels). The images are compared first: max
channel difference and the number of pixels differing by more than 1 (edge-rule differences).

The "limit" column: bytes the frame must move at least (clear, colour writes, blend reads, depth
reads/writes, from softgl's own counters in gl.stats()) divided by time, as a share of the
measured memory copy bandwidth at the same thread count. Results go to benchmarks/results/suite.md.
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path

# NumPy's BLAS threads spin after each call and would steal a core from both renderers.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import scenes as S  # noqa: E402
from reference_gl import LlvmpipeProcess, machine_name, measure_memory_bandwidth  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results"


def frame_bytes(stats: dict, size: int, samples: int, depth: bool) -> float:
    """The least memory traffic of one frame, from softgl's counters for that frame."""
    s = max(1, samples)
    clear = size * size * s * (4 + (4 if depth else 0))
    color = 4 * stats["samples_written"] + 4 * stats["samples_blended"]
    tested = stats["samples_written"] + stats["fragments_killed_early"] + stats["fragments_killed_late"]
    return clear + color + (8 * tested if depth else 0)


def compare_images(a: np.ndarray, b: np.ndarray) -> tuple[int, int]:
    d = np.abs(a.astype(np.int16) - b.astype(np.int16)).max(axis=-1)
    return int(d.max()), int((d > 1).sum())


class Side:
    """One implementation at one thread count and sample count, reused across scenes."""

    def __init__(self, name, renderer):
        self.name, self.r = name, renderer


def ab_times(soft, lp, scene, rounds: int, per_round: int) -> tuple[list, list]:
    ts, tl = [], []
    for k in range(rounds):
        order = (soft, lp) if k % 2 == 0 else (lp, soft)
        for side in order:
            t = side.time_draws(scene, repeats=per_round, warmup=1 if k < 2 else 0)
            (ts if side is soft else tl).extend(t)
    return ts, tl


def run_scene(spec, size, threads, soft, lp, budget_s: float):
    scene = spec.build(size)
    a = soft.render(scene)
    b = lp.render(scene)
    maxdiff, ndiff = compare_images(a, b)
    # One measured frame of each decides the repeat count (time budget per side).
    t0 = time.perf_counter(); soft.render(scene); t_s = time.perf_counter() - t0
    t_l = statistics.median(lp.time_draws(scene, repeats=1, warmup=0))
    per_frame = max(t_s, t_l, 1e-4)
    total = int(min(40, max(4, budget_s / per_frame)))
    rounds = 4 if total >= 8 else 2
    per_round = max(1, total // rounds)
    ts, tl = ab_times(soft, lp, scene, rounds, per_round)
    # Counters of exactly one frame.
    soft.gl._stats(True)
    soft._frame(soft._begin(scene))
    st = soft.gl._stats(True)
    ms, ml = statistics.median(ts), statistics.median(tl)
    return dict(key=spec.key, title=spec.title, threads=threads, samples=spec.samples,
                softgl=ms, llvmpipe=ml, ratio=ms / ml, soft_spread=(min(ts), max(ts)),
                lp_spread=(min(tl), max(tl)), n=(len(ts), len(tl)), maxdiff=maxdiff, ndiff=ndiff,
                bytes=frame_bytes(st, size, spec.samples, scene.state.depth_test), stats=st,
                note=spec.note)


def fmt_ms(t):
    return f"{t * 1e3:.2f}" if t < 0.1 else f"{t * 1e3:.1f}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="256x256, short time budget")
    ap.add_argument("--size", type=int, default=None)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--only", default="")
    ap.add_argument("--budget", type=float, default=None, help="seconds of timed frames per side and scene")
    ap.add_argument("--out", default=str(RESULTS / "suite.md"))
    args = ap.parse_args(argv)
    size = args.size or (256 if args.quick else 1024)
    budget = args.budget or (0.4 if args.quick else 2.0)
    threads_list = [int(t) for t in args.threads.split(",")]
    only = set(filter(None, args.only.split(",")))
    specs = [s for s in S.SUITE if not only or s.key in only]
    execs = [s for s in S.EXECUTOR if not only or s.key in only]
    texs = [s for s in S.TEXTURED if not only or s.key in only]

    load0 = os.getloadavg()
    started = time.strftime("%Y-%m-%d %H:%M")
    bw = {t: measure_memory_bandwidth(size_mb=64 if args.quick else 256, repeats=5, threads=t)
          for t in threads_list}
    rows, exec_rows, tex_rows = [], [], []
    info = {}
    for t in threads_list:
        for samples in sorted({s.samples for s in specs} | ({0} if (execs and t == 1) or texs else set())):
            group = [s for s in specs if s.samples == samples]
            group_exec = execs if (samples == 0 and t == 1) else []
            group_tex = texs if samples == 0 else []
            if not group and not group_exec and not group_tex:
                continue
            soft = S.SoftglRenderer(size, size, threads=t, samples=samples)
            with LlvmpipeProcess(size, size, threads=t, samples=samples) as lp:
                info = lp.info()
                for spec in group:
                    r = run_scene(spec, size, t, soft, lp, budget)
                    rows.append(r)
                    print(f"  t={t} {spec.key:<16} softgl {fmt_ms(r['softgl']):>8} ms  llvmpipe "
                          f"{fmt_ms(r['llvmpipe']):>8} ms  ratio {r['ratio']:.2f}  maxdiff {r['maxdiff']}"
                          f" ({r['ndiff']} px)", flush=True)
                for spec in group_exec:
                    r = run_scene(spec, size, t, soft, lp, budget)
                    frags = 8 * size * size
                    r["frag_s"] = (frags / r["softgl"], frags / r["llvmpipe"])
                    exec_rows.append(r)
                    print(f"  exec {spec.key:<12} softgl {r['frag_s'][0] / 1e6:.1f} Mfrag/s  llvmpipe "
                          f"{r['frag_s'][1] / 1e6:.1f} Mfrag/s  ratio {r['ratio']:.2f}", flush=True)
                for spec in group_tex:
                    r = run_scene(spec, size, t, soft, lp, budget)
                    frags = 8 * size * size
                    r["frag_s"] = (frags / r["softgl"], frags / r["llvmpipe"])
                    tex_rows.append(r)
                    print(f"  t={t} {spec.key:<14} softgl {r['frag_s'][0] / 1e6:.1f} Mfrag/s  llvmpipe "
                          f"{r['frag_s'][1] / 1e6:.1f} Mfrag/s  ratio {r['ratio']:.2f}  maxdiff {r['maxdiff']}"
                          f" ({r['ndiff']} px)", flush=True)
    load1 = os.getloadavg()
    text = report(rows, exec_rows, size, bw, info, load0, load1, started, args.quick, tex_rows)
    print()
    print(text)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(text)
    return rows, exec_rows


def report(rows, exec_rows, size, bw, info, load0, load1, started, quick, tex_rows=()):
    out = []
    out.append(f"# softgl vs llvmpipe ({'quick, ' if quick else ''}{size}x{size})\n")
    out.append(f"- machine: {machine_name()}, {os.cpu_count()} logical CPUs; load average "
               f"{load0[0]:.2f} at start, {load1[0]:.2f} at end (1 min); run {started}")
    out.append(f"- llvmpipe: {info.get('renderer', '?')} / {info.get('version', '?')}")
    out.append("- memory copy bandwidth (read+write): " +
               ", ".join(f"{v:.1f} GB/s at {t} thread{'s' if t > 1 else ''}" for t, v in bw.items()))
    out.append("- times: median ms per frame (clear + uniforms + draws), A/B alternated; "
               "ratio = softgl / llvmpipe (< 1: softgl faster); limit = least bytes moved per "
               "frame / time, as a share of the copy bandwidth; diff = max channel difference of "
               "the two images (pixels differing by more than 1)")
    out.append("- command: `python benchmarks/suite.py" + (" --quick" if quick else "") + "`\n")
    for t in sorted({r["threads"] for r in rows}):
        sub = [r for r in rows if r["threads"] == t]
        out.append(f"## threads = {t} (softgl threads={t}, LP_NUM_THREADS={t})\n")
        out.append("| scene | softgl ms | llvmpipe ms | ratio | limit | diff | note |")
        out.append("| --- | ---: | ---: | ---: | ---: | ---: | --- |")
        for r in sub:
            share = r["bytes"] / r["softgl"] / (bw[t] * 1e9)
            out.append(f"| {r['title']} | {fmt_ms(r['softgl'])} | {fmt_ms(r['llvmpipe'])} | "
                       f"{r['ratio']:.2f} | {share * 100:.0f}% | {r['maxdiff']} ({r['ndiff']} px) | "
                       f"{r['note']} |")
        g = math.exp(statistics.mean(math.log(r["ratio"]) for r in sub))
        out.append(f"\ngeometric mean ratio: **{g:.2f}** ({sum(r['ratio'] < 1 for r in sub)} of "
                   f"{len(sub)} scenes faster than llvmpipe)\n")
    if exec_rows:
        out.append("## Executor throughput (issue 3), 1 thread\n")
        out.append("8 full-screen quads, no blending, no depth: fragments shaded per second on one "
                   "core (raster and write included on both sides).\n")
        out.append("| shader | softgl Mfrag/s | llvmpipe Mfrag/s | ratio (time) |")
        out.append("| --- | ---: | ---: | ---: |")
        for r in exec_rows:
            out.append(f"| {r['title']} | {r['frag_s'][0] / 1e6:.1f} | {r['frag_s'][1] / 1e6:.1f} | "
                       f"{r['ratio']:.2f} |")
    if tex_rows:
        out.append("\n## Textured fill rate (issue 5)\n")
        out.append("8 full-screen quads, one `texture()` lookup each, no blending, no depth; a 512x512 RGBA8 "
                   "texture repeated 3 times across the screen (minified 1.5x at 1024²: the trilinear row "
                   "blends mip levels 0 and 1).\n")
        out.append("| filter | threads | softgl ms | llvmpipe ms | softgl Mfrag/s | llvmpipe Mfrag/s | ratio | diff |")
        out.append("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
        for r in tex_rows:
            out.append(f"| {r['title']} | {r['threads']} | {fmt_ms(r['softgl'])} | {fmt_ms(r['llvmpipe'])} | "
                       f"{r['frag_s'][0] / 1e6:.1f} | {r['frag_s'][1] / 1e6:.1f} | {r['ratio']:.2f} | "
                       f"{r['maxdiff']} ({r['ndiff']} px) |")
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    main()
