"""Throughput of the geometric core (setup + bin + raster, with the coverage probe's per-sample
count/depth writes as the stand-in fragment stage).

    python tests/pipeline/bench_raster.py

Prints triangles/s for 100,000 tiny triangles and Mpixels/s for large ones, threads 1 and 2.
Times are the best of several runs, measured inside C++ (softgl._core.raster_coverage 'seconds').
"""
import os
import platform

import numpy as np

import softgl._core as core

W, H = 1024, 768


def clip_from_window(xy):
    xy = np.asarray(xy, np.float64).reshape(-1, 2)
    return np.stack([2 * xy[:, 0] / W - 1, 2 * xy[:, 1] / H - 1, np.zeros(len(xy)),
                     np.ones(len(xy))], 1).astype(np.float32)


def tiny(n=100_000, seed=0):
    rng = np.random.default_rng(seed)
    c = rng.uniform(0, [W, H], (n, 2))
    return clip_from_window(c[:, None, :] + rng.uniform(-1.5, 1.5, (n, 3, 2)))


def large(n=200, seed=1):
    # Screen-sized triangles: each covers about half the target.
    rng = np.random.default_rng(seed)
    xy = []
    for _ in range(n):
        if rng.random() < 0.5:
            xy += [(-50, -50), (W + 50, -50), (rng.uniform(0, W), H + 300)]
        else:
            xy += [(-50, H + 50), (rng.uniform(0, W), -300), (W + 50, H + 50)]
    return clip_from_window(xy)


def run(clip, threads, record, repeat=5):
    best = None
    for _ in range(repeat):
        r = core.raster_coverage(W, H, clip, threads=threads, record=record)
        t = r["seconds"]
        if best is None or sum(t) < sum(best[0]):
            best = (t, r)
    return best


def main():
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, target {W}x{H}")
    for name, clip in (("100k tiny triangles", tiny()), ("200 large triangles", large())):
        for record in (False, True):
            for threads in (1, 2):
                (ts, tb, tr), r = run(clip, threads, record)
                n = len(clip) // 3
                px = r["samples_covered"]
                total = ts + tb + tr
                what = "+count/depth/weights writes" if record else "coverage only"
                print(f"{name} threads={threads} {what}: setup {ts*1e3:.2f} ms, bin {tb*1e3:.2f} ms,"
                      f" raster {tr*1e3:.2f} ms | {n/total/1e6:.2f} Mtri/s, {px/total/1e6:.1f} Mpix/s"
                      f" ({px} pixels covered)")


if __name__ == "__main__":
    main()
