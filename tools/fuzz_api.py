#!/usr/bin/env python3
"""Long runs of softgl's WebGL command-stream fuzzer (tests/fuzz_api/command_stream.py).

Each seed runs in its own subprocess, so a crash (segfault, abort, sanitizer report) or a hang is
caught and reported with the seed that reproduces it; a contract violation is reported with the
last calls. Prints the figures quoted in docs/reliability.md.

    python tools/fuzz_api.py --minutes 10 [--steps 2000] [--jobs 2] [--first-seed 0]
    python tools/fuzz_api.py --seed 1234 --steps 2000        # replay one seed in this process
    eval "$(tools/build_asan_module.sh)"; $ASAN_PY tools/fuzz_api.py --minutes 10   # sanitized
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "fuzz_api"))


def run_seed(seed: int, steps: int) -> dict:
    import numpy as np
    from command_stream import CommandFuzzer, Violation
    warnings.simplefilter("ignore", RuntimeWarning)
    f = CommandFuzzer(seed)
    result = {"seed": seed, "version": f.version, "violation": None}
    with np.errstate(all="ignore"):
        try:
            for _ in range(steps):
                f.step()
        except Violation as e:
            result["violation"] = str(e)
    result.update(calls=f.calls, errors=f.errors)
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--minutes", type=float, default=5.0)
    ap.add_argument("--steps", type=int, default=2000, help="fuzzer steps per seed")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds before a seed counts as hung")
    ap.add_argument("--seed", type=int, help="run this one seed here and print its result")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()

    if args.seed is not None:
        r = run_seed(args.seed, args.steps)
        print(json.dumps(r) if args.child else r.get("violation") or f"seed {args.seed}: ok, {r['calls']} calls")
        return 0

    deadline = time.time() + args.minutes * 60
    seed = args.first_seed
    running: list[tuple[int, subprocess.Popen, float]] = []
    totals = dict(seeds=0, calls=0, errors=0)
    problems = []
    start = time.time()
    while running or time.time() < deadline:
        while time.time() < deadline and len(running) < args.jobs:
            p = subprocess.Popen([sys.executable, __file__, "--child", "--seed", str(seed), "--steps", str(args.steps)],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            running.append((seed, p, time.time()))
            seed += 1
        time.sleep(0.05)
        for item in list(running):
            s, p, t0 = item
            if p.poll() is None:
                if time.time() - t0 > args.timeout:
                    p.kill()
                    p.wait()
                    problems.append({"seed": s, "kind": "hang", "detail": f"> {args.timeout:.0f}s"})
                    running.remove(item)
                continue
            running.remove(item)
            out, err = p.communicate()
            totals["seeds"] += 1
            if p.returncode != 0:
                problems.append({"seed": s, "kind": f"crash (exit {p.returncode})", "detail": err[-3000:]})
                continue
            r = json.loads(out.strip().splitlines()[-1])
            totals["calls"] += r["calls"]
            totals["errors"] += r["errors"]
            if r["violation"]:
                problems.append({"seed": s, "kind": "violation", "detail": r["violation"]})
    elapsed = time.time() - start
    print(f"seeds {totals['seeds']} (from {args.first_seed}), {args.steps} steps each; "
          f"{totals['calls']} calls ({totals['errors']} reported an error) in {elapsed:.0f}s "
          f"= {totals['calls'] / max(elapsed, 1e-9):.0f} calls/s; problems: {len(problems)}")
    for pr in problems:
        print(f"--- seed {pr['seed']}: {pr['kind']}\n{pr['detail']}\n")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
