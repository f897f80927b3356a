"""How softgl's frame time grows with triangles, pixels and threads (issue 7, "Scaling").

    python benchmarks/scaling.py [--max-tris 1000000] [--max-size 4096] [--threads 1,2] [--llvmpipe]

Two sweeps, each at every thread count, median of a few frames (clear + draws), from Python:

* triangles: n = 10^2 ... 10^6 small depth-tested triangles (about 8 px each, per-vertex colour)
  at 1024x1024 -- the vertex, setup and binning side;
* pixels: 8 full-screen alpha-blended layers at 256^2 ... 4096^2 -- the fill side.

With --llvmpipe the same scenes also run in Mesa llvmpipe (LP_NUM_THREADS = threads), A/B
alternated. Results go to benchmarks/results/scaling.md.
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

# NumPy's BLAS threads spin after each call and would steal a core from both renderers.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent))
import scenes as S  # noqa: E402
from reference_gl import LlvmpipeProcess, machine_name  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results"


def median_ms(renderer, scene, budget_s: float) -> float:
    t = renderer.time_draws(scene, repeats=1, warmup=1)[0]
    reps = int(min(15, max(3, budget_s / max(t, 1e-4))))
    return statistics.median(renderer.time_draws(scene, repeats=reps, warmup=0)) * 1e3


def sweep(cases, threads_list, budget, use_lp):
    rows = []
    for label, size, build, per in cases:
        scene = build(size)
        row = {"label": label, "per": per}
        for t in threads_list:
            soft = S.SoftglRenderer(size, size, threads=t)
            if use_lp:
                with LlvmpipeProcess(size, size, threads=t) as lp:
                    a = median_ms(soft, scene, budget)
                    b = median_ms(lp, scene, budget)
                    a = min(a, median_ms(soft, scene, budget))   # A/B/A: the better softgl median
                    row[("lp", t)] = b
            else:
                a = median_ms(soft, scene, budget)
            row[("soft", t)] = a
            del soft
            print(f"  {label:>12} t={t}: softgl {a:9.2f} ms" +
                  (f"  llvmpipe {row[('lp', t)]:9.2f} ms" if use_lp else ""), flush=True)
        rows.append(row)
    return rows


def table(title, unit, rows, threads_list, use_lp):
    out = [f"## {title}\n"]
    head = ["| " + unit + " |"]
    sep = ["| ---: |"]
    for t in threads_list:
        head.append(f" softgl t={t} ms | ns per {rows[0]['per'][0]} |")
        sep.append(" ---: | ---: |")
        if use_lp:
            head.append(f" llvmpipe t={t} ms | ratio |")
            sep.append(" ---: | ---: |")
    if len(threads_list) > 1:
        head.append(f" speed-up t={threads_list[-1]} |")
        sep.append(" ---: |")
    out.append("".join(head))
    out.append("".join(sep))
    for r in rows:
        line = f"| {r['label']} |"
        for t in threads_list:
            ms = r[("soft", t)]
            line += f" {ms:.2f} | {ms * 1e6 / r['per'][1]:.2f} |"
            if use_lp:
                line += f" {r[('lp', t)]:.2f} | {ms / r[('lp', t)]:.2f} |"
        if len(threads_list) > 1:
            line += f" {r[('soft', threads_list[0])] / r[('soft', threads_list[-1])]:.2f} |"
        out.append(line)
    return "\n".join(out) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--max-tris", type=int, default=1_000_000)
    ap.add_argument("--max-size", type=int, default=4096)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--budget", type=float, default=1.5, help="seconds of timed frames per point")
    ap.add_argument("--llvmpipe", action="store_true", help="also time Mesa llvmpipe")
    ap.add_argument("--out", default=str(RESULTS / "scaling.md"))
    args = ap.parse_args(argv)
    threads_list = [int(t) for t in args.threads.split(",")]
    load0 = os.getloadavg()
    started = time.strftime("%Y-%m-%d %H:%M")

    tris = []
    n = 100
    while n <= args.max_tris:
        tris.append((f"{n:,}", 1024, lambda s, n=n: S.tiny_depth_triangles(s, n=n, pixels=4.0), ("triangle", n)))
        n *= 10
    pix = []
    size = 256
    while size <= args.max_size:
        pix.append((f"{size}²", size, lambda s: S.fullscreen_layers(s, layers=8), ("pixel", 8 * size * size)))
        size *= 2
    print("triangles:")
    rows_t = sweep(tris, threads_list, args.budget, args.llvmpipe)
    print("pixels:")
    rows_p = sweep(pix, threads_list, args.budget, args.llvmpipe)
    load1 = os.getloadavg()

    text = [f"# softgl scaling (triangles, pixels, threads)\n",
            f"- machine: {machine_name()}, {os.cpu_count()} logical CPUs; load average {load0[0]:.2f} at "
            f"start, {load1[0]:.2f} at end (1 min); run {started}",
            "- times: median ms per frame (clear + draws) from Python; ns per triangle / per blended "
            "pixel = time / count",
            "- command: `python benchmarks/scaling.py" + (" --llvmpipe" if args.llvmpipe else "") +
            (f" --max-size {args.max_size}" if args.max_size != 4096 else "") + "`\n",
            table("Triangles (about 8 px each, depth-tested, 1024x1024)", "triangles", rows_t, threads_list,
                  args.llvmpipe),
            table("Pixels (8 full-screen alpha-blended layers)", "framebuffer", rows_p, threads_list,
                  args.llvmpipe)]
    out = "\n".join(text)
    print(out)
    Path(args.out).write_text(out)


if __name__ == "__main__":
    main()
