#!/usr/bin/env python3
"""The Python module's batch simulate against the CLI's rollout rate, on every core.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_batch.py [--cli build/diverse] [--rounds 7]

Each round measures, one after the other so that the machine's changes of speed fall on
both: Task.simulate_batch of 64 copies of the input motion's parameters (jump_high, 567 steps
each) on 1 thread and on every core, without the half-timestep check (the optimizer's
rollouts have none either), and `diverse bench --json --rounds 1`, the CLI's own rate for
the same rollout on 1 thread and on every core (a batch of 64 over the library's thread
pool). The Python batch also records every state (Motion.qpos), as the CLI's does not. It prints the
medians and the ranges over the rounds of the ratios: the Python batch over the CLI's
rate (both on every core), and each one's speedup from 1 thread to every core.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

import diverse


def python_rate(task, rows, threads):
    start = time.perf_counter()
    task.simulate_batch(rows, threads=threads, half_timestep=False)
    return len(rows) / (time.perf_counter() - start)


def spread(values):
    return f"median {statistics.median(values):.3f} (range {min(values):.3f} to {max(values):.3f})"


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default=os.path.join(os.path.dirname(__file__), "../build/diverse"))
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--batch", type=int, default=64)
    args = parser.parse_args(argv)
    task = diverse.load_task("jump_high")
    rows = np.tile(task.m0, (args.batch, 1))
    cores = os.cpu_count()
    over_cli, py_speedup, cli_speedup, py_n, cli_n = [], [], [], [], []
    load_before = os.getloadavg()[0]
    for _ in range(args.rounds):
        p1 = python_rate(task, rows, 1)
        pn = python_rate(task, rows, 0)
        bench = json.loads(subprocess.run([args.cli, "bench", "jump_high", "--json", "--rounds", "1",
                                           "--seconds", "1", "--batch", str(args.batch)],
                                          check=True, capture_output=True, text=True).stdout)
        c1, cn = bench["rollouts_per_second_1_thread"], bench["rollouts_per_second_n_threads"]
        over_cli.append(pn / cn)
        py_speedup.append(pn / p1)
        cli_speedup.append(cn / c1)
        py_n.append(pn)
        cli_n.append(cn)
    print(f"jump_high, batches of {args.batch}, {cores} cores, {args.rounds} rounds, "
          f"load average {load_before:.2f} before, {os.getloadavg()[0]:.2f} after")
    print(f"Python batch, rollouts/s on {cores} threads: {spread(py_n)}")
    print(f"CLI (diverse bench), rollouts/s on {cores} threads: {spread(cli_n)}")
    print(f"Python batch / CLI: {spread(over_cli)}")
    print(f"speedup 1 -> {cores} threads, Python batch: {spread(py_speedup)}")
    print(f"speedup 1 -> {cores} threads, CLI: {spread(cli_speedup)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
