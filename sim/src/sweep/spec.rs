//! The sweep file: a scene and the numbers of it that change from run to run.
//!
//! ```toml
//! scene = "capture_free_floating.toml"   # relative to the sweep file
//! runs = 100                             # Monte-Carlo runs per grid point (default 1)
//! seed = 2026                            # run k draws from stream k of ChaCha8(seed)
//!
//! [[parameter]]
//! key = "events[0].mass"                 # a number of the scene file, by its TOML path
//! uniform = [40.0, 160.0]                # or normal = { mean, std }, or values = […] (a grid)
//! ```
//!
//! A parameter's `key` names one number of the scene file (`payload.mass`, `initial.q[2]`,
//! `events[0].omega[1]`, `drives.kp`); the number is replaced in the scene's text, every other
//! line kept, so the scene's own validation (and its line numbers) judge each run. Parameters
//! with `values` span a grid (the first listed varies slowest); `runs` is the number of random
//! draws at each grid point.

use crate::scene::line_of;
use anyhow::{bail, Context, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::Spanned;
use toml_edit::{DocumentMut, Item, Value};

/// At most this many runs in one sweep.
pub const MAX_RUNS: u64 = 100_000_000;

/// How a parameter's value is chosen for a run.
#[derive(Clone, Debug, PartialEq)]
pub enum Draw {
    /// Uniform on `[lo, hi)`.
    Uniform {
        /// Lower bound.
        lo: f64,
        /// Upper bound (> `lo`).
        hi: f64,
    },
    /// Normal with this mean and standard deviation.
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation (> 0).
        std: f64,
    },
    /// One axis of the grid: every value, in order.
    Values(Vec<f64>),
}

/// One swept number of the scene.
#[derive(Clone, Debug)]
pub struct Parameter {
    /// Its TOML path in the scene file, as written (`events[0].mass`).
    pub key: String,
    /// The path's steps.
    path: Vec<Step>,
    /// How it is chosen.
    pub draw: Draw,
    /// Whether the scene holds an integer there (then only integral `values` are accepted).
    integer: bool,
}

/// A step of a key path: a table key or an array index.
#[derive(Clone, Debug, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
}

/// A validated sweep file.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The sweep file.
    pub path: PathBuf,
    /// The scene file.
    pub scene_path: PathBuf,
    /// The scene file's text.
    scene_text: String,
    /// Random draws per grid point.
    pub runs_per_point: u64,
    /// The seed of every run's generator.
    pub seed: u64,
    /// The swept numbers, in file order.
    pub parameters: Vec<Parameter>,
    /// FNV-1a (64 bit) of the sweep file, the scene file and the model file: shards of one sweep
    /// carry the same fingerprint.
    pub fingerprint: u64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSweep {
    scene: String,
    runs: Option<Spanned<u64>>,
    seed: Option<u64>,
    #[serde(default)]
    parameter: Vec<Spanned<RawParameter>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawParameter {
    key: String,
    uniform: Option<[f64; 2]>,
    normal: Option<RawNormal>,
    values: Option<Vec<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawNormal {
    mean: f64,
    std: f64,
}

impl Sweep {
    /// Reads and validates a sweep file, its scene (the nominal run must be a valid scene) and
    /// every parameter's key.
    ///
    /// # Errors
    /// A file that cannot be read, an unknown or missing key, a draw out of range, or a key that
    /// names no number of the scene, each with the sweep file and line.
    pub fn load(path: &Path) -> Result<Sweep> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read sweep `{}`", path.display()))?;
        Sweep::parse(&text, path).with_context(|| format!("sweep `{}`", path.display()))
    }

    fn parse(text: &str, path: &Path) -> Result<Sweep> {
        let raw: RawSweep = toml::from_str(text)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let scene_path = dir.join(&raw.scene);
        let scene_text = std::fs::read_to_string(&scene_path)
            .with_context(|| format!("scene: cannot read `{}`", scene_path.display()))?;
        let doc: DocumentMut = scene_text
            .parse()
            .with_context(|| format!("scene `{}`", scene_path.display()))?;
        let mut parameters = Vec::new();
        for p in raw.parameter {
            let line = line_of(text, p.span().start);
            let k = parameters.len();
            let p = parameter(p.into_inner(), &doc)
                .with_context(|| format!("parameter[{k}] (line {line})"))?;
            if parameters.iter().any(|q: &Parameter| q.key == p.key) {
                bail!(
                    "parameter[{k}] (line {line}): key `{}` is swept twice",
                    p.key
                );
            }
            parameters.push(p);
        }
        let runs_per_point = match raw.runs {
            None => 1,
            Some(r) => {
                let line = line_of(text, r.span().start);
                let r = *r.get_ref();
                let random = parameters
                    .iter()
                    .any(|p| !matches!(p.draw, Draw::Values(_)));
                if r == 0 || r > MAX_RUNS {
                    bail!("runs (line {line}): must be 1 to {MAX_RUNS}");
                }
                if r > 1 && !random {
                    bail!(
                        "runs (line {line}): {r} runs of the same numbers: more than one run \
                         per grid point needs a `uniform` or `normal` parameter"
                    );
                }
                r
            }
        };
        let mut sweep = Sweep {
            path: path.to_path_buf(),
            scene_path,
            scene_text,
            runs_per_point,
            seed: raw.seed.unwrap_or(0),
            parameters,
            fingerprint: 0,
        };
        if sweep.grid_points().saturating_mul(runs_per_point) > MAX_RUNS {
            bail!("the grid times `runs` is more than {MAX_RUNS} runs");
        }
        let nominal = sweep
            .scene_text_for(&[])
            .and_then(|t| sweep.parse_scene(&t));
        nominal.with_context(|| format!("scene `{}`", sweep.scene_path.display()))?;
        sweep.fingerprint = fingerprint(text, &sweep.scene_text, &sweep.model_bytes());
        Ok(sweep)
    }

    /// The number of grid points (1 without `values` parameters).
    #[must_use]
    pub fn grid_points(&self) -> u64 {
        self.parameters
            .iter()
            .filter_map(|p| match &p.draw {
                Draw::Values(v) => Some(v.len() as u64),
                _ => None,
            })
            .fold(1u64, u64::saturating_mul)
    }

    /// The number of runs: grid points × runs per point.
    #[must_use]
    pub fn runs(&self) -> u64 {
        self.grid_points() * self.runs_per_point
    }

    /// The scene text with `values` (one per parameter, in order; fewer: the rest nominal) in
    /// place of the swept numbers.
    ///
    /// # Errors
    /// Only on a value the file cannot hold (an integer parameter's fraction, never after
    /// validation).
    pub fn scene_text_for(&self, values: &[f64]) -> Result<String> {
        let mut doc: DocumentMut = self.scene_text.parse()?;
        for (p, &v) in self.parameters.iter().zip(values) {
            let target = number_at(doc.as_item_mut(), &p.path)
                .with_context(|| format!("key `{}`", p.key))?;
            let decor = target.decor().clone();
            *target = if p.integer {
                if v.fract() != 0.0 || v.abs() > 9.0e15 {
                    bail!("key `{}`: {v} is not an integer", p.key);
                }
                Value::from(v as i64)
            } else {
                Value::from(v)
            };
            *target.decor_mut() = decor;
        }
        Ok(doc.to_string())
    }

    /// Parses scene text as the sweep's scene file (paths relative to it).
    ///
    /// # Errors
    /// The scene's validation error, naming its key.
    pub fn parse_scene(&self, text: &str) -> Result<crate::scene::Scene> {
        let dir = self.scene_path.parent().unwrap_or(Path::new("."));
        Ok(crate::scene::Scene::parse(text, dir)?)
    }

    fn model_bytes(&self) -> Vec<u8> {
        let dir = self.scene_path.parent().unwrap_or(Path::new("."));
        crate::scene::Scene::model_path(&self.scene_text, dir)
            .and_then(|m| std::fs::read(m).ok())
            .unwrap_or_default()
    }
}

/// Validates one parameter against the scene document.
fn parameter(raw: RawParameter, doc: &DocumentMut) -> Result<Parameter> {
    let path = parse_key(&raw.key)?;
    let mut doc = doc.clone();
    let integer = number_at(doc.as_item_mut(), &path)
        .with_context(|| format!("key `{}`", raw.key))?
        .is_integer();
    let draw = match (raw.uniform, raw.normal, raw.values) {
        (Some([lo, hi]), None, None) => {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                bail!("uniform: [lo, hi] must be finite with lo < hi");
            }
            Draw::Uniform { lo, hi }
        }
        (None, Some(RawNormal { mean, std }), None) => {
            if !(mean.is_finite() && std.is_finite() && std > 0.0) {
                bail!("normal: mean must be finite and std finite and > 0");
            }
            Draw::Normal { mean, std }
        }
        (None, None, Some(v)) => {
            if v.is_empty() || v.iter().any(|x| !x.is_finite()) {
                bail!("values: must be a non-empty list of finite numbers");
            }
            Draw::Values(v)
        }
        _ => bail!("give exactly one of `uniform`, `normal` and `values`"),
    };
    if integer && !matches!(&draw, Draw::Values(v) if v.iter().all(|x| x.fract() == 0.0)) {
        bail!(
            "key `{}` is an integer in the scene: sweep it by `values` of integers",
            raw.key
        );
    }
    Ok(Parameter {
        key: raw.key,
        path,
        draw,
        integer,
    })
}

/// `events[0].omega[2]` as steps.
fn parse_key(key: &str) -> Result<Vec<Step>> {
    let bad = || anyhow::anyhow!("key `{key}`: expected a TOML path like `events[0].mass`");
    let mut steps = Vec::new();
    for segment in key.split('.') {
        let (name, mut rest) = segment.split_at(segment.find('[').unwrap_or(segment.len()));
        let name_ok = !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        if !name_ok {
            return Err(bad());
        }
        steps.push(Step::Key(name.to_string()));
        while !rest.is_empty() {
            let close = rest.find(']').ok_or_else(bad)?;
            let index = rest[1..close].parse::<usize>().map_err(|_| bad())?;
            steps.push(Step::Index(index));
            rest = &rest[close + 1..];
            if !(rest.is_empty() || rest.starts_with('[')) {
                return Err(bad());
            }
        }
    }
    Ok(steps)
}

/// The number at `path` in a scene document.
fn number_at<'a>(item: &'a mut Item, path: &[Step]) -> Result<&'a mut Value> {
    match (item, path.split_first()) {
        (Item::Value(v), _) => value_number(v, path),
        (Item::Table(t), Some((Step::Key(k), rest))) => {
            number_at(t.get_mut(k).ok_or_else(|| no_such(k))?, rest)
        }
        (Item::ArrayOfTables(a), Some((Step::Index(i), rest))) => {
            let n = a.len();
            let t = a.get_mut(*i).ok_or_else(|| out_of(*i, n))?;
            match rest.split_first() {
                Some((Step::Key(k), rest)) => {
                    number_at(t.get_mut(k).ok_or_else(|| no_such(k))?, rest)
                }
                Some((step, _)) => bail!("has no {}", describe(step)),
                None => bail!("names a table, not a number"),
            }
        }
        (_, None) => bail!("names a table, not a number"),
        (_, Some((step, _))) => bail!("has no {}", describe(step)),
    }
}

/// The number at `path` below a value.
fn value_number<'a>(v: &'a mut Value, path: &[Step]) -> Result<&'a mut Value> {
    match path.split_first() {
        None if v.is_float() || v.is_integer() => Ok(v),
        None => bail!("names a {}, not a number", v.type_name()),
        Some((step, rest)) => value_number(step_value(v, step)?, rest),
    }
}

fn step_value<'a>(v: &'a mut Value, step: &Step) -> Result<&'a mut Value> {
    match (v, step) {
        (Value::InlineTable(t), Step::Key(k)) => t.get_mut(k).ok_or_else(|| no_such(k)),
        (Value::Array(a), Step::Index(i)) => {
            let n = a.len();
            a.get_mut(*i).ok_or_else(|| out_of(*i, n))
        }
        (v, step) => bail!("a {} has no {}", v.type_name(), describe(step)),
    }
}

fn describe(step: &Step) -> String {
    match step {
        Step::Key(k) => format!("key `{k}`"),
        Step::Index(i) => format!("index [{i}]"),
    }
}

fn no_such(k: &str) -> anyhow::Error {
    anyhow::anyhow!("the scene has no key `{k}` there")
}

fn out_of(i: usize, n: usize) -> anyhow::Error {
    anyhow::anyhow!("index [{i}] out of range: the scene has {n}")
}

/// FNV-1a (64 bit) over the three files, each prefixed by its length.
fn fingerprint(sweep: &str, scene: &str, model: &[u8]) -> u64 {
    use std::hash::Hasher;
    let mut h = fnv::FnvHasher::default();
    for part in [sweep.as_bytes(), scene.as_bytes(), model] {
        h.write_u64(part.len() as u64);
        h.write(part);
    }
    h.finish()
}
