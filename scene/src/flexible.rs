//! Flexible joints: Spong's reduced model (M. W. Spong, "Modeling and control of elastic joint
//! robots", ASME J. Dyn. Sys. Meas. Control 109, 1987, eqs. (2.5)–(2.6)), with a viscous damper
//! beside each spring. Joint `i` is a motor coordinate `θ_i` (the rotor angle divided by the
//! gear ratio, so on the link side) joined to the link coordinate `q_i` by a torsional spring
//! `K_i` and damper `D_i`:
//!
//! ```text
//! link:   M(q) q̈ + c(q, q̇) = τ_s,        τ_s = K (θ − q) + D (θ̇ − q̇)
//! motor:  B θ̈ + τ_s = τ_m,                B_i = I_m,i n_i²
//! ```
//!
//! (Spong's assumption: the rotor's kinetic energy is that of its own spin only, so `B` is
//! constant and diagonal and the two equations couple only through the spring.) `τ_m` is the
//! scene's drive torque evaluated on the motor side — `τ_drive(t, θ, θ̇)` less the joint damping
//! `b θ̇` and Coulomb friction `τ_c tanh(θ̇ / v_s)` of `[effects]`, which are drive-train
//! losses; gravity and external wrenches load the links. The state of a flexible scene is
//! `[q, q̇, θ, θ̇]` (`4N`), starting from `θ = q₀`, `θ̇ = q̇₀` (springs unstretched). Its energy
//! is `½ q̇ᵀ M q̇ + ½ Σ B_i θ̇_i² + ½ Σ K_i (θ_i − q_i)²` (plus the gravitational potential).
//!
//! As `K → ∞` the model tends to the rigid arm with rotor inertia `B` on the diagonal of `M`
//! (`[effects] rotor`), the spring deflection to `τ_s / K`.
//!
//! Scene keys (`[effects] flexible = { … }`, each a number for every joint or one per joint):
//! `stiffness` `K` (N·m/rad, `> 0`), `damping` `D` (N·m·s/rad, `>= 0`, default 0),
//! `motor_inertia` `I_m` (kg·m², `> 0`), `gear_ratio` `n` (`!= 0`, default 1). Fixed base only;
//! not with `[effects] rotor` (the motor inertia is given here).

use crate::error::Coordinates;
use crate::Result;
use kanegen_model::bounds::GAIN;
use serde::Deserialize;

/// One number for every joint, or one per joint.
#[derive(Deserialize)]
#[serde(untagged)]
pub(crate) enum RawValues {
    Scalar(f64),
    Vector(Vec<f64>),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawFlexible {
    stiffness: RawValues,
    damping: Option<RawValues>,
    motor_inertia: RawValues,
    gear_ratio: Option<RawValues>,
}

/// Validated flexible-joint parameters (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct Flexible {
    /// Spring stiffness `K_i`, N·m/rad (`> 0`).
    pub stiffness: Vec<f64>,
    /// Spring damping `D_i`, N·m·s/rad (`>= 0`).
    pub damping: Vec<f64>,
    /// Rotor inertia `I_m,i`, kg·m² (`> 0`).
    pub motor_inertia: Vec<f64>,
    /// Gear ratio `n_i` (`!= 0`).
    pub gear_ratio: Vec<f64>,
    /// Reflected motor inertia `B_i = I_m,i n_i²`, kg·m².
    pub reflected: Vec<f64>,
}

/// One value per coordinate `n`, finite and within [`GAIN`] (the messages of the parser's
/// `check_len`, which this module does not call: the parser calls this module).
fn checked(key: &str, v: Vec<f64>, n: Coordinates<'_>) -> Result<Vec<f64>> {
    if v.len() != n.len() {
        return Err(n.wrong_count(key, v.len()));
    }
    GAIN.check(&v).map_err(|e| invalid!("{key}: {e}"))?;
    Ok(v)
}

fn values(key: &str, g: RawValues, n: Coordinates<'_>) -> Result<Vec<f64>> {
    let v = match g {
        RawValues::Scalar(x) => vec![x; n.len()],
        RawValues::Vector(v) => v,
    };
    checked(key, v, n)
}

impl Flexible {
    /// Validates the raw table of a scene with the joint coordinates `coordinates` (`line`:
    /// where the table starts).
    pub(crate) fn from_raw(
        r: RawFlexible,
        coordinates: Coordinates<'_>,
        line: usize,
    ) -> Result<Flexible> {
        let key = |k: &str| format!("effects.flexible.{k} (line {line})");
        let stiffness = values(&key("stiffness"), r.stiffness, coordinates)?;
        if stiffness.iter().any(|k| *k <= 0.0) {
            bail!("{}: must be > 0 (N·m/rad)", key("stiffness"));
        }
        let damping = match r.damping {
            None => vec![0.0; coordinates.len()],
            Some(d) => values(&key("damping"), d, coordinates)?,
        };
        if damping.iter().any(|d| *d < 0.0) {
            bail!("{}: must be >= 0 (N·m·s/rad)", key("damping"));
        }
        let motor_inertia = values(&key("motor_inertia"), r.motor_inertia, coordinates)?;
        if motor_inertia.iter().any(|i| *i <= 0.0) {
            bail!(
                "{}: must be > 0 (kg·m²; the motor equation divides by it)",
                key("motor_inertia")
            );
        }
        let gear_ratio = match r.gear_ratio {
            None => vec![1.0; coordinates.len()],
            Some(g) => values(&key("gear_ratio"), g, coordinates)?,
        };
        if gear_ratio.contains(&0.0) {
            bail!("{}: must be non-zero", key("gear_ratio"));
        }
        let reflected: Vec<f64> = motor_inertia
            .iter()
            .zip(&gear_ratio)
            .map(|(i, g)| i * g * g)
            .collect();
        let reflected = checked(&key("motor_inertia"), reflected, coordinates)?;
        Ok(Flexible {
            stiffness,
            damping,
            motor_inertia,
            gear_ratio,
            reflected,
        })
    }

    /// The spring-damper torques `τ_s = K (θ − q) + D (θ̇ − q̇)` on the links.
    #[must_use]
    pub fn spring_torque(&self, q: &[f64], qd: &[f64], th: &[f64], thd: &[f64]) -> Vec<f64> {
        (0..q.len())
            .map(|i| self.stiffness[i] * (th[i] - q[i]) + self.damping[i] * (thd[i] - qd[i]))
            .collect()
    }

    /// The motor kinetic and spring potential energy `½ Σ B θ̇² + ½ Σ K (θ − q)²`.
    #[must_use]
    pub fn energy(&self, q: &[f64], th: &[f64], thd: &[f64]) -> f64 {
        (0..q.len())
            .map(|i| {
                let e = th[i] - q[i];
                0.5 * (self.reflected[i] * thd[i] * thd[i] + self.stiffness[i] * e * e)
            })
            .sum()
    }

    /// Whether the springs dissipate (some `D_i > 0`).
    #[must_use]
    pub fn dissipates(&self) -> bool {
        self.damping.iter().any(|d| *d > 0.0)
    }
}
