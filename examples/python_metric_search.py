#!/usr/bin/env python3
"""A small diversity search whose distance is written in Python.

    PYTHONPATH=build/python /usr/bin/python3 examples/python_metric_search.py [TASK] [--out DIR]
        [--variations N] [--generations G] [--seed S]

The distance compares where the hands and feet are, relative to the body's centre of mass,
at the pose samples of the two airborne phases (a Python variant of the paper's HF
metric that weighs height twice as much as the other directions, so the search favours
variations that tuck or stretch). diverse.run optimizes it as it would a built-in one,
writes the same run directory as `diverse run`, and reports every generation through
the callback; the summary's "custom" names the Python distance. Then it prints each
variation's C, dmin and how far its hands and feet are from M0's.
"""
import argparse
import sys

import numpy as np

import diverse


def limbs_apart(a, b):
    """Sum over the pose samples of the squared distances between the hands' and feet's
    centres of mass, height counted twice. Motions with different numbers of samples
    (one never took off) are 0 apart: their constraint value scores them."""
    if a.link_com.shape != b.link_com.shape or len(a.link_com) == 0:
        return 0.0
    ends = [i for i, name in enumerate(a.link_names) if any(k in name for k in ("hand", "foot"))]
    d = a.link_com[:, ends, :] - b.link_com[:, ends, :]
    return float(np.sum(d[..., 0] ** 2 + d[..., 1] ** 2 + 2.0 * d[..., 2] ** 2))


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("task", nargs="?", default="jump_high")
    parser.add_argument("--out", default="runs/python-metric")
    parser.add_argument("--variations", type=int, default=4)
    parser.add_argument("--generations", type=int, default=10)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)

    def progress(record):
        c = record["constraint"]
        print(f"generation {record['generation']:>3}: D = {record['D']:.4g}, "
              f"{int((c == 0).sum())} of {len(c)} motions meet the task")

    try:
        run = diverse.run(args.task, args.out, variations=args.variations, generations=args.generations,
                          seed=args.seed, popsize=8, sigma0=0.03, metric=limbs_apart, force=True,
                          on_generation=progress)
    except diverse.UserError as e:
        print(f"python_metric_search.py: {e}", file=sys.stderr)
        return 2
    print(f"{run.summary['task']}: D = {run.D:.4g} under {run.summary['custom']['metric']}, "
          f"all meet the task: {run.all_satisfied}")
    task = diverse.load_task(run.settings["task_file"])
    rows = np.array([[m.parameters[n] for n in task.parameter_names] for m in run.motions])
    outcomes = [m.outcome for m in task.simulate_batch(rows)]
    for m, o in zip(run.motions, outcomes):
        print(f"{m.label:>4}  C {m.constraint:<8.4g} dmin {m.dmin:<10.4g} "
              f"from M0 {limbs_apart(o, outcomes[0]):.4g}")
    print(f"{run.dir}  (summary.json, motions/)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
