"""Shared fixtures of the Python module's tests (ctest -R python_module).

ctest runs them with PYTHONPATH=BUILD/python and DIVERSE_CLI=BUILD/diverse; by hand:
    PYTHONPATH=build/python DIVERSE_CLI=build/diverse /usr/bin/python3 -m pytest tests/python
"""
import os
import subprocess

import pytest

import diverse

# A tiny run: enough generations for the optimizer to move, a few seconds on 2 cores.
TINY = dict(variations=2, generations=2, popsize=8, sigma0=0.03, seed=3)
TINY_CLI = ["--n", "2", "--generations", "2", "--popsize", "8", "--sigma0", "0.03", "--seed", "3"]


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("DIVERSE_CLI", os.path.join(os.path.dirname(__file__), "../../build/diverse"))
    if not os.path.exists(path):
        pytest.skip("DIVERSE_CLI: the diverse tool is not built")
    return path


def run_cli(cli, *args):
    """Runs the CLI; returns (exit code, stderr)."""
    p = subprocess.run([cli, *args], capture_output=True, text=True)
    return p.returncode, p.stderr


@pytest.fixture(scope="session")
def task():
    return diverse.load_task("jump_high")


@pytest.fixture(scope="session")
def m0(task):
    return task.simulate()


@pytest.fixture(scope="session")
def tiny_run(tmp_path_factory):
    """A finished tiny run from Python."""
    out = tmp_path_factory.mktemp("runs") / "py"
    return diverse.run("jump_high", out, **TINY)
