//! The states file read by `kanegen eval`: `{"states":[{"q":[…],"qd":[…],"tau":[…]}]}`.

use anyhow::{bail, Context, Result};
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
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StatesFile {
    states: Vec<State>,
}

/// Parses and validates a states file for a chain with `n` joints; errors name the state and field.
pub fn parse_states(text: &str, n: usize) -> Result<Vec<State>> {
    let f: StatesFile = serde_json::from_str(text).context("malformed states file")?;
    for (i, s) in f.states.iter().enumerate() {
        let fields: [(&str, Option<&Vec<f64>>); 3] = [
            ("q", Some(&s.q)),
            ("qd", Some(&s.qd)),
            ("tau", s.tau.as_ref()),
        ];
        for (name, v) in fields {
            let Some(v) = v else { continue };
            if v.len() != n {
                bail!(
                    "states[{i}].{name}: expected {n} values (the model has {n} joints), got {}",
                    v.len()
                );
            }
            if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                bail!("states[{i}].{name}[{k}]: value is not finite");
            }
        }
    }
    Ok(f.states)
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
        let e = parse_states(r#"{"states":[{"q":[1,2],"qd":[1]}]}"#, 2).unwrap_err();
        assert!(e.to_string().contains("states[0].qd"), "{e}");
        let e = parse_states(r#"{"states":[{"q":[1,2],"qd":[1,2],"qdd":[0,0]}]}"#, 2).unwrap_err();
        assert!(format!("{e:#}").contains("qdd"), "{e:#}");
        let ok = parse_states(r#"{"states":[{"q":[1,2],"qd":[1,2],"tau":[3,4]}]}"#, 2).unwrap();
        assert_eq!(ok[0].tau.as_deref(), Some(&[3.0, 4.0][..]));
        assert!(parse_vec3("0,0,-9.81").unwrap()[2] == -9.81);
        assert!(parse_vec3("0,0").is_err() && parse_vec3("a,b,c").is_err());
    }
}
