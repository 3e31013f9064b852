#!/usr/bin/env python3
"""How many distinct variations finished runs hold (paper section 9: N = 10 against N = 4).

    scripts/distinct-variations.py [--times F ...] RUN...

For each run directory, from its summary.json (the run's own metric, M0 included as
index 0): the scale of "the same", d0 = d(M0, M0 nudged by 0.01 per normalized parameter)
(nudged_m0_distance); for each threshold T = F x d0 (F = 10, 20, 50 by default), the
pairs of M0..MN farther apart than T, and the largest set of motions that are all
pairwise farther apart than T (the number of distinct motions; exhaustive search, fine for
N up to about 20); the smallest and mean distance among M1..MN and among M0..MN. Prints
a Markdown table.

For runs with blends (RUN/blend/summary.json, `diverse blend RUN`), a second table: how
many blends meet the task, against the path points simulated the same way; which of the
run's motions the feasible blends are nearest to, and how far (mean and largest); and how
many feasible blends are farther than F x d0 from every motion of the run (new distinct
motions).
"""
import argparse
import itertools
import json
import os
import sys


def largest_distinct_set(d, threshold):
    n = len(d)
    best = [0] if n else []
    # Grow cliques depth first, candidates in index order (n <= ~20).
    def grow(current, candidates):
        nonlocal best
        if len(current) + len(candidates) <= len(best):
            return
        if not candidates:
            best = list(current)
            return
        for k, c in enumerate(candidates):
            rest = [x for x in candidates[k + 1:] if d[c][x] > threshold]
            grow(current + [c], rest)
    grow([], list(range(n)))
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--times", type=float, nargs="+", default=[10.0, 20.0, 50.0])
    parser.add_argument("runs", nargs="+")
    args = parser.parse_args()
    factors = args.times
    head = ["run", "task", "metric", "N", "generations", "D", "d0 = d(M0, nudged M0)"]
    for f in factors:
        head.append(f"pairs > {f:g} d0")
        head.append(f"distinct at {f:g} d0")
    head += ["min d among M1..MN", "mean d among M1..MN", "mean d among M0..MN"]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for run in args.runs:
        path = os.path.join(run, "summary.json")
        try:
            with open(path) as f:
                s = json.load(f)
        except (OSError, ValueError) as e:
            sys.exit(f"distinct-variations.py: {path}: {e}")
        metric = s["metric"]
        d = s["distances"][metric]
        n = len(d)
        d0 = s.get("nudged_m0_distance", 0.0)
        row = [os.path.basename(os.path.normpath(run)), s["task"], metric, str(n - 1), str(s["generations"]),
               f"{s['D']:.4g}", f"{d0:.3g}"]
        all_pairs = list(itertools.combinations(range(n), 2))
        var_pairs = list(itertools.combinations(range(1, n), 2))
        for f in factors:
            t = f * d0
            row.append(f"{sum(1 for i, j in all_pairs if d[i][j] > t)} of {len(all_pairs)}")
            row.append(str(len(largest_distinct_set(d, t))))
        var = [d[i][j] for i, j in var_pairs]
        every = [d[i][j] for i, j in all_pairs]
        row.append(f"{min(var):.4g}" if var else "-")
        row.append(f"{sum(var) / len(var):.4g}" if var else "-")
        row.append(f"{sum(every) / len(every):.4g}" if every else "-")
        print("| " + " | ".join(row) + " |")

    blended = [run for run in args.runs if os.path.exists(os.path.join(run, "blend", "summary.json"))]
    if not blended:
        return
    print()
    head = ["run", "task", "N", "blends", "meet the task", "path points that meet it",
            "feasible blends nearest to", "their distance to it: mean, largest"]
    head += [f"feasible, > {f:g} d0 from every motion" for f in factors]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for run in blended:
        with open(os.path.join(run, "summary.json")) as f:
            s = json.load(f)
        with open(os.path.join(run, "blend", "summary.json")) as f:
            b = json.load(f)
        d0 = s.get("nudged_m0_distance", 0.0)
        labels = b["labels"]
        feasible = [x for x in b["blends"] if x["feasible"]]
        k = len(b["blends"])
        paths = b["paths"]
        near = {}
        for x in feasible:
            if x["nearest"] is not None:
                near[labels[x["nearest"]]] = near.get(labels[x["nearest"]], 0) + 1
        dist = [x["distances"][x["nearest"]] for x in feasible if x["nearest"] is not None]
        row = [os.path.basename(os.path.normpath(run)), b["task"], str(len(labels) - 1), str(k),
               f"{len(feasible)} ({100.0 * len(feasible) / k:.0f} %)",
               f"{paths['feasible']} of {paths['points']}" +
               (f" ({100.0 * paths['feasible'] / paths['points']:.0f} %)" if paths["points"] else ""),
               ", ".join(f"{l} {c}" for l, c in sorted(near.items(), key=lambda kv: -kv[1])) or "-",
               f"{sum(dist) / len(dist):.3g}, {max(dist):.3g}" if dist else "-"]
        for f in factors:
            row.append(str(sum(1 for x in feasible
                               if all(v is not None and v > f * d0 for v in x["distances"]))))
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
