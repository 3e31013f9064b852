#!/usr/bin/env python3
"""Predicted wall time per generation of a round-robin run on R ranks (docs/scaling.md).

    scripts/scaling-model.py RUN_DIR [--popsize 16] [--n 4] [--threads 1]

Reads RUN_DIR/summary.json of a run made with `mpirun -n R diverse run` (its
timing.messages: the remote rollouts' time quantiles and the message overhead per
rollout, both measured) and models a generation: N batches of lambda rollouts, each batch
handed out dynamically to R x threads slots (the next free slot takes the next sample),
every rollout that rank 0 does not compute itself costing the measured overhead on top.
Rollout times are drawn from the measured quantiles (piecewise linear between p10, p50,
p90 and max, flat below p10). Prints ranks, predicted seconds per generation, and the
speed-up over one slot. Everything printed is derived; only the inputs are measured.
"""
import argparse
import json
import random
import sys


def sampler(q):
    points = [(0.0, q["p10"]), (0.1, q["p10"]), (0.5, q["p50"]), (0.9, q["p90"]), (1.0, q["max"])]

    def draw(rng):
        u = rng.random()
        for (u0, t0), (u1, t1) in zip(points, points[1:]):
            if u <= u1:
                return t0 + (t1 - t0) * (u - u0) / (u1 - u0) if u1 > u0 else t1
        return points[-1][1]

    return draw


def batch_time(times, slots, local_slots, overhead):
    free = [0.0] * slots  # slot s < local_slots is rank 0's own thread (no messages)
    for t in times:
        s = min(range(slots), key=lambda i: free[i])
        free[s] += t + (0.0 if s < local_slots else overhead)
    return max(free)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run")
    ap.add_argument("--popsize", type=int, default=16)
    ap.add_argument("--n", type=int, default=4)
    ap.add_argument("--threads", type=int, default=1, help="threads per rank")
    ap.add_argument("--trials", type=int, default=400)
    a = ap.parse_args()
    timing = json.load(open(f"{a.run}/summary.json"))["timing"]
    if "messages" not in timing:
        sys.exit(f"{a.run}: summary.json has no timing.messages (run it with mpirun -n 2 or more)")
    m = timing["messages"]
    draw = sampler(m["remote_rollout_ms"])
    overhead = m["overhead_us_per_evaluation"] / 1000.0
    rng = random.Random(1)
    print(f"# lambda {a.popsize}, N {a.n}, {a.threads} thread(s) per rank; rollout p50 "
          f"{m['remote_rollout_ms']['p50']:.2f} ms, overhead {overhead * 1000:.0f} us per remote rollout")
    print("ranks  ms/generation  speed-up")
    base = None
    for ranks in (1, 2, 4, 8, 16, 32, 64):
        slots = ranks * a.threads
        total = 0.0
        for _ in range(a.trials):
            for _ in range(a.n):
                total += batch_time([draw(rng) for _ in range(a.popsize)], slots, a.threads, overhead)
        per_gen = total / a.trials
        base = base or per_gen
        print(f"{ranks:5d}  {per_gen:13.1f}  {base / per_gen:8.2f}")


if __name__ == "__main__":
    main()
