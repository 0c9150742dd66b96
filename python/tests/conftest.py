"""Shared fixtures: the repository root, the `kanegen` command line, random states."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def cli_command():
    """The `kanegen` binary: $KANEGEN_BIN, else the release build in target/, else cargo run."""
    env = os.environ.get("KANEGEN_BIN")
    if env:
        return [env]
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    built = target / "release" / "kanegen"
    if built.exists():
        return [str(built)]
    return ["cargo", "run", "--quiet", "--release", "--manifest-path", str(ROOT / "Cargo.toml"), "--"]


class Cli:
    """Runs the command line from the repository root."""

    def __init__(self):
        self.command = cli_command()

    def run(self, *args):
        """(returncode, stdout, stderr) of `kanegen ARGS`."""
        p = subprocess.run(
            self.command + [str(a) for a in args], cwd=ROOT, capture_output=True, text=True
        )
        return p.returncode, p.stdout, p.stderr

    def ok(self, *args):
        """Standard output of a run that must succeed."""
        code, out, err = self.run(*args)
        assert code == 0, err
        return out

    def json(self, *args):
        """`--json` output parsed."""
        return json.loads(self.ok(*args, "--json"))

    def error(self, *args):
        """The message of a run that must fail: stderr without `Error: `."""
        code, _, err = self.run(*args)
        assert code == 1, err
        # The binary writes `Error: {message}` and a newline.
        assert err.startswith("Error: ") and err.endswith("\n"), err
        return err[len("Error: "):-1]


@pytest.fixture(scope="session")
def cli():
    return Cli()


@pytest.fixture(scope="session")
def root():
    return ROOT


def random_state(model, rng, batch=None):
    """(q, v, x) with a unit base quaternion on a free-floating base; x a third vector of
    length nv (accelerations) and tau of the joints' length."""
    shape = (() if batch is None else (batch,))
    q = rng.uniform(-1.0, 1.0, shape + (model.nq,))
    if model.base == "free-floating":
        quat = q[..., 3:7]
        q[..., 3:7] = quat / np.linalg.norm(quat, axis=-1, keepdims=True)
    v = rng.uniform(-1.0, 1.0, shape + (model.nv,))
    a = rng.uniform(-1.0, 1.0, shape + (model.nv,))
    n = len(model.joint_names)
    tau = rng.uniform(-1.0, 1.0, shape + (n,))
    return q, v, a, tau
