"""The bindings against the command line: values, counts, generated code, simulations and
error messages."""

import json

import numpy as np
import pytest

import kanegen

from conftest import random_state


def eval_cli(cli, tmp_path, model_path, states, *flags):
    f = tmp_path / "states.json"
    f.write_text(json.dumps({"states": states}))
    return cli.json("eval", model_path, "--states", f, "--algorithm", "spatial", *flags)["results"]


@pytest.mark.parametrize("path", ["tests/data/erd/ur5_robot.urdf", "tests/data/erd/xarm7.urdf"])
def test_fixed_base_mass_matrix_and_effects_equal_eval(cli, root, tmp_path, path):
    g = [0.0, 0.0, -9.81]
    m = kanegen.Model.load(root / path, gravity=g)
    rng = np.random.default_rng(1)
    q, v, _, _ = random_state(m, rng, batch=5)
    states = [{"q": list(qk), "qd": list(vk)} for qk, vk in zip(q, v)]
    want = eval_cli(cli, tmp_path, path, states, "--gravity", "0,0,-9.81")
    got_m = m.mass_matrix(q)
    got_c = m.nonlinear_effects(q, v)
    for k, r in enumerate(want):
        np.testing.assert_allclose(got_m[k], r["A"], rtol=1e-12, atol=1e-12)
        # eval prints b = tau - c at tau = 0.
        np.testing.assert_allclose(-got_c[k], r["b"], rtol=1e-12, atol=1e-12)


def test_free_floating_equals_eval(cli, root, tmp_path):
    path = "models/dextre_standin.toml"
    m = kanegen.Model.load(root / path)
    assert m.base == "free-floating" and m.nq == m.nv + 1
    rng = np.random.default_rng(2)
    q, v, _, _ = random_state(m, rng, batch=3)
    states = [
        {
            "q": list(qk[7:]),
            "qd": list(vk[6:]),
            "base": {
                "position": list(qk[:3]),
                "quaternion": list(qk[3:7]),
                "v": list(vk[:3]),
                "omega": list(vk[3:6]),
            },
        }
        for qk, vk in zip(q, v)
    ]
    want = eval_cli(cli, tmp_path, path, states)
    for k, r in enumerate(want):
        np.testing.assert_allclose(m.mass_matrix(q[k]), r["A"], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(-m.nonlinear_effects(q[k], v[k]), r["b"], rtol=1e-12, atol=1e-9)


def test_names_equal_info(cli, root):
    info = cli.json("info", "tests/data/erd/xarm7.urdf")
    m = kanegen.Model.load(root / "tests/data/erd/xarm7.urdf")
    assert m.joint_names == [j["name"] for j in info["joints"]]
    assert m.frame_names == [f["name"] for f in info["frames"]]


def test_count_equals_cli(cli, root):
    assert kanegen.count(root / "models/two_link.toml") == cli.json("count", "models/two_link.toml")
    assert kanegen.count(root / "models/two_link.toml", algorithm="spatial", gravity=(0, 0, -9.81)) == cli.json(
        "count", "models/two_link.toml", "--algorithm", "spatial", "--gravity", "0,0,-9.81"
    )


def test_generate_equals_cli(cli, root):
    got = kanegen.generate(root / "models/two_link.toml", gravity=[0, 0, -9.81], name="Arm")
    assert got == cli.ok("generate", "models/two_link.toml", "--gravity", "0,0,-9.81", "--name", "Arm")
    assert "pub struct Arm" in got


def test_simulate_equals_cli(cli, root):
    got = kanegen.simulate(root / "scenes/free_floating_7dof.toml")
    want = cli.json("simulate", "scenes/free_floating_7dof.toml")
    # Everything but the wall-clock time.
    assert {k: v for k, v in got["summary"].items() if k != "wall_s"} == {
        k: v for k, v in want.items() if k != "wall_s"
    }
    assert got["x"].shape == (len(got["t"]), len(got["columns"]))
    assert got["columns"][:2] == ["q_" + n for n in kanegen.Model.load(
        root / "tests/data/reference/bmsd_7dof_free_floating.urdf", allow_nonphysical=True).joint_names[:2]]
    assert got["t"][0] == 0.0 and got["t"][-1] == pytest.approx(want["t_end"])


@pytest.mark.parametrize(
    "call, args",
    [
        (lambda p: kanegen.Model.load(p), ("eval", "{p}", "--states", "models/two_link.toml")),
        (lambda p: kanegen.count(p), ("count", "{p}")),
        (lambda p: kanegen.generate(p), ("generate", "{p}")),
    ],
)
def test_missing_file_message_equals_cli(cli, root, call, args):
    p = "no/such/model.urdf"
    want = cli.error(*[a.format(p=p) for a in args])
    with pytest.raises(kanegen.KanegenError) as e:
        call(p)
    assert str(e.value) == want


def test_bad_model_message_equals_cli(cli, root, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("name = 'x'\n[[joints]]\nname = 'j'\n")
    want = cli.error("count", bad)
    with pytest.raises(kanegen.KanegenError) as e:
        kanegen.Model.load(bad)
    assert str(e.value) == want
    with pytest.raises(kanegen.KanegenError) as e:
        kanegen.count(bad)
    assert str(e.value) == want


def test_base_and_gravity_messages_equal_cli(cli, root, monkeypatch):
    monkeypatch.chdir(root)
    want = cli.error("eval", "models/two_link.toml", "--states", "none.json", "--base", "free-floating")
    with pytest.raises(kanegen.KanegenError) as e:
        kanegen.Model.load("models/two_link.toml", base="free-floating")
    assert str(e.value) == want
    with pytest.raises(kanegen.KanegenError, match="exceeds the bound"):
        kanegen.Model.load(root / "models/two_link.toml", gravity=[0, 0, -1e9])
