//! # kanegen-python
//!
//! The Python module `kanegen._kanegen` (re-exported as `kanegen`): a thin layer over the
//! library crates and the command line's library functions. [`Model`] holds a model read as the
//! CLI reads it (`kanegen_cli::app::load_with_base`) and evaluates the run-time path's
//! algorithms of `kanegen-dynamics` (CRBA, RNEA, ABA, their derivatives, `M⁻¹`, frames) on one
//! state or on a batch, the batch across cores ([`batch`]); [`count`] and [`generate`] run the
//! CLI's commands in process ([`kanegen_cli::app::run_args`]); [`simulate`] runs a scene as
//! `kanegen simulate` does and returns its samples. Every error is a `kanegen.KanegenError` with
//! the message the CLI prints after `Error: `; a panic is caught at the boundary and becomes
//! one too.
#![warn(missing_docs)]

mod batch;
mod lanes;
mod model;

use anyhow::Context;
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

pyo3::create_exception!(
    _kanegen,
    KanegenError,
    pyo3::exceptions::PyValueError,
    "An error of kanegen: its message is the one the command line prints after `Error: `."
);

/// The Python exception of an error chain, formatted as the CLI formats it (`{e:#}`).
pub(crate) fn to_py(e: &anyhow::Error) -> PyErr {
    KanegenError::new_err(format!("{e:#}"))
}

/// Runs `f` with a panic turned into an error (the message the panic carried).
pub(crate) fn catch<T>(f: impl FnOnce() -> anyhow::Result<T>) -> anyhow::Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|p| {
        let msg = p
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| p.downcast_ref::<&str>().copied())
            .unwrap_or("unknown panic");
        Err(anyhow::anyhow!("internal error: {msg}"))
    })
}

/// The CLI run in process on `args` (without the program name), its standard output returned.
fn run_cli(py: Python<'_>, args: Vec<String>) -> PyResult<String> {
    let out = py.allow_threads(|| {
        catch(|| {
            let mut buf = Vec::new();
            kanegen_cli::app::run_args(
                std::iter::once("kanegen".to_string()).chain(args),
                &mut buf,
            )?;
            Ok(String::from_utf8(buf)?)
        })
    });
    out.map_err(|e| to_py(&e))
}

/// `json.loads(text)`.
fn json_loads<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

/// A keyword option as CLI arguments: `name_x=True` is `--name-x`, `False` and `None` nothing, a
/// list or tuple `X,Y,Z`, anything else its `str()`.
fn option_args(key: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    let flag = format!("--{}", key.replace('_', "-"));
    if value.is_none() {
        return Ok(vec![]);
    }
    if let Ok(b) = value.downcast::<pyo3::types::PyBool>() {
        return Ok(if b.is_true() { vec![flag] } else { vec![] });
    }
    if value.is_instance_of::<pyo3::types::PyList>()
        || value.is_instance_of::<pyo3::types::PyTuple>()
    {
        let parts: Vec<String> = value
            .try_iter()?
            .map(|x| x?.str().map(|s| s.to_string()))
            .collect::<PyResult<_>>()?;
        return Ok(vec![flag, parts.join(",")]);
    }
    Ok(vec![flag, value.str()?.to_string()])
}

/// The CLI arguments of `path` and keyword options.
fn command_args(
    command: &str,
    path: PathBuf,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<String>> {
    let mut args = vec![command.to_string(), path.to_string_lossy().into_owned()];
    if let Some(opts) = options {
        for (k, v) in opts.iter() {
            args.extend(option_args(&k.extract::<String>()?, &v)?);
        }
    }
    Ok(args)
}

/// Operation counts of a model or a scene: what `kanegen count PATH --json` prints, as a dict.
/// Options are the command's flags: `algorithm="spatial"`, `base="free-floating"`,
/// `gravity=(0, 0, -9.81)`.
#[pyfunction]
#[pyo3(signature = (path, **options))]
fn count<'py>(
    py: Python<'py>,
    path: PathBuf,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut args = command_args("count", path, options)?;
    args.push("--json".into());
    json_loads(py, &run_cli(py, args)?)
}

/// The Rust source `kanegen generate PATH` emits, as a string. Options are the command's flags:
/// `gravity=(0, 0, -9.81)`, `base="free-floating"`, `name="Arm"`, `scalar="f32"`, `fma=True`,
/// `runtime_payload=True`, `no_derivatives=True`, `algorithm=...`, `snap=1e-9`, `lock="2=0.5"`,
/// `allow_nonphysical=True`, `ignore_mimic=True`, `allow_large=True`.
#[pyfunction]
#[pyo3(signature = (path, **options))]
fn generate(
    py: Python<'_>,
    path: PathBuf,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    run_cli(py, command_args("generate", path, options)?)
}

/// Integrates a scene as `kanegen simulate SCENE` does; returns a dict: `"t"` (T,), `"x"`
/// (T, K) the trajectory in the columns of the CLI's `trajectory.csv` without `t`, `"columns"`
/// their names, `"summary"` what `--json` prints (a dict).
#[pyfunction]
#[pyo3(signature = (path, allow_long = false))]
fn simulate<'py>(py: Python<'py>, path: PathBuf, allow_long: bool) -> PyResult<Bound<'py, PyDict>> {
    use kanegen_cli::commands::simulate_text::{csv_header, csv_values};
    use kanegen_sim::scene::{Scene, SceneOptions};
    use kanegen_sim::simulate::{simulate_to, Control, Sample};
    let run = py.allow_threads(|| {
        catch(|| {
            let scene = Scene::load_with(&path, SceneOptions { allow_long })?;
            let mut rows: Vec<Vec<f64>> = Vec::new();
            let mut sink = |s: &Sample| -> anyhow::Result<()> {
                rows.push(csv_values(&scene, s));
                Ok(())
            };
            let control = Control {
                progress: None,
                stop: None,
            };
            let summary = simulate_to(&scene, &mut sink, control)?;
            summary.check_finite()?;
            let summary = serde_json::to_string(&summary).context("summary")?;
            Ok((csv_header(&scene), rows, summary))
        })
    });
    let (header, rows, summary) = run.map_err(|e| to_py(&e))?;
    let k = header.len() - 1;
    let t: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let x: Vec<f64> = rows.iter().flat_map(|r| r[1..].iter().copied()).collect();
    let x = Array2::from_shape_vec((rows.len(), k), x).expect("rows of the header's length");
    let d = PyDict::new(py);
    d.set_item("t", t.into_pyarray(py))?;
    d.set_item("x", x.into_pyarray(py))?;
    d.set_item("columns", header[1..].to_vec())?;
    d.set_item("summary", json_loads(py, &summary)?)?;
    Ok(d)
}

/// The extension module.
#[pymodule]
fn _kanegen(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("KanegenError", m.py().get_type::<KanegenError>())?;
    m.add_class::<model::Model>()?;
    m.add_function(wrap_pyfunction!(count, m)?)?;
    m.add_function(wrap_pyfunction!(generate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    Ok(())
}
