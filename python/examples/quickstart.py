"""M(q) and q̈ of a 7-dof arm (xArm7 URDF) at one state and at a batch of states."""

import pathlib

import numpy as np

import kanegen

root = pathlib.Path(__file__).resolve().parents[2]
arm = kanegen.Model.load(root / "tests/data/erd/xarm7.urdf", gravity=[0.0, 0.0, -9.81])
print(arm, arm.joint_names)

q = np.linspace(-0.5, 0.5, arm.nq)
v = np.full(arm.nv, 0.1)
tau = np.zeros(arm.nv)
np.set_printoptions(precision=4, suppress=True, linewidth=120)
print("M =\n", arm.mass_matrix(q))
print("qdd =", arm.forward_dynamics(q, v, tau))

# A batch: rows are states, evaluated in Rust across cores.
qs = np.random.default_rng(0).uniform(-1.0, 1.0, (1000, arm.nq))
qdd = arm.forward_dynamics(qs, np.zeros_like(qs), np.zeros_like(qs))
print("batch:", qdd.shape)
