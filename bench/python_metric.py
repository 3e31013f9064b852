#!/usr/bin/env python3
"""What a distance or a constraint term written in Python costs a run.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_metric.py [--rounds 3]

Per call: the built-in hf distance (called from Python) against the distance of
examples/python_metric_search.py, on two outcomes of the input motion, 2000 calls each.
Per run: jump_high, N = 4, 10 generations of 8 samples, 2 threads, with the task's md, with
that Python distance, and with a Python constraint term (land within 10 cm of M0), in
interleaved rounds; the runs' optimization wall times (summary.json timing.wall_seconds)
as ratios to the built-in run's, and how many distances the Python one was asked for.
"""
import argparse
import os
import statistics
import sys
import tempfile
import time

import numpy as np

import diverse

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "../examples"))
from python_metric_search import limbs_apart  # noqa: E402


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    task = diverse.load_task("jump_high")
    a, b = task.simulate_batch(np.tile(task.m0, (2, 1)))
    n = 2000
    start = time.perf_counter()
    for _ in range(n):
        diverse.distance(a, b, "hf")
    builtin = (time.perf_counter() - start) / n
    oa, ob = a.outcome, b.outcome
    start = time.perf_counter()
    for _ in range(n):
        limbs_apart(oa, ob)
    python = (time.perf_counter() - start) / n
    print(f"per call: built-in hf {builtin * 1e6:.1f} us, limbs_apart {python * 1e6:.1f} us "
          f"({python / builtin:.0f}x)")

    calls = [0]

    def counted(x, y):
        calls[0] += 1
        return limbs_apart(x, y)

    def near_m0(o):
        return 1e3 * max(0.0, abs(o.landing_x - a.landing_x) - 0.1)

    settings = dict(variations=4, generations=10, popsize=8, sigma0=0.03, seed=1, force=True, threads=2)
    over_metric, over_term = [], []
    with tempfile.TemporaryDirectory() as work:
        for _ in range(args.rounds):
            wall = {}
            for label, extra in [("builtin", {}), ("metric", dict(metric=counted)), ("term", dict(constraint=near_m0))]:
                calls[0] = 0
                run = diverse.run(task, os.path.join(work, label), **settings, **extra)
                wall[label] = run.summary["timing"]["wall_seconds"]
                if label == "metric":
                    asked = calls[0]
            over_metric.append(wall["metric"] / wall["builtin"])
            over_term.append(wall["term"] / wall["builtin"])
            print(f"round: built-in {wall['builtin']:.2f} s, Python distance {wall['metric']:.2f} s "
                  f"({asked} calls, {asked * python:.2f} s of Python), Python term {wall['term']:.2f} s")
    print(f"load average {os.getloadavg()[0]:.2f}")
    for label, ratios in [("Python distance / built-in", over_metric), ("Python term / built-in", over_term)]:
        print(f"{label}: median {statistics.median(ratios):.2f} (range {min(ratios):.2f} to {max(ratios):.2f})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
