#!/usr/bin/env python3
"""Reads a diverse run directory with the standard library, numpy and matplotlib.

    python3 examples/read_run.py RUN [--variation I] [--joints NAME ...] [--out PNG]

Prints the run's summary (every motion's constraint value C and dmin, the distances under
the run's metric), loads a motion file (motions/m<I>.json, default M1, or M0 if the run has
no variation), names the columns of its recorded states from the model it ran on
(model/m<I>.xml), and plots the chosen hinge joints' angles over time into a PNG (default
RUN/m<I>-joints.png). Without --joints it plots the joints of the character's left leg
(names ending in _l that contain hip, knee or ankle), or the first four hinges.

The formats are those of src/run/run.h (summary.json) and src/io/motion_record.h (the
motion file); docs/python.md explains them for Python users.
"""
import argparse
import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt

# Entries of qpos each joint type takes, in MuJoCo's order of joints in the model.
QPOS_SIZE = {"free": 7, "ball": 4, "slide": 1, "hinge": 1}


def joint_columns(model_xml):
    """(name, type, first qpos column) of every joint, in the order MuJoCo lays out qpos:
    the bodies' joints in document order. Joint types come from the element, else its
    default class (childclass of the bodies above it, or `class`), else "hinge"."""
    root = ET.parse(model_xml).getroot()
    defaults = {}  # class name -> joint type

    def read_defaults(node, inherited, name):
        joint = node.find("joint")
        kind = joint.get("type", inherited) if joint is not None else inherited
        defaults[name] = kind
        for child in node.findall("default"):
            read_defaults(child, kind, child.get("class", name))

    for top in root.findall("default"):
        read_defaults(top, "hinge", top.get("class", "main"))

    columns = []
    qpos = 0

    def walk(body, childclass):
        nonlocal qpos
        childclass = body.get("childclass", childclass)
        for element in body:
            if element.tag == "freejoint":
                kind, name = "free", element.get("name", "")
            elif element.tag == "joint":
                cls = element.get("class", childclass)
                kind = element.get("type", defaults.get(cls, defaults.get("main", "hinge")))
                name = element.get("name", "")
            else:
                continue
            columns.append((name, kind, qpos))
            qpos += QPOS_SIZE[kind]
        for child in body.findall("body"):
            walk(child, childclass)

    for world in root.findall("worldbody"):
        for body in world.findall("body"):
            walk(body, "main")
    return columns, qpos


def load_motion(run, index):
    """The motion file as a dict, its times (s) and states (steps x nq) as numpy arrays."""
    path = run / "motions" / f"m{index}.json"
    motion = json.loads(path.read_text())
    replay = motion["replay"]
    qpos = np.array([replay["qpos0"]] + replay["qpos"], dtype=float)
    times = np.arange(len(qpos)) * replay["timestep"]
    model = (path.parent / replay["model"]).resolve()
    return motion, times, qpos, model


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a run directory written by `diverse run`")
    parser.add_argument("--variation", type=int, default=None, help="motion index (default 1, or 0)")
    parser.add_argument("--joints", nargs="*", default=None, help="hinge joint names to plot")
    parser.add_argument("--out", type=Path, default=None, help="PNG to write")
    parser.add_argument("--columns", action="store_true", help="print the model's joints and their qpos columns")
    args = parser.parse_args(argv)

    summary_path = args.run / "summary.json"
    if not summary_path.exists():
        print(f"read_run.py: {summary_path}: missing; not a finished run directory", file=sys.stderr)
        return 2
    summary = json.loads(summary_path.read_text())
    motions = summary["motions"]
    metric = summary.get("metric", "")
    print(f"{summary.get('task', '?')}: {len(motions)} motions, metric {metric}, D = {summary.get('D', float('nan')):.4g}")
    print(f"{'motion':>6} {'C':>10} {'dmin':>10}")
    for m in motions:
        print(f"{m['label']:>6} {m['constraint']:>10.4g} {m.get('dmin', 0.0):>10.4g}")
    distances = summary.get("distances", {}).get(metric)
    if distances:
        d = np.array(distances)
        print(f"distances under {metric}: closest pair {d[np.triu_indices(len(d), 1)].min():.4g}, "
              f"farthest {d.max():.4g}")

    index = args.variation if args.variation is not None else (1 if len(motions) > 1 else 0)
    if not 0 <= index < len(motions):
        print(f"read_run.py: --variation: expected 0 to {len(motions) - 1}, got {index}", file=sys.stderr)
        return 2
    motion, times, qpos, model = load_motion(args.run, index)
    columns, nq = joint_columns(model)
    if nq != qpos.shape[1]:
        print(f"read_run.py: {model}: {nq} qpos columns from the joints, the motion has {qpos.shape[1]}",
              file=sys.stderr)
        return 2
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
    for phase in motion.get("phases", []):
        if phase.get("begin", -1) > 0:
            ax.axvline(phase["begin"], color="#999999", linewidth=0.8, linestyle=":")
            ax.text(phase["begin"], ax.get_ylim()[1], " " + phase["name"], fontsize=7, va="top", color="#666666")
    label = motions[index]["label"]
    ax.set_title(f"{summary.get('task', '')} {label}: joint angles (C = {motions[index]['constraint']:.3g})")
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
