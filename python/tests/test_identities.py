"""Identities of the dynamics, derivatives against central differences, batches against loops,
and the errors of bad arguments."""

import numpy as np
import pytest

import kanegen

from conftest import random_state

MODELS = [
    ("tests/data/erd/xarm7.urdf", {"gravity": [0.0, 0.0, -9.81]}),
    ("tests/data/erd/b1-z1.urdf", {"gravity": [0.0, 0.0, -9.81]}),
    ("models/dextre_standin.toml", {"gravity": [0.1, -0.2, 0.3]}),
]


@pytest.fixture(params=MODELS, ids=[m[0].split("/")[-1] for m in MODELS])
def model(request, root):
    path, kw = request.param
    return kanegen.Model.load(root / path, **kw)


def integrate(model, q, dv):
    """q ⊕ dv: Pinocchio's integrate (base: p0 += R0 dv_lin, R0 ← R0 exp(dω)), joints added."""
    if model.base == "fixed":
        return q + dv
    out = q.copy()
    x, y, z, w = q[3:7]
    r = rotation(q[3:7])
    out[:3] = q[:3] + r @ dv[:3]  # first order in dv: enough for central differences of O(h²)
    dq = quat_from_rotvec(dv[3:6])
    out[3:7] = quat_mul(np.array([x, y, z, w]), dq)
    out[7:] = q[7:] + dv[6:]
    return out


def rotation(quat):
    x, y, z, w = quat
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def quat_from_rotvec(r):
    t = np.linalg.norm(r)
    if t == 0:
        return np.array([0.0, 0.0, 0.0, 1.0])
    axis = r / t
    return np.concatenate([axis * np.sin(t / 2), [np.cos(t / 2)]])


def quat_mul(a, b):
    (ax, ay, az, aw), (bx, by, bz, bw) = a, b
    return np.array(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ]
    )


def test_mass_matrix_symmetric_positive_and_inverse(model):
    q, _, _, _ = random_state(model, np.random.default_rng(3))
    m = model.mass_matrix(q)
    assert m.shape == (model.nv, model.nv)
    np.testing.assert_allclose(m, m.T, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(m) > 0)
    np.testing.assert_allclose(m @ model.mass_matrix_inverse(q), np.eye(model.nv), atol=1e-9)


def test_inverse_of_forward_dynamics(model):
    q, v, _, tau = random_state(model, np.random.default_rng(4))
    a = model.forward_dynamics(q, v, tau)
    back = model.inverse_dynamics(q, v, a)
    want = np.concatenate([np.zeros(model.nv - len(tau)), tau])
    np.testing.assert_allclose(back, want, atol=1e-9)
    # M a + c = tau
    np.testing.assert_allclose(model.mass_matrix(q) @ a + model.nonlinear_effects(q, v), want, atol=1e-9)
    np.testing.assert_allclose(model.gravity_effects(q), model.nonlinear_effects(q, np.zeros(model.nv)), atol=1e-12)


def test_derivatives_against_central_differences(model):
    q, v, a, tau = random_state(model, np.random.default_rng(5))
    h = 1e-6
    nv = model.nv
    dq, dv = model.inverse_dynamics_derivatives(q, v, a)
    fq, fv, minv = model.forward_dynamics_derivatives(q, v, tau)
    np.testing.assert_allclose(minv, model.mass_matrix_inverse(q), atol=1e-10)
    fds = [np.zeros((len(dq), nv)), np.zeros((len(dv), nv)), np.zeros((len(fq), nv)), np.zeros((len(fv), nv))]
    for j in range(nv):
        e = np.zeros(nv)
        e[j] = h
        qp, qm = integrate(model, q, e), integrate(model, q, -e)
        fds[0][:, j] = (model.inverse_dynamics(qp, v, a) - model.inverse_dynamics(qm, v, a)) / (2 * h)
        fds[1][:, j] = (model.inverse_dynamics(q, v + e, a) - model.inverse_dynamics(q, v - e, a)) / (2 * h)
        fds[2][:, j] = (model.forward_dynamics(qp, v, tau) - model.forward_dynamics(qm, v, tau)) / (2 * h)
        fds[3][:, j] = (model.forward_dynamics(q, v + e, tau) - model.forward_dynamics(q, v - e, tau)) / (2 * h)
    for k, (got, want) in enumerate(zip([dq, dv, fq, fv], fds)):
        # Central differences: O(h²) truncation, O(ε |f| / h) rounding; bounded relative to the
        # matrix's largest entry.
        err = np.abs(got - want).max() / (1.0 + np.abs(want).max())
        assert err < 1e-6, (k, err)


def test_frame_jacobian_against_placement_differences(model):
    q, _, _, _ = random_state(model, np.random.default_rng(6))
    name = model.frame_names[-1]
    jac = model.frame_jacobian(name, q)
    assert jac.shape == (6, model.nv)
    h = 1e-6
    for j in range(model.nv):
        e = np.zeros(model.nv)
        e[j] = h
        (p1, r1), (p0, r0) = model.frame_placement(name, integrate(model, q, e)), model.frame_placement(name, integrate(model, q, -e))
        np.testing.assert_allclose(jac[:3, j], (p1 - p0) / (2 * h), atol=1e-6)
        # ω from Ṙ Rᵀ
        w = (r1 - r0) / (2 * h) @ model.frame_placement(name, q)[1].T
        np.testing.assert_allclose(jac[3:, j], [w[2, 1], w[0, 2], w[1, 0]], atol=1e-6)


def test_batch_equals_loop(model):
    q, v, a, tau = random_state(model, np.random.default_rng(7), batch=33)
    calls = [
        ("mass_matrix", (q,)),
        ("nonlinear_effects", (q, v)),
        ("gravity_effects", (q,)),
        ("inverse_dynamics", (q, v, a)),
        ("forward_dynamics", (q, v, tau)),
        ("mass_matrix_inverse", (q,)),
        ("inverse_dynamics_derivatives", (q, v, a)),
        ("forward_dynamics_derivatives", (q, v, tau)),
    ]
    for name, args in calls:
        f = getattr(model, name)
        got = f(*args)
        for k in range(len(q)):
            one = f(*(x[k] for x in args))
            if isinstance(one, tuple):
                for g, o in zip(got, one):
                    np.testing.assert_array_equal(g[k], o)
            else:
                np.testing.assert_array_equal(got[k], one)
    frame = model.frame_names[0]
    pos, rot = model.frame_placement(frame, q)
    assert pos.shape == (33, 3) and rot.shape == (33, 3, 3)
    np.testing.assert_array_equal(model.frame_jacobian(frame, q)[5], model.frame_jacobian(frame, q[5]))


def test_strided_and_fortran_order_batches_equal_contiguous_ones(model):
    q, v, a, tau = random_state(model, np.random.default_rng(11), batch=9)
    want = model.forward_dynamics(q, v, tau)
    # Every other row of a doubled batch, and column-major copies: not C-contiguous.
    doubled = [np.repeat(x, 2, axis=0)[::2] for x in (q, v, tau)]
    assert not doubled[0].flags["C_CONTIGUOUS"]
    np.testing.assert_array_equal(model.forward_dynamics(*doubled), want)
    fortran = [np.asfortranarray(x) for x in (q, v, tau)]
    np.testing.assert_array_equal(model.forward_dynamics(*fortran), want)
    np.testing.assert_array_equal(model.mass_matrix(fortran[0]), model.mass_matrix(q))


def test_lists_and_integers_are_accepted(root):
    m = kanegen.Model.load(root / "models/two_link.toml")
    np.testing.assert_array_equal(m.mass_matrix([0, 1]), m.mass_matrix(np.array([0.0, 1.0])))


def test_bad_arguments_raise_with_the_argument_named(root):
    m = kanegen.Model.load(root / "models/two_link.toml")
    with pytest.raises(kanegen.KanegenError, match=r"^q: expected shape \(2,\) or \(B, 2\), got \(3,\)$"):
        m.mass_matrix(np.zeros(3))
    with pytest.raises(kanegen.KanegenError, match=r"^v: expected shape \(2,\) or \(B, 2\), got \(4, 3\)$"):
        m.nonlinear_effects(np.zeros((4, 2)), np.zeros((4, 3)))
    with pytest.raises(kanegen.KanegenError, match=r"^tau: shape \(5, 2\) does not match the batch of the arguments before it \(4 states\)$"):
        m.forward_dynamics(np.zeros((4, 2)), np.zeros((4, 2)), np.zeros((5, 2)))
    with pytest.raises(kanegen.KanegenError, match=r"^v: shape \(4, 2\) does not match the batch of the arguments before it \(one state\)$"):
        m.nonlinear_effects(np.zeros(2), np.zeros((4, 2)))
    with pytest.raises(kanegen.KanegenError, match=r"^q\[1, 0\] = NaN is not finite$"):
        m.mass_matrix(np.array([[0.0, 0.0], [np.nan, 0.0]]))
    with pytest.raises(kanegen.KanegenError, match=r"^no frame `hand` in model `two_link`"):
        m.frame_jacobian("hand", np.zeros(2))
    with pytest.raises((TypeError, ValueError)):
        m.mass_matrix("ab")


def test_unit_quaternion_required(root):
    m = kanegen.Model.load(root / "models/dextre_standin.toml")
    q = np.zeros(m.nq)
    with pytest.raises(kanegen.KanegenError, match=r"^q\[3:7\]: the base quaternion"):
        m.mass_matrix(q)
    q = np.zeros((2, m.nq))
    q[:, 6] = 1.0
    q[1, 6] = 2.0
    with pytest.raises(kanegen.KanegenError, match=r"^state 1: q\[3:7\]"):
        m.mass_matrix(q)
