"""Forward dynamics of 10,000 states of a 7-dof arm (xArm7): kanegen's batch call against a
Python loop over `pinocchio.aba` on the same states (and against Pinocchio's own loop when it is
installed). Prints the best of several rounds of each, in ms, and the ratio.

Run: python python/examples/benchmark_forward_dynamics.py (with `pin` installed)."""

import os
import pathlib
import time

import numpy as np

import kanegen

ROUNDS = 7
B = 10_000

root = pathlib.Path(__file__).resolve().parents[2]
path = root / "tests/data/erd/xarm7.urdf"
g = [0.0, 0.0, -9.81]
arm = kanegen.Model.load(path, gravity=g)
rng = np.random.default_rng(0)
q = rng.uniform(-1.0, 1.0, (B, arm.nq))
v = rng.uniform(-1.0, 1.0, (B, arm.nv))
tau = rng.uniform(-1.0, 1.0, (B, arm.nv))


def best(f, rounds=ROUNDS, clock=time.perf_counter):
    """(best, median, last result) of `rounds` calls of f, by `clock`."""
    times = []
    for _ in range(rounds):
        t = clock()
        out = f()
        times.append(clock() - t)
    return min(times), sorted(times)[len(times) // 2], out


t_batch, med_batch, qdd = best(lambda: arm.forward_dynamics(q, v, tau))
print(f"cpus: {os.cpu_count()}, load average: {os.getloadavg()[0]:.2f}")
print(f"kanegen batch forward_dynamics, {B} states: best {t_batch * 1e3:.2f} ms, median {med_batch * 1e3:.2f} ms")
t_loop, _, _ = best(lambda: [arm.forward_dynamics(q[k], v[k], tau[k]) for k in range(B)], 3)
print(f"kanegen Python loop over single states: best {t_loop * 1e3:.1f} ms")

try:
    import pinocchio as pin
except ImportError:
    print("pinocchio not installed (pip install pin): no comparison")
    raise SystemExit(0)

pm = pin.buildModelFromUrdf(str(path))
pm.gravity.linear = np.array(g)
data = pm.createData()
t_pin, med_pin, want = best(lambda: np.array([pin.aba(pm, data, q[k], v[k], tau[k]) for k in range(B)]))
err = np.abs(qdd - want).max() / np.abs(want).max()
print(f"Python loop over pinocchio.aba ({pin.__version__}): best {t_pin * 1e3:.1f} ms, median {med_pin * 1e3:.1f} ms")
print(f"ratio (best / best): {t_pin / t_batch:.1f}x; max |qdd - aba| / max |aba| = {err:.1e}")
# CPU time (all threads of the process): what each side costs, whatever the machine's load.
c_batch = best(lambda: arm.forward_dynamics(q, v, tau), clock=time.process_time)[0]
c_pin = best(lambda: [pin.aba(pm, data, q[k], v[k], tau[k]) for k in range(B)], 3, time.process_time)[0]
print(f"CPU time per state: kanegen batch {c_batch / B * 1e9:.0f} ns, pinocchio.aba loop {c_pin / B * 1e9:.0f} ns ({c_pin / c_batch:.1f}x)")
