"""Runs from Python: the CLI's run directory and D, the callback, Python metrics and terms."""
import json
import os

import numpy as np
import pytest

import diverse
from conftest import TINY, TINY_CLI, run_cli


def summary(path):
    s = json.load(open(os.path.join(path, "summary.json")))
    s.pop("timing")
    s.pop("task_file")
    return s


def test_a_python_run_is_the_cli_run(tiny_run, cli, tmp_path):
    code, err = run_cli(cli, "run", "jump_high", *TINY_CLI, "--quiet", "--no-render", "--out", str(tmp_path / "cli"))
    assert code == 0, err
    cli_run = diverse.load_run(tmp_path / "cli")
    assert tiny_run.D == cli_run.D
    assert summary(tiny_run.dir) == summary(tmp_path / "cli")
    assert open(os.path.join(tiny_run.dir, "log.jsonl")).read() == open(tmp_path / "cli" / "log.jsonl").read()
    for a, b in zip(tiny_run.motions, cli_run.motions):
        np.testing.assert_array_equal(a.qpos, b.qpos)


def test_load_run_reads_every_motion(tiny_run):
    assert len(tiny_run.motions) == 3 and tiny_run.all_satisfied
    for i, m in enumerate(tiny_run.motions):
        assert m.label == f"M{i}" and m.constraint == 0
        assert m.qpos.shape == (len(m.times), 19) and m.times[1] == m.timestep
        assert m.phases["rise"] > 0 and {t["name"] for t in m.terms} >= {"fall", "landing"}
        assert len(m.pose_samples["samples"]) == 20
        assert os.path.exists(m.model)
    d = tiny_run.distances("md")
    assert d[0, 1] > 0 and tiny_run.summary["metric"] == "md"
    with pytest.raises(diverse.UserError, match="^metric: expected one of hf, md, shape, wja, got xx$"):
        tiny_run.distances("xx")


def test_the_callback_sees_every_generation_and_stops_the_run(cli, tmp_path):
    seen = []

    def progress(record):
        seen.append(record)
        return record["generation"] < 1  # stop after the first generation

    stopped = diverse.run("jump_high", tmp_path / "py", **dict(TINY, generations=3), on_generation=progress)
    assert isinstance(stopped, diverse.StoppedRun) and stopped.generation == 1
    assert [r["generation"] for r in seen] == [1]
    assert seen[0]["constraint"].shape == (3,) and seen[0]["D"] > 0 and seen[0]["evaluations"] > 0
    assert not (tmp_path / "py" / "summary.json").exists()
    # Resumed, it ends as an uninterrupted run does.
    resumed = diverse.resume(tmp_path / "py", on_generation=lambda r: seen.append(r))
    assert [r["generation"] for r in seen] == [1, 2, 3]
    code, err = run_cli(cli, "run", "jump_high", *TINY_CLI[:2], "--generations", "3", *TINY_CLI[4:], "--quiet",
                        "--no-render", "--out", str(tmp_path / "cli"))
    assert code == 0, err
    assert resumed.D == diverse.load_run(tmp_path / "cli").D


def test_an_exception_in_the_callback_ends_the_run(tmp_path):
    def fails(record):
        raise KeyError("from the callback")

    with pytest.raises(KeyError, match="from the callback"):
        diverse.run("jump_high", tmp_path / "py", **TINY, on_generation=fails)


def spread(a, b):
    """A distance of our own: how far apart the links are, summed over the pose samples."""
    if a.link_com.shape != b.link_com.shape:
        return 0.0
    return float(np.sum((a.link_com - b.link_com) ** 2))


def test_a_python_metric_drives_a_run_to_four_variations(tmp_path, cli):
    run = diverse.run("jump_high", tmp_path / "py", variations=4, generations=3, popsize=8, sigma0=0.03, seed=5,
                      metric=spread)
    assert run.all_satisfied and len(run.motions) == 5
    assert run.summary["custom"] == {"metric": "python: spread"}
    # D is under the Python distance: eq. 1 from its matrix over the five motions.
    task = diverse.load_task("jump_high")
    rows = np.array([[m.parameters[n] for n in task.parameter_names] for m in run.motions])
    outcomes = [m.outcome for m in task.simulate_batch(rows)]
    d = np.array([[spread(a, b) for b in outcomes] for a in outcomes])
    dmin = np.array([min(d[i, j] for j in range(5) if j != i) for i in range(5)])
    assert run.D == pytest.approx(d.sum() + 10 * 5 * dmin.sum(), rel=1e-9)
    assert [m["dmin"] for m in run.summary["motions"]] == pytest.approx(list(dmin), rel=1e-9)
    # The CLI cannot resume it: it has not the Python code.
    code, err = run_cli(cli, "resume", str(tmp_path / "py"))
    assert code == 2 and "custom: the run's" in err and "resume it from that program" in err


def test_a_python_constraint_term_drives_a_run_to_four_variations(tmp_path, m0):
    # Land within 10 cm of where the input motion lands.
    def near_m0(o):
        return 1e3 * max(0.0, abs(o.landing_x - m0.landing_x) - 0.1)

    run = diverse.run("jump_high", tmp_path / "py", variations=4, generations=3, popsize=8, sigma0=0.03, seed=5,
                      constraint=near_m0)
    assert run.all_satisfied and len(run.motions) == 5
    assert run.summary["custom"] == {"constraint": "python: near_m0"}
    for m in run.motions:
        assert near_m0(type("O", (), {"landing_x": run.summary["motions"][m.index]["landing_x"]})) == 0


def test_a_term_no_motion_meets_shows_in_every_c(tmp_path):
    run = diverse.run("jump_high", tmp_path / "py", **dict(TINY, generations=1), constraint=lambda o: 2.5)
    assert not run.all_satisfied
    assert [m.constraint for m in run.motions] == [pytest.approx(2.5)] * 3


def test_python_side_errors(tmp_path):
    with pytest.raises(diverse.UserError, match=r"^metric: expected a finite number >= 0 from <lambda>, got -1.0$"):
        diverse.run("jump_high", tmp_path / "a", **TINY, metric=lambda a, b: -1.0)
    with pytest.raises(diverse.UserError, match=r"^constraint: expected a finite number >= 0 from <lambda>, got 'x'$"):
        diverse.run("jump_high", tmp_path / "b", **TINY, constraint=lambda o: "x")
    with pytest.raises(ZeroDivisionError):
        diverse.run("jump_high", tmp_path / "c", **TINY, metric=lambda a, b: 1 / 0)
    with pytest.raises(diverse.UserError, match=r"^on_generation: expected a function or None$"):
        diverse.run("jump_high", tmp_path / "d", **TINY, on_generation=3)
    with pytest.raises(diverse.UserError, match=r"^strategy: expected one of round-robin, progressive"):
        diverse.run("jump_high", tmp_path / "e", **dict(TINY, strategy="bogus"))
    with pytest.raises(diverse.UserError, match=r"^metric: expected a metric name"):
        diverse.run("jump_high", tmp_path / "f", **TINY, metric=3)
    with pytest.raises(diverse.UserError, match=r"already holds a run \(use --force"):
        diverse.run("jump_high", tmp_path / "a", **TINY)
    with pytest.raises(diverse.UserError, match=r"nothing: no such directory$"):
        diverse.load_run(tmp_path / "nothing")
    with pytest.raises(diverse.UserError, match=r": not a run directory \(no run.json; `diverse run TASK --out DIR` makes one\)$"):
        diverse.load_run(tmp_path)
