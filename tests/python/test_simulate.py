"""Tasks, simulate and the batch form against the CLI's own motion file."""
import json

import numpy as np
import pytest

import diverse
from conftest import run_cli


def test_task_names_ranges_and_input_motion(task):
    names = task.parameter_names
    assert task.name == "jump_high" and task.metric == "md" and task.variations == 4
    assert len(names) == len(set(names)) == len(task.lower) == len(task.upper) == len(task.m0) > 10
    assert np.all(task.lower < task.upper)
    assert np.all((task.m0 >= task.lower) & (task.m0 <= task.upper))
    # The input motion's file, as named values.
    m0_file = json.load(open(task.file.replace(".toml", ".m0.json")))
    values = m0_file.get("parameters", m0_file)
    assert [values[n] for n in names] == list(task.m0)
    x = task.normalize(task.m0)
    assert np.all((x >= 0) & (x <= 1))
    np.testing.assert_allclose(task.denormalize(x), task.m0, rtol=0, atol=1e-12)


def test_simulate_is_the_cli_motion_file(task, m0, cli, tmp_path):
    # `diverse simulate` writes the exact states of the same rollout: bit for bit the same.
    code, err = run_cli(cli, "simulate", "jump_high", "--no-film", "--out", str(tmp_path))
    assert code == 0, err
    motion = json.load(open(tmp_path / "motion.json"))
    replay = motion["replay"]
    assert m0.qpos.shape == (len(replay["qpos"]) + 1, replay["nq"]) == (m0.steps + 1, task.nq)
    np.testing.assert_array_equal(m0.qpos[0], replay["qpos0"])
    np.testing.assert_array_equal(m0.qpos[1:], np.array(replay["qpos"]))
    np.testing.assert_array_equal(m0.ctrl, np.array(replay["ctrl"]))
    assert m0.constraint == motion["constraint"]["total"] == 0 and m0.met
    assert [t["name"] for t in m0.terms] == [t["name"] for t in motion["constraint"]["terms"]]
    assert m0.half_timestep is True  # jump_high asks for the check, and M0 holds it
    assert {p["name"]: p["begin"] for p in motion["phases"]} == m0.phases
    assert m0.times[-1] == pytest.approx(m0.steps * m0.timestep)
    assert m0.effort == motion["effort"]


def test_arrays_are_read_only_views(m0):
    q = m0.qpos
    assert not q.flags.writeable and not q.flags.owndata
    with pytest.raises(ValueError):
        q[0, 0] = 1.0
    o = m0.outcome
    assert o.link_com.shape == (20, len(o.link_names), 3)
    assert o.angles.shape == (20, len(o.angle_names)) and o.root.shape == (20, 4)
    # Relative to the whole body's centre of mass: the mass-weighted mean is 0.
    assert o.link_mass.shape == (len(o.link_names),) and np.all(o.link_mass > 0)
    com = np.einsum("l,slk->sk", o.link_mass, o.link_com) / o.link_mass.sum()
    np.testing.assert_allclose(com, 0, atol=1e-12)


def test_a_changed_parameter_changes_the_motion(task, m0):
    p = task.m0.copy()
    p[0] = task.lower[0]
    changed = task.simulate(p)
    assert changed.params[0] == task.lower[0]
    assert changed.qpos.shape != m0.qpos.shape or not np.array_equal(changed.qpos, m0.qpos)
    assert diverse.distance(m0, changed, "md") > 0


def test_batch_equals_one_by_one_on_two_threads(task, m0):
    rows = np.stack([task.m0, task.lower + 0.5 * (task.upper - task.lower), task.m0])
    batch = task.simulate_batch(rows, threads=2)
    assert len(batch) == 3
    single = task.simulate(rows[1])
    for motion, reference in [(batch[0], m0), (batch[1], single), (batch[2], m0)]:
        np.testing.assert_array_equal(motion.qpos, reference.qpos)
        assert motion.constraint == reference.constraint
        assert motion.terms == reference.terms


def test_distances_are_the_runs(tiny_run, task):
    # A run's summary matrices come from the optimizer's outcomes; simulating the motion
    # files' parameters again gives the same distances.
    rows = np.array([[m.parameters[n] for n in task.parameter_names] for m in tiny_run.motions])
    motions = task.simulate_batch(rows, threads=2)
    for metric in ["hf", "md", "wja"]:
        d = diverse.distances(motions, metric)
        assert d.shape == (3, 3)
        np.testing.assert_array_equal(d, d.T)
        np.testing.assert_array_equal(np.diag(d), 0)
        np.testing.assert_allclose(d, tiny_run.distances(metric), rtol=1e-12, atol=0)
        assert diverse.distance(motions[0], motions[1], metric) == d[0, 1]


def test_errors_are_the_clis_lines(task, cli, tmp_path):
    code, err = run_cli(cli, "simulate", "no_such_task", "--out", str(tmp_path))
    with pytest.raises(diverse.UserError) as e:
        diverse.load_task("no_such_task")
    assert code == 2 and err.strip() == "diverse: error: " + str(e.value)
    with pytest.raises(diverse.UserError, match=r"^params: expected \d+ values \(the parameters of jump_high\), got 2$"):
        task.simulate([1.0, 2.0])
    p = task.m0.copy()
    p[3] = task.upper[3] + 1
    with pytest.raises(diverse.UserError, match=r"^params: " + task.parameter_names[3] + r": expected a number in \["):
        task.simulate(p)
    with pytest.raises(diverse.UserError, match=r"^params\[1\]: " + task.parameter_names[3] + ": expected a number"):
        task.simulate_batch(np.stack([task.m0, p]))
    with pytest.raises(diverse.UserError, match=r"^params: expected a 2-D array"):
        task.simulate_batch(task.m0)
    with pytest.raises(diverse.UserError, match=r"^metric: unknown metric 'xx'"):
        diverse.distance(task.simulate(), task.simulate(), "xx")
    with pytest.raises(diverse.UserError, match=r"^a: expected a Motion"):
        diverse.distance(1, task.simulate())
    with pytest.raises(diverse.UserError, match=r"^strength: expected a number in \[0.1, 10\]"):
        diverse.load_task("jump_high", strength=20)
    assert issubclass(diverse.UserError, ValueError)
