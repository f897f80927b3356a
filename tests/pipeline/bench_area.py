"""Throughput of area coverage (pipeline/coverage, SOFTGL_smooth) on one core: exact (NICEST) vs the
sampled estimate (FASTEST, grid x grid), next to the sample raster (aliased) for scale.

    python tests/pipeline/bench_area.py

Setup + bin + rasterize_area with a fragment stage that only sums fractions (raster_area,
record=False). Pixels/s counts emitted fragments (fraction > 0) per second of the whole path, best
of several runs, timed inside C++.
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


def large(n=100, seed=1):
    rng = np.random.default_rng(seed)
    xy = []
    for _ in range(n):    # about half the target each, edges crossing the screen
        xy += [(rng.uniform(-50, 100), rng.uniform(-50, 100)), (W + rng.uniform(-100, 50), rng.uniform(0, H)),
               (rng.uniform(0, W), H + rng.uniform(-100, 50))]
    return clip_from_window(xy)


def medium(n=20000, seed=2):
    rng = np.random.default_rng(seed)
    c = rng.uniform(0, [W, H], (n, 2))
    return clip_from_window(c[:, None, :] + rng.uniform(-12, 12, (n, 3, 2)))


def best(fn, repeat=5):
    out = None
    for _ in range(repeat):
        r = fn()
        if out is None or sum(r["seconds"]) < sum(out["seconds"]):
            out = r
    return out


def main():
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, "
          f"target {W}x{H}, threads=1")
    for name, clip in (("100 large triangles", large()), ("20k triangles of ~150 px", medium())):
        r = best(lambda: core.raster_coverage(W, H, clip, threads=1, record=False))
        t = sum(r["seconds"])
        print(f"{name}: sample raster (aliased): {r['samples_covered'] / t / 1e6:.1f} Mpix/s")
        for label, kw in (("exact", {}), ("sampled 4x4", dict(sampled=True, grid=4)),
                          ("sampled 8x8", dict(sampled=True, grid=8)),
                          ("sampled 16x16", dict(sampled=True, grid=16))):
            r = best(lambda: core.raster_area(W, H, clip, threads=1, record=False, **kw))
            t = sum(r["seconds"])
            st = r["raster"]
            print(f"  {label:14s}: {r['fragment_count'] / t / 1e6:7.1f} Mpix/s "
                  f"({r['fragment_count']} fragments, {t * 1e3:.1f} ms; blocks accepted/partial "
                  f"{st['blocks_accepted']}/{st['blocks_partial']})")


if __name__ == "__main__":
    main()
