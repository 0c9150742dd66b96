//! Computed-torque control of the SSRMS (7 dof, fixed base, in orbit) on kanegen's generated code.
//!
//! The controller is `τ = ID(q, q̇, q̈_d + K_d (q̇_d − q̇) + K_p (q_d − q))` with the generated,
//! allocation-free inverse dynamics; the plant is integrated with RK4 on the generated forward
//! dynamics. The arm starts 0.01 rad off a 60 s quintic slew of every joint and converges onto
//! it, within the SSRMS joint torque limit of 2332 N m.
//!
//! Run: `cargo run --release --example computed_torque`

use kanegen_generated::ssrms::Ssrms;

const N: usize = Ssrms::N;

/// Quintic from `q0` to `q1` over `tf` with zero end rates and accelerations: (q, q̇, q̈) at `t`.
fn quintic(q0: f64, q1: f64, tf: f64, t: f64) -> (f64, f64, f64) {
    let s = (t / tf).clamp(0.0, 1.0);
    let d = q1 - q0;
    let p = 10.0 * s.powi(3) - 15.0 * s.powi(4) + 6.0 * s.powi(5);
    let dp = (30.0 * s.powi(2) - 60.0 * s.powi(3) + 30.0 * s.powi(4)) / tf;
    let ddp = (60.0 * s - 180.0 * s.powi(2) + 120.0 * s.powi(3)) / (tf * tf);
    if t >= tf {
        (q1, 0.0, 0.0)
    } else {
        (q0 + d * p, d * dp, d * ddp)
    }
}

fn main() {
    let (tf, dt) = (60.0, 0.01);
    let (kp, kd) = (0.25, 1.0); // critically damped error dynamics, ω_n = 0.5 rad/s
    let q_start = [0.0; N];
    let q_goal = [0.3, -0.4, 0.5, -0.6, 0.4, -0.3, 0.2];
    let desired = |t: f64| {
        let mut out = ([0.0; N], [0.0; N], [0.0; N]);
        for j in 0..N {
            let (a, b, c) = quintic(q_start[j], q_goal[j], tf, t);
            (out.0[j], out.1[j], out.2[j]) = (a, b, c);
        }
        out
    };
    let control = |t: f64, q: &[f64; N], qd: &[f64; N]| -> [f64; N] {
        let (q_d, qd_d, qdd_d) = desired(t);
        let qdd_ref: [f64; N] =
            core::array::from_fn(|j| qdd_d[j] + kd * (qd_d[j] - qd[j]) + kp * (q_d[j] - q[j]));
        Ssrms::inverse_dynamics(q, qd, &qdd_ref)
    };
    // State x = (q, q̇); τ held constant over a step (zero-order hold, as a digital controller).
    let deriv =
        |q: &[f64; N], qd: &[f64; N], tau: &[f64; N]| (*qd, Ssrms::forward_dynamics(q, qd, tau));
    let mut q: [f64; N] = core::array::from_fn(|j| q_start[j] + 0.01);
    let mut qd = [0.0; N];
    let mut t = 0.0;
    let mut step = 0usize;
    let mut max_tau = [0.0f64; N];
    println!(
        "{:>6} {:>14} {:>14}",
        "t [s]", "max |q_d − q|", "max |τ| [N m]"
    );
    while t < tf + 10.0 - 1e-9 {
        let tau = control(t, &q, &qd);
        for j in 0..N {
            max_tau[j] = max_tau[j].max(tau[j].abs());
        }
        let add = |a: &[f64; N], b: &[f64; N], h: f64| -> [f64; N] {
            core::array::from_fn(|j| a[j] + h * b[j])
        };
        let (k1q, k1v) = deriv(&q, &qd, &tau);
        let (k2q, k2v) = deriv(&add(&q, &k1q, dt / 2.0), &add(&qd, &k1v, dt / 2.0), &tau);
        let (k3q, k3v) = deriv(&add(&q, &k2q, dt / 2.0), &add(&qd, &k2v, dt / 2.0), &tau);
        let (k4q, k4v) = deriv(&add(&q, &k3q, dt), &add(&qd, &k3v, dt), &tau);
        for j in 0..N {
            q[j] += dt / 6.0 * (k1q[j] + 2.0 * k2q[j] + 2.0 * k3q[j] + k4q[j]);
            qd[j] += dt / 6.0 * (k1v[j] + 2.0 * k2v[j] + 2.0 * k3v[j] + k4v[j]);
        }
        t += dt;
        step += 1;
        if step.is_multiple_of(1000) {
            let (q_d, _, _) = desired(t);
            let err = (0..N).map(|j| (q_d[j] - q[j]).abs()).fold(0.0, f64::max);
            let tmax = max_tau.iter().copied().fold(0.0, f64::max);
            println!("{t:>6.1} {err:>14.3e} {tmax:>14.3}");
        }
    }
    let (q_d, _, _) = desired(t);
    let err = (0..N).map(|j| (q_d[j] - q[j]).abs()).fold(0.0, f64::max);
    println!("final tracking error {err:.3e} rad (SSRMS joint torque limit 2332 N m)");
    let tmax = max_tau.iter().copied().fold(0.0, f64::max);
    assert!(err < 1e-6, "computed-torque control did not converge");
    assert!(tmax < 2332.0, "torque limit exceeded: {tmax} N m");
}
