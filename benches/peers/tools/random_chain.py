#!/usr/bin/env python3
"""Seeded random serial chains with general geometry, written as URDF.

usage: random_chain.py N [N ...] --out DIR [--seed 20260101] [--length 1.0] [--mass 10.0]

Writes DIR/random_nN.urdf for each N: a fixed base link `base` (massless) and N revolute joints
`j1 .. jN`, each moving one link `b1 .. bN`. The generator follows kanegen-model's
`random::random_chain` (model/src/random.rs) in distribution, with numpy's PCG64 instead of
ChaCha8, so the chains are not the same numbers as the project's benches/data/random_n*.toml:

* joint origin: translation uniform in [-1, 1]^3 · length; rotation = a random unit axis
  (uniform direction, rejection-sampled in the unit ball) turned by an angle uniform in
  [-3, 3] rad, written as URDF `rpy` (fixed-axis roll, pitch, yaw);
* joint axis: a random unit vector (same sampling), 17 significant digits;
* body: mass = mass · U(0.2, 2); principal moments of a solid box with sides
  U(0.1, 1) · length each, (m (b² + c²) / 12, ...), turned by a random rotation into the body
  axes (full tensor, symmetric, positive definite, triangle inequality holds by construction);
  centre of mass uniform in [-0.6, 0.6]^3 · length. URDF `<inertial>` with `<origin xyz=com
  rpy="0 0 0">`, so Pinocchio and kanegen read the same tensor in body axes.
* `<limit>` is written because URDF requires it for revolute joints; it plays no part in the
  dynamics.

Every chain is drawn from its own stream, seeded with (seed, N), so adding or removing an N does
not change the other chains. No number is snapped: nothing lies near 0 or ±1 on purpose, so the
"clean" variant of the peer harness equals the raw one for these chains.
"""
import argparse
import math
import os

import numpy as np


def unit(rng):
    while True:
        v = rng.uniform(-1.0, 1.0, 3)
        n = float(np.linalg.norm(v))
        if 0.2 < n <= 1.0:
            return v / n


def axis_rotation(u, ang):
    s, c = math.sin(ang), math.cos(ang)
    K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return c * np.eye(3) + s * K + (1.0 - c) * np.outer(u, u)


def random_rotation(rng):
    u = unit(rng)
    return axis_rotation(u, rng.uniform(-3.0, 3.0))


def rpy_of(R):
    """URDF rpy with R = Rz(yaw) Ry(pitch) Rx(roll)."""
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    roll = math.atan2(R[2, 1], R[2, 2])
    yaw = math.atan2(R[1, 0], R[0, 0])
    return roll, pitch, yaw


def chain_urdf(n, seed, length, mass):
    rng = np.random.default_rng([seed, n])
    f = lambda x: repr(float(x))
    v3 = lambda v: " ".join(f(x) for x in v)
    out = ['<?xml version="1.0"?>',
           f'<!-- random chain N = {n}, seed ({seed}, {n}), benches/peers/tools/random_chain.py; generated, do not edit -->',
           f'<robot name="random_n{n}">', '  <link name="base"/>']
    for j in range(1, n + 1):
        xyz = rng.uniform(-1.0, 1.0, 3) * length
        rpy = rpy_of(random_rotation(rng))
        axis = unit(rng)
        m = mass * rng.uniform(0.2, 2.0)
        d = length * rng.uniform(0.1, 1.0, 3)
        p = np.array([d[1] ** 2 + d[2] ** 2, d[0] ** 2 + d[2] ** 2, d[0] ** 2 + d[1] ** 2]) * m / 12.0
        Rb = random_rotation(rng)
        I = Rb @ np.diag(p) @ Rb.T
        I = 0.5 * (I + I.T)
        com = rng.uniform(-0.6, 0.6, 3) * length
        parent = "base" if j == 1 else f"b{j - 1}"
        out += [f'  <joint name="j{j}" type="revolute">',
                f'    <parent link="{parent}"/>', f'    <child link="b{j}"/>',
                f'    <origin xyz="{v3(xyz)}" rpy="{v3(rpy)}"/>',
                f'    <axis xyz="{v3(axis)}"/>',
                '    <limit lower="-6.283185307179586" upper="6.283185307179586" effort="1000" velocity="10"/>',
                '  </joint>',
                f'  <link name="b{j}">', '    <inertial>',
                f'      <origin xyz="{v3(com)}" rpy="0 0 0"/>', f'      <mass value="{f(m)}"/>',
                f'      <inertia ixx="{f(I[0, 0])}" ixy="{f(I[0, 1])}" ixz="{f(I[0, 2])}" '
                f'iyy="{f(I[1, 1])}" iyz="{f(I[1, 2])}" izz="{f(I[2, 2])}"/>',
                '    </inertial>', '  </link>']
    out.append('</robot>')
    return "\n".join(out) + "\n"


def main():
    p = argparse.ArgumentParser()
    p.add_argument("n", nargs="+", type=int)
    p.add_argument("--out", required=True)
    p.add_argument("--seed", type=int, default=20260101)
    p.add_argument("--length", type=float, default=1.0)
    p.add_argument("--mass", type=float, default=10.0)
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    for n in a.n:
        path = os.path.join(a.out, f"random_n{n}.urdf")
        open(path, "w").write(chain_urdf(n, a.seed, a.length, a.mass))
        print(path)


if __name__ == "__main__":
    main()
