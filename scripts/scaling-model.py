#!/usr/bin/env python3
"""Predicted wall time per generation and utilization of R ranks (docs/guide/running-at-scale.md).

    scripts/scaling-model.py RUN_DIR... [--batches per-variation|per-generation|both]
                             [--popsize 16] [--n 4] [--threads 1] [--overhead-us US]

Reads the rollout times a run measured (RUN_DIR/summary.json, "timing"):
  timing.rollouts.cpu_ms.deciles  a single-process run: every rollout's CPU time,
                                  p0, p10, ..., p100 (load-independent);
  timing.messages                 a run made with `mpirun -n R`: the remote rollouts'
                                  time quantiles and the message overhead per rollout.
Several RUN_DIRs: their deciles are averaged point by point.

Models a generation as N batches of lambda rollouts (per-variation: round-robin standing
at means, the progressive strategy) or one batch of N x lambda (per-generation: the
default round-robin at best samples, the simultaneous strategy; src/optimize/diversity.h,
"Batches"). Each batch is handed out dynamically to
R x threads slots (the next free slot takes the next sample, as src/distribute does) and
lasts until its last rollout ends; every rollout that rank 0 does not compute itself
costs the overhead on top (measured under mpirun, or --overhead-us). Rollout times are
drawn from the measured quantiles (piecewise linear between them). Prints, per R, the
predicted ms per generation, the speed-up over one slot and the utilization: the
rollouts' own time over (slots x wall time), i.e. the share of the R workers' time spent
computing. Everything printed is derived; only the inputs are measured.
"""
import argparse
import json
import random
import sys


def sampler(points):
    """points: [(u, t)] increasing in u from 0 to 1."""

    def draw(rng):
        u = rng.random()
        for (u0, t0), (u1, t1) in zip(points, points[1:]):
            if u <= u1:
                return t0 + (t1 - t0) * (u - u0) / (u1 - u0) if u1 > u0 else t1
        return points[-1][1]

    return draw


def read_times(runs):
    """Quantile points and the overhead per remote rollout (ms) from the runs."""
    deciles, overheads, quantiles = [], [], None
    for run in runs:
        timing = json.load(open(f"{run}/summary.json"))["timing"]
        if "rollouts" in timing:
            deciles.append(timing["rollouts"]["cpu_ms"]["deciles"])
        elif "messages" in timing:
            m = timing["messages"]
            q = m["remote_rollout_ms"]
            quantiles = [(0.0, q["p10"]), (0.1, q["p10"]), (0.5, q["p50"]), (0.9, q["p90"]), (1.0, q["max"])]
            overheads.append(m["overhead_us_per_evaluation"] / 1000.0)
        else:
            sys.exit(f"{run}: summary.json has no timing.rollouts or timing.messages")
    if deciles:
        mean = [sum(d[k] for d in deciles) / len(deciles) for k in range(11)]
        quantiles = [(k / 10.0, mean[k]) for k in range(11)]
    overhead = sum(overheads) / len(overheads) if overheads else None
    return quantiles, overhead


def batch_time(times, slots, local_slots, overhead):
    free = [0.0] * slots  # slot s < local_slots is rank 0's own thread (no messages)
    for t in times:
        s = min(range(slots), key=lambda i: free[i])
        free[s] += t + (0.0 if s < local_slots else overhead)
    return max(free)


def model(draw, batching, n, popsize, threads, overhead, trials, ranks_list, rng):
    rows = []
    base = None
    for ranks in ranks_list:
        slots = ranks * threads
        wall = work = 0.0
        for _ in range(trials):
            batches = [popsize] * n if batching == "per-variation" else [n * popsize]
            for size in batches:
                times = [draw(rng) for _ in range(size)]
                work += sum(times)
                wall += batch_time(times, slots, threads, overhead)
        per_gen = wall / trials
        base = base or per_gen
        rows.append((ranks, per_gen, base / per_gen, work / (slots * wall)))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--batches", default="both", choices=["per-variation", "per-generation", "both"])
    ap.add_argument("--popsize", type=int, default=16)
    ap.add_argument("--n", type=int, default=4)
    ap.add_argument("--threads", type=int, default=1, help="threads per rank")
    ap.add_argument("--overhead-us", type=float, default=None,
                    help="message cost per remote rollout (default: the runs' measured one, else 0)")
    ap.add_argument("--ranks", default="1,2,4,8,16,32,64")
    ap.add_argument("--trials", type=int, default=400)
    a = ap.parse_args()
    quantiles, measured_overhead = read_times(a.runs)
    overhead = a.overhead_us / 1000.0 if a.overhead_us is not None else (measured_overhead or 0.0)
    draw = sampler(quantiles)
    ranks_list = [int(r) for r in a.ranks.split(",")]
    median = next(t for u, t in quantiles if u >= 0.5)
    print(f"# lambda {a.popsize}, N {a.n}, {a.threads} thread(s) per rank; rollout p50 {median:.2f} ms, "
          f"p90 {next(t for u, t in quantiles if u >= 0.9):.2f} ms, max {quantiles[-1][1]:.2f} ms; "
          f"overhead {overhead * 1000:.0f} us per remote rollout")
    batchings = ["per-variation", "per-generation"] if a.batches == "both" else [a.batches]
    for batching in batchings:
        rng = random.Random(1)
        print(f"{batching}: ranks  ms/generation  speed-up  utilization")
        for ranks, per_gen, speedup, util in model(draw, batching, a.n, a.popsize, a.threads, overhead,
                                                   a.trials, ranks_list, rng):
            print(f"{'':{len(batching)}}  {ranks:5d}  {per_gen:13.1f}  {speedup:8.2f}  {100 * util:10.1f} %")


if __name__ == "__main__":
    main()
