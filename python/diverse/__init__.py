"""diverse from Python: many different physically simulated ways to perform a skill.

The C++ library (``_diverse``) does the work; this package gives it Python's shape.
``docs/guide/python.md`` is the guide and reference.

    import diverse
    task = diverse.load_task("jump_high")
    m0 = task.simulate()                       # the input motion: C, qpos, phases, ...
    run = diverse.run(task, "runs/py", generations=20, seed=1)
    run.D, run.motions[1].qpos                 # the same run directory as `diverse run`
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from ._diverse import (  # noqa: F401  (the module's public names)
    Motion,
    Outcome,
    Task,
    UserError,
    __version__,
    distance,
    distances,
    joints,
    load_task,
)
from . import _diverse

for _public in (Motion, Outcome, Task, UserError):
    _public.__module__ = "diverse"

__all__ = [
    "Motion", "Outcome", "Task", "UserError", "distance", "distances", "joints", "load_task",
    "run", "resume", "load_run", "Run", "RunMotion", "StoppedRun",
]


@dataclass
class RunMotion:
    """One motion of a finished run (motions/m<i>.json and its model)."""

    index: int
    label: str                 # "M0", "M1", ...
    constraint: float          # C (summary.json); 0 = meets the task
    dmin: float                # distance to the nearest other motion
    fell: bool
    failed: bool
    times: np.ndarray          # s, one per row of qpos
    qpos: np.ndarray           # (steps + 1, nq): the recorded states
    timestep: float            # s
    phases: dict               # phase name -> begin time (s), -1 if never reached
    parameters: dict           # the controller's named parameters
    terms: list                # constraint terms [{name, violation, penalty}]
    pose_samples: Any          # what the metrics compare (io/motion_record.h)
    file: str                  # motions/m<i>.json
    model: str                 # model/m<i>.xml, the MJCF it replays on


@dataclass
class Run:
    """A finished run directory, read with load_run()."""

    dir: str
    settings: dict             # run.json
    summary: dict              # summary.json
    motions: list = field(default_factory=list)

    @property
    def D(self) -> float:
        return self.summary["D"]

    @property
    def all_satisfied(self) -> bool:
        return self.summary["all_satisfied"]

    def distances(self, metric: str = "md") -> np.ndarray:
        """The (N+1) x (N+1) matrix of summary.json under hf, md, wja or shape."""
        table = self.summary["distances"]
        if metric not in table:
            raise UserError(f"metric: expected one of {', '.join(k for k in table if k != 'objective')}, got {metric}")
        return np.array(table[metric], dtype=float)


@dataclass
class StoppedRun:
    """A run its on_generation callback stopped: resume(dir) continues it."""

    dir: str
    generation: int
    stopped: bool = True


def load_run(dir: str | os.PathLike) -> Run:
    """Reads a finished run directory: summary, distances, every motion's states."""
    raw = _diverse._load_run(os.fspath(dir))
    return Run(dir=raw["dir"], settings=raw["run"], summary=raw["summary"],
               motions=[RunMotion(**m) for m in raw["motions"]])


def _generation(dir: str) -> int:
    import json
    with open(os.path.join(dir, "checkpoint.json")) as f:
        return int(json.load(f)["optimizer"]["generation"])


def _split_metric(metric):
    """A metric name for the library, or a Python distance function."""
    if metric is None:
        return "", None
    if callable(metric):
        return "", metric
    if isinstance(metric, str):
        return metric, None
    raise UserError("metric: expected a metric name (hf, md, wja, shape, md+shape) or a function(a, b)")


def run(task: Task | str, out: str | os.PathLike, *, generations: int = 0, seed: int = 1,
        strategy: str = "round-robin", variations: int = 0, popsize: int = 16, sigma0: float = 0.0,
        k: float = 10.0, metric: str | Callable[[Outcome, Outcome], float] | None = None,
        constraint: Optional[Callable[[Outcome], float]] = None, threads: int = 0,
        force: bool = False, render: bool = False, quiet: bool = True,
        checkpoint_seconds: float = 5.0, strength: float = 1.0,
        on_generation: Optional[Callable[[dict], Any]] = None) -> Run | StoppedRun:
    """A diversity run of `task`, written to `out` exactly as `diverse run TASK --out OUT`.

    generations, variations and sigma0 at 0 take the task's own values, as the CLI does;
    the same seed gives the same D as the CLI. `metric` is a name or a function
    f(a, b) -> float >= 0 of two Outcomes; `constraint` a function g(outcome) -> float >= 0
    added to every sample's C (0 where the motion is acceptable). on_generation(record) is
    called after every generation with {generation, D, best_D, constraint, dmin,
    evaluations, simulation_steps}; returning False stops the run (StoppedRun; resume()
    continues it). Returns the finished Run.
    """
    name, py_metric = _split_metric(metric)
    out = os.fspath(out)
    done = _diverse._run(task, out, generations, seed, strategy, variations, popsize, sigma0, k, name,
                         threads, force, render, quiet, checkpoint_seconds, strength,
                         on_generation, py_metric, constraint)
    return load_run(out) if done else StoppedRun(out, _generation(out))


def resume(dir: str | os.PathLike, *, metric: Callable | None = None,
           constraint: Optional[Callable] = None, threads: int = 0, render: bool = False,
           quiet: bool = True, checkpoint_seconds: float = 5.0,
           on_generation: Optional[Callable[[dict], Any]] = None) -> Run | StoppedRun:
    """Continues a run from its checkpoint, as `diverse resume DIR` (a run with a Python
    metric or constraint term needs the same functions again)."""
    if metric is not None and not callable(metric):
        raise UserError("metric: expected the run's Python distance function (a named metric is in run.json)")
    dir = os.fspath(dir)
    done = _diverse._resume(dir, threads, render, quiet, checkpoint_seconds, on_generation, metric,
                            constraint)
    return load_run(dir) if done else StoppedRun(dir, _generation(dir))
