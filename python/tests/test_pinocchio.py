"""Against Pinocchio: its values committed in tests/data (always), and Pinocchio itself on random
states when `import pinocchio` works."""

import json

import numpy as np
import pytest

import kanegen

from conftest import random_state


@pytest.mark.parametrize("name", ["ur5_robot", "xarm7", "z1"])
def test_derivatives_equal_committed_pinocchio_values(root, name):
    ref = json.loads((root / "tests/data/reference/derivatives.json").read_text())
    g = ref["gravity"]
    m = kanegen.Model.load(root / "tests/data/erd" / f"{name}.urdf", gravity=g)
    assert m.joint_names == ref["models"][name]["joints"]
    for s in ref["models"][name]["fixed"]:
        dq, dv = m.inverse_dynamics_derivatives(s["q"], s["v"], s["a"])
        fq, fv, minv = m.forward_dynamics_derivatives(s["q"], s["v"], s["tau"])
        for got, want in [
            (dq, s["rnea"]["dtau_dq"]),
            (dv, s["rnea"]["dtau_dv"]),
            (fq, s["aba"]["ddq_dq"]),
            (fv, s["aba"]["ddq_dv"]),
            (minv, s["minv"]),
        ]:
            np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("name", ["ur5_robot", "xarm7", "kinova"])
def test_dynamics_and_frames_equal_committed_pinocchio_values(root, name):
    ref = json.loads((root / "tests/data/erd" / f"{name}.reference.json").read_text())
    fixed = ref["fixed"]
    m = kanegen.Model.load(root / "tests/data/erd" / f"{name}.urdf", gravity=fixed["gravity"])
    # Pinocchio's body frames that are kanegen's frames (its joint frames are not).
    frames = [(k, f["name"]) for k, f in enumerate(ref["frames"]) if f["kind"] == "body"]
    frames = [(k, n) for k, n in frames if n in m.frame_names]
    assert frames
    for s in fixed["states"]:
        np.testing.assert_allclose(m.mass_matrix(s["q"]), s["A"], rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(m.nonlinear_effects(s["q"], s["qd"]), s["nle_gravity"], rtol=1e-9, atol=1e-9)
        for k, name_f in frames:
            want = s["frames"][k]
            p, r = m.frame_placement(name_f, s["q"])
            np.testing.assert_allclose(p, want["translation"], atol=1e-9)
            np.testing.assert_allclose(r, want["rotation"], atol=1e-9)


def test_against_pinocchio(root):
    pin = pytest.importorskip("pinocchio", reason="Pinocchio (pip install pin) is not installed")
    path = root / "tests/data/erd/xarm7.urdf"
    g = [0.0, 0.0, -9.81]
    m = kanegen.Model.load(path, gravity=g)
    pm = pin.buildModelFromUrdf(str(path))
    pm.gravity.linear = np.array(g)
    data = pm.createData()
    q, v, a, tau = random_state(m, np.random.default_rng(8), batch=20)
    fd = m.forward_dynamics(q, v, tau)
    for k in range(len(q)):
        np.testing.assert_allclose(m.mass_matrix(q[k]), np.triu(pin.crba(pm, data, q[k])) + np.triu(data.M, 1).T, atol=1e-9)
        np.testing.assert_allclose(m.nonlinear_effects(q[k], v[k]), pin.nonLinearEffects(pm, data, q[k], v[k]), atol=1e-9)
        np.testing.assert_allclose(fd[k], pin.aba(pm, data, q[k], v[k], tau[k]), atol=1e-9)
        np.testing.assert_allclose(m.inverse_dynamics(q[k], v[k], a[k]), pin.rnea(pm, data, q[k], v[k], a[k]), atol=1e-9)
        dq, dv, _ = pin.computeRNEADerivatives(pm, data, q[k], v[k], a[k])
        got_q, got_v = m.inverse_dynamics_derivatives(q[k], v[k], a[k])
        np.testing.assert_allclose(got_q, dq, atol=1e-9)
        np.testing.assert_allclose(got_v, dv, atol=1e-9)
