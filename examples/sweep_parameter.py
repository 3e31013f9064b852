#!/usr/bin/env python3
"""Sweeps one parameter of a task's input motion and plots what it does to the motion.

    PYTHONPATH=build/python /usr/bin/python3 examples/sweep_parameter.py [TASK] [--parameter NAME]
        [--steps K] [--out PNG]

Simulates the input motion M0 with one controller parameter set to K values across its
range (the others as in M0), all at once on every core (Task.simulate_batch), and plots
the peak height of the centre of mass, where the feet come to rest and the constraint
value C (0 = the motion meets the task) against the parameter. By default the parameter
is the one whose sweep moves the peak the most among the first few, so the plot shows
something; docs/guide/python.md explains the module.
"""
import argparse
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import diverse


def sweep(task, index, steps):
    """The motions of M0 with parameter `index` at `steps` values across its range."""
    values = np.linspace(task.lower[index], task.upper[index], steps)
    rows = np.tile(task.m0, (steps, 1))
    rows[:, index] = values
    return values, task.simulate_batch(rows)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("task", nargs="?", default="jump_high", help="task name or file (default jump_high)")
    parser.add_argument("--parameter", default=None, help="the parameter to sweep (Task.parameter_names)")
    parser.add_argument("--steps", type=int, default=21, help="values across the range (default 21)")
    parser.add_argument("--out", default=None, help="PNG to write (default sweep-<parameter>.png)")
    args = parser.parse_args(argv)
    try:
        task = diverse.load_task(args.task)
        if task.m0 is None:
            raise diverse.UserError(f"{task.file}: m0: the input motion's file does not exist yet")
        names = task.parameter_names
        if args.parameter is None:
            # The first few parameters, coarsely: the one that moves the peak the most.
            spans = [np.ptp([m.peak_com_z for m in sweep(task, i, 5)[1]]) for i in range(min(8, len(names)))]
            index = int(np.argmax(spans))
        elif args.parameter in names:
            index = names.index(args.parameter)
        else:
            raise diverse.UserError(f"--parameter: expected a parameter of {task.name} "
                                    f"({', '.join(names[:6])}, ...), got {args.parameter}")
        if args.steps < 2:
            raise diverse.UserError(f"--steps: expected an integer >= 2, got {args.steps}")
    except diverse.UserError as e:
        print(f"sweep_parameter.py: {e}", file=sys.stderr)
        return 2

    values, motions = sweep(task, index, args.steps)
    peak = np.array([m.peak_com_z for m in motions])
    rest = np.array([m.landing_x for m in motions])
    c = np.array([m.constraint for m in motions])
    met = c == 0
    name = names[index]
    print(f"{task.name}: {name} from {values[0]:.4g} to {values[-1]:.4g} (M0 {task.m0[index]:.4g}), "
          f"{met.sum()} of {len(values)} motions meet the task")
    for v, p, r, cc in zip(values, peak, rest, c):
        print(f"{v:>10.4g} peak {p:6.3f} m  rest x {r:7.3f} m  C {cc:.4g}")

    fig, axes = plt.subplots(2, 1, figsize=(7, 5.5), dpi=110, sharex=True)
    for ax, y, label in [(axes[0], peak, "peak COM height (m)"), (axes[1], rest, "feet at rest, x (m)")]:
        ax.plot(values, y, color="#555555", linewidth=1)
        ax.scatter(values[met], y[met], color="#2a7", label="meets the task", zorder=3)
        ax.scatter(values[~met], y[~met], color="#c33", marker="x", label="misses it (C > 0)", zorder=3)
        ax.axvline(task.m0[index], color="#999999", linestyle=":", linewidth=1)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[0].set_title(f"{task.name}: the input motion with {name} swept (dotted: M0's value)")
    axes[1].set_xlabel(name)
    fig.tight_layout()
    out = args.out or f"sweep-{name}.png"
    fig.savefig(out)
    print(f"{out}  ({len(values)} motions)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
