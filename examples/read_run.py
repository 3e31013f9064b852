#!/usr/bin/env python3
"""Reads a diverse run directory into numpy with the module diverse, and plots a motion.

    PYTHONPATH=build/python /usr/bin/python3 examples/read_run.py RUN [--variation I] [--joints NAME ...] [--out PNG]

Prints the run's summary (every motion's constraint value C and dmin, the distances under
the run's metric), takes one motion (default M1, or M0 if the run has no variation), names
the columns of its recorded states from the model it ran on (model/m<I>.xml), and plots
the chosen hinge joints' angles over time into a PNG (default RUN/m<I>-joints.png).
Without --joints it plots the joints of the character's left leg (names ending in _l that
contain hip, knee or ankle), or the first four hinges.

docs/guide/python.md is the module's guide; the file formats are those of src/run/run.h
(summary.json) and src/io/motion_record.h (the motion files).
"""
import argparse
import sys
from pathlib import Path

import numpy as np
import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt

import diverse


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a run directory written by `diverse run`")
    parser.add_argument("--variation", type=int, default=None, help="motion index (default 1, or 0)")
    parser.add_argument("--joints", nargs="*", default=None, help="hinge joint names to plot")
    parser.add_argument("--out", type=Path, default=None, help="PNG to write")
    parser.add_argument("--columns", action="store_true", help="print the model's joints and their qpos columns")
    args = parser.parse_args(argv)

    try:
        run = diverse.load_run(args.run)
    except diverse.UserError as e:
        print(f"read_run.py: {e}", file=sys.stderr)
        return 2
    summary = run.summary
    motions = run.motions
    metric = summary.get("metric", "")
    print(f"{summary.get('task', '?')}: {len(motions)} motions, metric {metric}, D = {run.D:.4g}")
    print(f"{'motion':>6} {'C':>10} {'dmin':>10}")
    for m in motions:
        print(f"{m.label:>6} {m.constraint:>10.4g} {m.dmin:>10.4g}")
    if metric in summary.get("distances", {}):
        d = run.distances(metric)
        print(f"distances under {metric}: closest pair {d[np.triu_indices(len(d), 1)].min():.4g}, "
              f"farthest {d.max():.4g}")

    index = args.variation if args.variation is not None else (1 if len(motions) > 1 else 0)
    if not 0 <= index < len(motions):
        print(f"read_run.py: --variation: expected 0 to {len(motions) - 1}, got {index}", file=sys.stderr)
        return 2
    motion = motions[index]
    times, qpos, model = motion.times, motion.qpos, Path(motion.model)
    columns = diverse.joints(motion.model)  # (name, type, first qpos column), as MuJoCo lays them out
    if args.columns:
        for name, kind, column in columns:
            print(f"column {column:>3} {kind:<6} {name}")
    hinges = {name: column for name, kind, column in columns if kind == "hinge" and name}
    names = args.joints
    if not names:
        names = [n for n in hinges if n.endswith("_l") and any(k in n for k in ("hip", "knee", "ankle"))]
        names = names or list(hinges)[:4]
    unknown = [n for n in names if n not in hinges]
    if unknown:
        print(f"read_run.py: --joints: {', '.join(unknown)}: not hinge joints of {model.name} "
              f"(it has {', '.join(hinges)})", file=sys.stderr)
        return 2

    fig, ax = plt.subplots(figsize=(8, 4.2), dpi=110)
    for name in names:
        ax.plot(times, np.degrees(qpos[:, hinges[name]]), label=name, linewidth=1.6)
    # The phases the controller reported, as vertical lines.
    for name, begin in motion.phases.items():
        if begin > 0:
            ax.axvline(begin, color="#999999", linewidth=0.8, linestyle=":")
            ax.text(begin, ax.get_ylim()[1], " " + name, fontsize=7, va="top", color="#666666")
    ax.set_title(f"{summary.get('task', '')} {motion.label}: joint angles (C = {motion.constraint:.3g})")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("angle (degrees)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    out = args.out or args.run / f"m{index}-joints.png"
    fig.savefig(out)
    print(f"{out}  ({len(names)} joints, {len(times)} states, {times[-1]:.2f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
