//! The states file read by `kanegen eval`: `{"states":[{"q":[…],"qd":[…],"tau":[…]}]}`, each
//! state of a free-floating model also with `"base": {"position": [3], "quaternion": [x, y, z, w],
//! "v": [3], "omega": [3]}` (base linear and angular velocity in the base frame).

use anyhow::{bail, Context, Result};
use kanegen_model::bounds::{Bound, FORCE, GRAVITY, LENGTH, POSITION, RATE};
use serde::Deserialize;

/// One state: joint positions, rates and (optional) drive torques/forces.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct State {
    /// Joint positions (rad or m).
    pub q: Vec<f64>,
    /// Joint rates.
    pub qd: Vec<f64>,
    /// Joint drive torques/forces; zero when absent.
    #[serde(default)]
    pub tau: Option<Vec<f64>>,
    /// The base's pose and twist (free-floating models only).
    #[serde(default)]
    pub base: Option<BaseState>,
}

/// The state of a free-floating base (conventions of `kanegen_dynamics::base`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseState {
    /// Base-frame origin in the inertial frame, m.
    pub position: [f64; 3],
    /// Attitude, `[x, y, z, w]` (normalized on reading).
    pub quaternion: [f64; 4],
    /// Velocity of the base-frame origin, base coordinates, m/s.
    pub v: [f64; 3],
    /// Angular velocity, base coordinates, rad/s.
    pub omega: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StatesFile {
    states: Vec<State>,
}

/// Parses and validates a states file for a model whose coordinates are `joints` (their names,
/// in the order of `q`), on a free-floating base when `floating` (then every state needs `base`,
/// and a fixed-base model's states must not have it); errors name the state and field, and a
/// wrong length lists the joints.
pub fn parse_states(text: &str, joints: &[&str], floating: bool) -> Result<Vec<State>> {
    let n = joints.len();
    let mut f: StatesFile = serde_json::from_str(text).context("malformed states file")?;
    for (i, s) in f.states.iter_mut().enumerate() {
        match (&mut s.base, floating) {
            (None, true) => bail!(
                "states[{i}].base: missing (a free-floating model needs the base's position, \
                 quaternion, v and omega)"
            ),
            (Some(_), false) => bail!(
                "states[{i}].base: given for a fixed base (use --base free-floating, or a model \
                 whose [base] has type = \"free-floating\")"
            ),
            (Some(b), true) => {
                let all = b
                    .position
                    .iter()
                    .chain(&b.quaternion)
                    .chain(&b.v)
                    .chain(&b.omega);
                if all.clone().any(|x| !x.is_finite()) {
                    bail!("states[{i}].base: values must be finite");
                }
                for (name, v, bound) in [
                    ("position", &b.position, LENGTH),
                    ("v", &b.v, RATE),
                    ("omega", &b.omega, RATE),
                ] {
                    bound
                        .check(v)
                        .map_err(|e| anyhow::anyhow!("states[{i}].base.{name}: {e}"))?;
                }
                let norm = b.quaternion.iter().map(|x| x * x).sum::<f64>().sqrt();
                if !(norm > 1e-6 && norm.is_finite()) {
                    bail!("states[{i}].base.quaternion: must be non-zero (got norm {norm:e})");
                }
                b.quaternion = b.quaternion.map(|x| x / norm);
            }
            (None, false) => {}
        }
        let fields: [(&str, Option<&Vec<f64>>, Bound); 3] = [
            ("q", Some(&s.q), POSITION),
            ("qd", Some(&s.qd), RATE),
            ("tau", s.tau.as_ref(), FORCE),
        ];
        for (name, v, bound) in fields {
            let Some(v) = v else { continue };
            if v.len() != n {
                bail!(
                    "states[{i}].{name}: expected {n} values, got {}: the model's coordinates \
                     are, in this order, {}",
                    v.len(),
                    joints
                        .iter()
                        .map(|j| format!("`{j}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
            if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                bail!("states[{i}].{name}[{k}]: value is not finite");
            }
            for (k, x) in v.iter().enumerate() {
                bound
                    .check(&[*x])
                    .map_err(|e| anyhow::anyhow!("states[{i}].{name}[{k}]: {e}"))?;
            }
        }
    }
    Ok(f.states)
}

/// Parses a gravity vector `X,Y,Z` (m/s²) within [`GRAVITY`].
///
/// # Errors
/// A malformed vector, or a component beyond the bound.
pub fn parse_gravity(s: &str) -> Result<[f64; 3]> {
    let g = parse_vec3(s)?;
    GRAVITY.check(&g).map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(g)
}

/// Parses a vector written `X,Y,Z`.
pub fn parse_vec3(s: &str) -> Result<[f64; 3]> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        bail!("expected three comma-separated numbers X,Y,Z, got `{s}`");
    }
    let mut out = [0.0f64; 3];
    for (o, p) in out.iter_mut().zip(&parts) {
        *o = p
            .parse()
            .with_context(|| format!("`{p}` is not a number (in `{s}`)"))?;
        if !o.is_finite() {
            bail!("`{p}` is not finite");
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_wrong_lengths_and_unknown_keys() {
        let e =
            parse_states(r#"{"states":[{"q":[1,2],"qd":[1]}]}"#, &["a", "b"], false).unwrap_err();
        assert!(e.to_string().contains("states[0].qd"), "{e}");
        assert!(e.to_string().contains("in this order, `a`, `b`"), "{e}");
        let e = parse_states(
            r#"{"states":[{"q":[1,2],"qd":[1,2],"qdd":[0,0]}]}"#,
            &["a", "b"],
            false,
        )
        .unwrap_err();
        assert!(format!("{e:#}").contains("qdd"), "{e:#}");
        let ok = parse_states(
            r#"{"states":[{"q":[1,2],"qd":[1,2],"tau":[3,4]}]}"#,
            &["a", "b"],
            false,
        )
        .unwrap();
        assert_eq!(ok[0].tau.as_deref(), Some(&[3.0, 4.0][..]));
        assert!(parse_vec3("0,0,-9.81").unwrap()[2] == -9.81);
        assert!(parse_vec3("0,0").is_err() && parse_vec3("a,b,c").is_err());
    }

    #[test]
    fn free_floating_states_need_a_base_and_fixed_ones_refuse_it() {
        let base =
            r#""base":{"position":[0,0,0],"quaternion":[0,0,0,2],"v":[0,0,0],"omega":[0,0,1]}"#;
        let with = format!(r#"{{"states":[{{"q":[1],"qd":[0],{base}}}]}}"#);
        let s = parse_states(&with, &["a"], true).unwrap();
        assert_eq!(s[0].base.as_ref().unwrap().quaternion, [0.0, 0.0, 0.0, 1.0]);
        let e = parse_states(&with, &["a"], false).unwrap_err();
        assert!(e.to_string().contains("states[0].base"), "{e}");
        let e = parse_states(r#"{"states":[{"q":[1],"qd":[0]}]}"#, &["a"], true).unwrap_err();
        assert!(e.to_string().contains("states[0].base: missing"), "{e}");
        let zero = with.replace("[0,0,0,2]", "[0,0,0,0]");
        let e = parse_states(&zero, &["a"], true).unwrap_err();
        assert!(e.to_string().contains("quaternion"), "{e}");
    }
}
