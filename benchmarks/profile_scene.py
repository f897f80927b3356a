"""Run one scene of ordinary.py on softgl for profiling (issue 18): setup, one warm-up frame, then
N frames, at one thread by default. Meant to be run under callgrind on an unstripped build, e.g.

    valgrind --tool=callgrind --toggle-collect='softgl::*draw*' \\
        python benchmarks/profile_scene.py cubemap_env 1

(instruction counts are deterministic, wall-clock under load is not). --save PATH writes the
canvas as a .npy file, to compare two builds byte for byte."""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ordinary  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", choices=sorted(ordinary.ALL))
    ap.add_argument("frames", type=int, nargs="?", default=1)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--save", help="write the canvas after the last frame to this .npy file")
    args = ap.parse_args()
    spec = ordinary.ALL[args.scene]
    gl = ordinary.softgl_context(spec, spec.width, spec.height, args.threads)
    frame = spec.setup(gl, spec.width, spec.height)
    for _ in range(1 + args.frames):
        frame()
        gl.finish()
    if args.save:
        np.save(args.save, ordinary.canvas_pixels(gl))


if __name__ == "__main__":
    main()
