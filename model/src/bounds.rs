//! Magnitude bounds of the numbers kanegen reads (models, states, scenes, command-line values).
//!
//! The algorithms square and multiply these numbers (`m |c|²`, `I q̇²`, `|ω|² r`): each bound
//! keeps those products far from `f64` overflow (1.8e308) for any chain length, so a finite input
//! gives a finite result or a clear error, never a silent `NaN`. The bounds are generous physical
//! limits, not modelling advice: an orbit is 4e7 m across, the ISS weighs 4.2e5 kg.
//!
//! | quantity | bound |
//! |---|---|
//! | lengths: joint origins, centres of mass, frames, DH `a`, `d`, base position | 1e6 m |
//! | masses | 1e12 kg |
//! | inertia tensor entries | 1e18 kg·m² |
//! | gravity | 1e3 m/s² |
//! | joint positions `q`, lock values | 1e6 rad or m |
//! | joint and base rates `q̇`, `v`, `ω` | 1e6 rad/s or m/s |
//! | drive torques and forces `τ`, wrench forces and moments | 1e15 N or N·m |
//! | gains and damping coefficients | 1e15 (SI) |
//!
//! ```
//! use kanegen_model::bounds::LENGTH;
//! assert!(LENGTH.check(&[1.0, -2.0]).is_ok());
//! let e = LENGTH.check(&[0.0, 1e200]).unwrap_err();
//! assert_eq!(e, "|value| = 1e200 exceeds the bound 1e6 m (length)");
//! ```

/// A magnitude bound: every value must be finite with `|x| ≤ max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    /// What is bounded, for messages (`length`).
    pub quantity: &'static str,
    /// The largest magnitude allowed.
    pub max: f64,
    /// Unit, for messages (`m`).
    pub unit: &'static str,
}

/// Lengths: joint origins, centres of mass, frame placements, DH `a` and `d`, base positions.
pub const LENGTH: Bound = Bound {
    quantity: "length",
    max: 1e6,
    unit: "m",
};
/// Masses.
pub const MASS: Bound = Bound {
    quantity: "mass",
    max: 1e12,
    unit: "kg",
};
/// Inertia tensor entries.
pub const INERTIA: Bound = Bound {
    quantity: "inertia",
    max: 1e18,
    unit: "kg·m²",
};
/// Gravity vectors.
pub const GRAVITY: Bound = Bound {
    quantity: "gravity",
    max: 1e3,
    unit: "m/s²",
};
/// Joint positions and lock values.
pub const POSITION: Bound = Bound {
    quantity: "joint position",
    max: 1e6,
    unit: "rad or m",
};
/// Joint rates and base velocities.
pub const RATE: Bound = Bound {
    quantity: "rate",
    max: 1e6,
    unit: "rad/s or m/s",
};
/// Drive torques and forces, wrench forces and moments.
pub const FORCE: Bound = Bound {
    quantity: "force or torque",
    max: 1e15,
    unit: "N or N·m",
};
/// Drive gains and damping coefficients.
pub const GAIN: Bound = Bound {
    quantity: "gain",
    max: 1e15,
    unit: "SI",
};

impl Bound {
    /// Checks `xs`: `Err` with the message for the first value that is not finite or exceeds the
    /// bound (`|value| = 1e200 exceeds the bound 1e6 m (length)`).
    ///
    /// # Errors
    /// The message, without the field name (the caller adds it).
    pub fn check(&self, xs: &[f64]) -> Result<(), String> {
        for &x in xs {
            if !x.is_finite() {
                return Err(format!("value {x} is not finite"));
            }
            if x.abs() > self.max {
                return Err(format!(
                    "|value| = {:e} exceeds the bound {:e} {} ({})",
                    x.abs(),
                    self.max,
                    self.unit,
                    self.quantity
                ));
            }
        }
        Ok(())
    }
}

/// A direction normalized to unit length without overflow or underflow: outside `1e-100 ≤
/// max |vᵢ| ≤ 1e100` divided by its largest component first, so `[1e200, 0, 0]` gives
/// `[1, 0, 0]` (its square would overflow). `None` for a zero (or non-finite)
/// vector, or one shorter than `min_norm`.
#[must_use]
pub fn normalize(v: &[f64; 3], min_norm: f64) -> Option<[f64; 3]> {
    if v.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let m = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if m == 0.0 {
        return None;
    }
    // In the ordinary range the plain formula (bit-identical to earlier releases: a unit axis
    // stays the same bits); outside it, scaled by the largest component first.
    let s = if (1e-100..=1e100).contains(&m) {
        *v
    } else {
        v.map(|x| x / m)
    };
    let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    let norm = if (1e-100..=1e100).contains(&m) {
        n
    } else {
        m * n
    };
    if norm < min_norm {
        return None;
    }
    Some(s.map(|x| x / n))
}
