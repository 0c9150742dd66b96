//! The velocity jump of a perfectly plastic payload capture on a free-floating base (Yoshida,
//! Nenchev & Uchiyama, "Impact dynamics of space robots"; Brach, *Mechanical Impact Dynamics*,
//! ch. 7; `kanegen_sim::events` derives it): the generalized momentum of system and payload is
//! kept,
//!
//! `H' ν⁺ = H ν⁻ + J_pᵀ h_p`,  `h_p = [m_p v_p; R I_p Rᵀ ω_p]`,
//!
//! `H` and `H'` the mass matrices before and after (the payload merged into the capturing body),
//! `J_p` the 6 × (6+N) Jacobian of the payload's centre-of-mass frame and `R` its rotation.

use crate::ode::solve_spd;

/// A payload as a capture catches it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CapturedPayload {
    /// Mass `m_p`, kg.
    pub mass: f64,
    /// Inertia `I_p` about its centre of mass, in the capturing body's axes.
    pub inertia: [[f64; 3]; 3],
    /// Velocity `v_p` of its centre of mass (inertial frame).
    pub v: [f64; 3],
    /// Angular velocity `ω_p` (inertial frame).
    pub omega: [f64; 3],
}

impl CapturedPayload {
    /// Its momentum `h_p = [m_p v_p; R I_p Rᵀ ω_p]` (inertial frame, the spin about its centre
    /// of mass), `r` the rotation of its centre-of-mass frame.
    #[must_use]
    pub fn momentum(&self, r: &[[f64; 3]; 3]) -> [f64; 6] {
        let wb: [f64; 3] = core::array::from_fn(|i| {
            r[0][i] * self.omega[0] + r[1][i] * self.omega[1] + r[2][i] * self.omega[2]
        });
        let iw: [f64; 3] = core::array::from_fn(|i| {
            self.inertia[i][0] * wb[0] + self.inertia[i][1] * wb[1] + self.inertia[i][2] * wb[2]
        });
        let spin = |i: usize| r[i][0] * iw[0] + r[i][1] * iw[1] + r[i][2] * iw[2];
        let m = self.mass;
        [
            m * self.v[0],
            m * self.v[1],
            m * self.v[2],
            spin(0),
            spin(1),
            spin(2),
        ]
    }
}

/// `ν⁺` of the module doc's impulse equation from the mass matrices `h` (before) and `h_new`
/// (after), `armature` (`N`, the reflected rotor inertia) added to the joint diagonal of both,
/// the payload's centre-of-mass frame rotation `r` and Jacobian `jp`, and `nu` (`ν⁻`); NaN when
/// `H'` is not positive definite (an LDLᵀ pivot `<= 0`).
#[must_use]
pub fn capture_velocity<const NV: usize>(
    mut h: [[f64; NV]; NV],
    mut h_new: [[f64; NV]; NV],
    armature: Option<&[f64]>,
    r: &[[f64; 3]; 3],
    jp: &[[f64; NV]; 6],
    payload: &CapturedPayload,
    nu: &[f64; NV],
) -> [f64; NV] {
    if let Some(a) = armature {
        let off = NV.saturating_sub(a.len());
        for (i, ai) in a.iter().enumerate().take(NV - off) {
            h[off + i][off + i] += ai;
            h_new[off + i][off + i] += ai;
        }
    }
    let hp = payload.momentum(r);
    let p: [f64; NV] = core::array::from_fn(|i| {
        let own: f64 = h[i].iter().zip(nu).map(|(hij, nj)| hij * nj).sum();
        own + (0..6).map(|row| jp[row][i] * hp[row]).sum::<f64>()
    });
    solve_spd(&h_new, &p).unwrap_or([f64::NAN; NV])
}
