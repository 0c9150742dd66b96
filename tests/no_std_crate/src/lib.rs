//! A flight controller's view of kanegen: no standard library, one `dynamics!`, a
//! computed-torque law on the generated code, and one `scene!` simulator.
#![no_std]

kanegen::dynamics!(TwoLink, "../../models/two_link.toml");

/// `τ = M(q) (q̈_d + k_d (q̇_d − q̇) + k_p (q_d − q)) + c(q, q̇)`.
#[must_use]
pub fn computed_torque(q: &[f64; 2], qd: &[f64; 2], q_ref: &[f64; 2]) -> [f64; 2] {
    let (kp, kd) = (4.0, 4.0);
    let a: [f64; 2] = core::array::from_fn(|i| kp * (q_ref[i] - q[i]) - kd * qd[i]);
    TwoLink::inverse_dynamics(q, qd, &a)
}

// The SSRMS effects scene (gravity, PD drives, damping, a tabulated inertial-frame wrench, RK4)
// as a compiled simulator.
kanegen::scene!(SsrmsEffects, "../../scenes/ssrms_effects.toml");

/// The SSRMS effects scene's state after its duration (`None` if the integration failed).
#[must_use]
pub fn ssrms_final_q() -> Option<[f64; 7]> {
    let mut last = SsrmsEffects::initial_state();
    SsrmsEffects::run(|_, s| last = *s).ok()?;
    Some(last.q)
}

// The compact form (loops over constant tables) of the same model: `no_std` as well.
kanegen::dynamics!(TwoLinkCompact, "../../models/two_link.toml", form = "compact");

/// Forward dynamics through the compact form.
#[must_use]
pub fn compact_forward_dynamics(q: &[f64; 2], qd: &[f64; 2], tau: &[f64; 2]) -> [f64; 2] {
    TwoLinkCompact::forward_dynamics(q, qd, tau)
}
