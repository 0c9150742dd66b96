//! `kanegen.Model`: a model read as the CLI reads it and the run-time path's algorithms on it
//! (`kanegen-dynamics`: CRBA, RNEA, ABA, their derivatives, `M⁻¹`, frame placements and
//! Jacobians), fixed or free-floating base, Pinocchio's layouts.

use crate::batch::{Arg, States};
use crate::lanes::{self, LaneData, LaneTables};
use crate::{catch, to_py};
use anyhow::{bail, Context};
use kanegen_dynamics::algorithms::derivatives::{self, Matrix};
use kanegen_dynamics::algorithms::{crba, floating, frames, rnea};
use kanegen_dynamics::kernels::{self, KernelData, KernelTables};
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::NonlinearEffectsMethod;
use kanegen_dynamics::{FloatingBase, FloatingState, Loads, MassMatrixMethod, Params};
use kanegen_model::{BaseKind, Model as Robot};
use kanegen_sim::provider::floating_state;
use pyo3::prelude::*;
use std::path::PathBuf;

/// The model and its numbers, shared by the workers of a batch.
struct Core {
    model: Robot,
    params: Params<f64>,
    /// The free-floating base (`None`: fixed).
    base: Option<FloatingBase<f64>>,
    gravity: Option<Vec3<f64>>,
    /// The run-time kernels' tables (fixed base: gravity in them; free-floating: in the loads).
    tables: KernelTables,
    /// On a fixed base, the tables on four lanes.
    lanes: Option<LaneTables>,
}

/// A worker's scratch for forward dynamics: the kernels' data and the loads (drives copied in).
struct Scratch {
    data: KernelData,
    loads: Loads<f64>,
}

/// The joint-space and base parts of one state.
struct Split<'a> {
    /// The base's pose and twist (free-floating only; at rest when `v` is not an argument).
    state: Option<FloatingState<f64>>,
    /// Joint positions.
    q: &'a [f64],
}

/// Tolerance on `|quaternion| − 1`.
const UNIT: f64 = 1e-6;

impl Core {
    fn n(&self) -> usize {
        self.params.dof()
    }

    fn nq(&self) -> usize {
        self.n() + if self.base.is_some() { 7 } else { 0 }
    }

    fn nv(&self) -> usize {
        self.n() + if self.base.is_some() { 6 } else { 0 }
    }

    fn loads(&self, tau: Option<&[f64]>) -> Loads<f64> {
        Loads {
            tau: tau.map(<[f64]>::to_vec),
            gravity: self.gravity.clone(),
            external: Vec::new(),
        }
    }

    /// `q` (and `v`) split into the base state and the joints' part (Pinocchio's free-flyer:
    /// `q = [p₀, quaternion x y z w, joints]`, `v = [v_b, ω_b, q̇]`).
    fn split<'a>(
        &self,
        q: &'a [f64],
        v: Option<&'a [f64]>,
    ) -> anyhow::Result<(Split<'a>, &'a [f64])> {
        let Some(_) = self.base else {
            return Ok((Split { state: None, q }, v.unwrap_or(&[])));
        };
        let quat = [q[3], q[4], q[5], q[6]];
        let norm = quat.iter().map(|x| x * x).sum::<f64>().sqrt();
        if (norm - 1.0).abs() > UNIT {
            bail!("q[3:7]: the base quaternion (x, y, z, w) has norm {norm}, not 1");
        }
        let (twist, qd) = match v {
            Some(v) => (&v[..6], &v[6..]),
            None => (&[0.0; 6][..], &[][..]),
        };
        let state = floating_state(q, twist);
        Ok((
            Split {
                state: Some(state),
                q: &q[7..],
            },
            qd,
        ))
    }

    fn mass_matrix(&self, q: &[f64]) -> anyhow::Result<Matrix<f64>> {
        let (s, _) = self.split(q, None)?;
        Ok(match (&self.base, &s.state) {
            (Some(b), Some(st)) => {
                floating::mass_matrix(MassMatrixMethod::Crba, &self.params, b, st, s.q)
            }
            _ => crba::mass_matrix(&self.params, s.q),
        })
    }

    /// `τ − c` at the drives `tau` (`None`: `−c`).
    fn tau_minus_c(&self, q: &[f64], v: &[f64], tau: Option<&[f64]>) -> anyhow::Result<Vec<f64>> {
        let (s, qd) = self.split(q, Some(v))?;
        let loads = self.loads(tau);
        Ok(match (&self.base, &s.state) {
            (Some(b), Some(st)) => floating::tau_minus_c(
                NonlinearEffectsMethod::Rnea,
                &self.params,
                b,
                st,
                s.q,
                qd,
                &loads,
            ),
            _ => rnea::tau_minus_c(&self.params, s.q, qd, &loads),
        })
    }

    fn inverse_dynamics(&self, q: &[f64], v: &[f64], a: &[f64]) -> anyhow::Result<Vec<f64>> {
        let (s, qd) = self.split(q, Some(v))?;
        let loads = self.loads(None);
        Ok(match (&self.base, &s.state) {
            (Some(b), Some(st)) => {
                let (p, (acc, qdd)) = (&self.params, base_acceleration(a));
                rnea::floating_inverse_dynamics(p, b, st, s.q, qd, &acc, qdd, &loads)
            }
            _ => rnea::inverse_dynamics(&self.params, s.q, qd, a, &loads),
        })
    }

    fn scratch(&self) -> Scratch {
        Scratch {
            data: KernelData::new(self.n()),
            loads: self.loads(Some(&vec![0.0; self.n()])),
        }
    }

    /// `q̈` (`ν̇`) into `out` by the run-time path's articulated-body kernel.
    fn forward_dynamics(
        &self,
        ws: &mut Scratch,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        out: &mut [f64],
    ) -> anyhow::Result<()> {
        let (s, qd) = self.split(q, Some(v))?;
        if let Some(t) = ws.loads.tau.as_mut() {
            t.copy_from_slice(tau);
        }
        let floating = self.base.as_ref().zip(s.state.as_ref());
        kernels::forward_dynamics(
            &self.tables,
            &mut ws.data,
            floating,
            s.q,
            qd,
            &ws.loads,
            None,
            out,
        );
        Ok(())
    }

    fn inverse_dynamics_derivatives(
        &self,
        q: &[f64],
        v: &[f64],
        a: &[f64],
    ) -> anyhow::Result<(Matrix<f64>, Matrix<f64>)> {
        let (s, qd) = self.split(q, Some(v))?;
        let g = self.gravity.as_ref();
        Ok(match (&self.base, &s.state) {
            (Some(b), Some(st)) => {
                let (p, (acc, qdd)) = (&self.params, base_acceleration(a));
                derivatives::rnea::floating_derivatives(p, b, st, s.q, qd, &acc, qdd, g)
            }
            _ => derivatives::rnea::derivatives(&self.params, s.q, qd, a, g),
        })
    }

    fn forward_dynamics_derivatives(
        &self,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
    ) -> anyhow::Result<(Matrix<f64>, Matrix<f64>, Matrix<f64>)> {
        let (s, qd) = self.split(q, Some(v))?;
        let g = self.gravity.as_ref();
        Ok(match (&self.base, &s.state) {
            (Some(b), Some(st)) => {
                derivatives::aba::floating_derivatives(&self.params, b, st, s.q, qd, tau, g)
            }
            _ => derivatives::aba::derivatives(&self.params, s.q, qd, tau, g),
        })
    }

    fn mass_matrix_inverse(&self, q: &[f64]) -> anyhow::Result<Matrix<f64>> {
        let (s, _) = self.split(q, None)?;
        Ok(match &self.base {
            Some(b) => derivatives::minverse::floating_mass_matrix_inverse(&self.params, b, s.q),
            None => derivatives::minverse::mass_matrix_inverse(&self.params, s.q),
        })
    }

    /// The index of the frame called `name`.
    fn frame(&self, name: &str) -> anyhow::Result<usize> {
        let frames = self.model.frames();
        frames.iter().position(|f| f.name == name).with_context(|| {
            let names: Vec<&str> = frames.iter().map(|f| f.name.as_str()).collect();
            format!(
                "no frame `{name}` in model `{}` (frames: {})",
                self.model.name(),
                names.join(", ")
            )
        })
    }

    fn frame_placement(&self, frame: usize, q: &[f64]) -> anyhow::Result<(Vec3<f64>, Mat3<f64>)> {
        let (s, _) = self.split(q, None)?;
        let f = &self.params.frames[frame];
        Ok(match &s.state {
            Some(st) => frames::floating_placement(&self.params, st, s.q, f),
            None => frames::placement(&self.params, s.q, f),
        })
    }

    fn frame_jacobian(&self, frame: usize, q: &[f64]) -> anyhow::Result<Matrix<f64>> {
        let (s, _) = self.split(q, None)?;
        let f = &self.params.frames[frame];
        Ok(match &s.state {
            Some(st) => frames::floating_jacobian(&self.params, st, s.q, f),
            None => frames::jacobian(&self.params, s.q, f),
        })
    }
}

/// `[v̇_b; ω̇_b]` and the joints' part of a free-floating acceleration `a`.
fn base_acceleration(a: &[f64]) -> ([f64; 6], &[f64]) {
    (core::array::from_fn(|k| a[k]), &a[6..])
}

/// What a method returns: an array, or a tuple of arrays.
type Res = PyResult<PyObject>;

/// The rows of matrices written one after another into `out`.
fn put(out: &mut [f64], ms: &[&Matrix<f64>]) -> anyhow::Result<()> {
    for (o, x) in out
        .iter_mut()
        .zip(ms.iter().flat_map(|m| m.iter().flatten()))
    {
        *o = *x;
    }
    Ok(())
}

/// `out = −x` (`c` from `τ − c` at `τ = 0`).
fn negated(out: &mut [f64], x: &[f64]) -> anyhow::Result<()> {
    for (o, b) in out.iter_mut().zip(x) {
        *o = -b;
    }
    Ok(())
}

/// A robot model (URDF or kanegen TOML) and the dynamics of the run-time path on it.
///
/// Every method takes one state (1-D arrays) or a batch (2-D arrays of shape `(B, n)`, evaluated
/// in Rust across cores) and returns numpy arrays (`(B, …)` for a batch). On a free-floating base
/// `q` is Pinocchio's free-flyer `[p₀ (3), quaternion x y z w (4), joints]` (length `nq = 7 + N`)
/// and velocities `[v_b (3), ω_b (3), q̇]` (length `nv = 6 + N`, base coordinates); `tau` is
/// always the `N` joint drives.
#[pyclass(module = "kanegen", frozen)]
pub struct Model {
    core: Core,
}

impl Model {
    fn new(model: Robot, gravity: Option<Vec<f64>>) -> anyhow::Result<Model> {
        if model.mimics().iter().any(Option::is_some) {
            bail!(
                "model `{}` has mimic joints, which the Python bindings do not support yet \
                 (`kanegen eval` and `kanegen generate` do)",
                model.name()
            );
        }
        let gravity = gravity
            .map(|g| {
                let text: Vec<String> = g.iter().map(f64::to_string).collect();
                kanegen_cli::states::parse_gravity(&text.join(",")).context("gravity")
            })
            .transpose()?;
        let params = Params::<f64>::new(&model);
        let base = match model.base_kind() {
            BaseKind::FreeFloating => model.base_inertial().map(FloatingBase::from_inertial),
            BaseKind::Fixed => None,
        };
        let tables = KernelTables::new(&params, gravity.filter(|_| base.is_none()));
        let lanes = base.is_none().then(|| lanes::lane_tables(&tables));
        Ok(Model {
            core: Core {
                params,
                base,
                gravity: gravity.map(Vec3),
                tables,
                lanes,
                model,
            },
        })
    }

    fn load_with(
        path: PathBuf,
        base: Option<&str>,
        gravity: Option<Vec<f64>>,
        allow_nonphysical: bool,
    ) -> anyhow::Result<Model> {
        let kind = base
            .map(|b| {
                BaseKind::from_name(b)
                    .with_context(|| format!("unknown base `{b}`: fixed or free-floating"))
            })
            .transpose()?;
        let model = kanegen_cli::app::load_with_base(&path, allow_nonphysical, kind)?;
        Model::new(model, gravity)
    }

    /// `f(arguments, output)` on the states of the `(name, array, length)` arguments, outputs
    /// of `shapes` ([`States::eval`], no scratch).
    fn each(
        &self,
        py: Python<'_>,
        args: &[(&str, &Arg<'_>, usize)],
        shapes: &[&[usize]],
        f: impl Fn(&[&[f64]], &mut [f64]) -> anyhow::Result<()> + Sync + Send,
    ) -> Res {
        let out = States::new(args)?.eval(py, shapes, || (), |(), x, o| f(x, o));
        out.map(Bound::unbind)
    }
}

/// A `PyResult` of a constructor's error chain.
fn build(r: anyhow::Result<Model>) -> PyResult<Model> {
    catch(|| r).map_err(|e| to_py(&e))
}

#[pymethods]
impl Model {
    /// Reads a model file (`.urdf` or `.toml`) as the CLI does. `base`: `"fixed"` or
    /// `"free-floating"` (default: the model's; a URDF's root link inertial is the free-floating
    /// base's); `gravity`: `(x, y, z)` in m/s², in the base frame (fixed base) or the inertial
    /// frame (free-floating), none by default; `allow_nonphysical`: accept link inertias that
    /// violate the triangle inequality (the CLI's `--allow-nonphysical`).
    #[staticmethod]
    #[pyo3(signature = (path, base = None, gravity = None, allow_nonphysical = false))]
    fn load(
        path: PathBuf,
        base: Option<&str>,
        gravity: Option<Vec<f64>>,
        allow_nonphysical: bool,
    ) -> PyResult<Model> {
        build(catch(|| {
            Model::load_with(path, base, gravity, allow_nonphysical)
        }))
    }

    /// A model from URDF text (fixed base unless `base="free-floating"`).
    #[staticmethod]
    #[pyo3(signature = (text, base = None, gravity = None))]
    fn from_urdf_string(
        text: &str,
        base: Option<&str>,
        gravity: Option<Vec<f64>>,
    ) -> PyResult<Model> {
        build(catch(|| {
            let mut model = kanegen_model::io::parse_urdf(text).context("URDF string")?;
            if let Some(b) = base {
                let kind = BaseKind::from_name(b)
                    .with_context(|| format!("unknown base `{b}`: fixed or free-floating"))?;
                model = model.with_base_kind(kind).context("base")?;
            }
            Model::new(model, gravity)
        }))
    }

    /// The model's name.
    #[getter]
    fn name(&self) -> String {
        self.core.model.name().to_string()
    }

    /// `"fixed"` or `"free-floating"`.
    #[getter]
    fn base(&self) -> &'static str {
        self.core.model.base_kind().name()
    }

    /// Gravity `(x, y, z)` or `None`.
    #[getter]
    fn gravity(&self) -> Option<[f64; 3]> {
        self.core.gravity.as_ref().map(|g| g.0)
    }

    /// Length of `q`: `N`, or `7 + N` on a free-floating base.
    #[getter]
    fn nq(&self) -> usize {
        self.core.nq()
    }

    /// Length of velocities and accelerations: `N`, or `6 + N` on a free-floating base.
    #[getter]
    fn nv(&self) -> usize {
        self.core.nv()
    }

    /// The joints in the order of `q` (after the base's entries).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        kanegen_cli::commands::eval::coordinate_names(&self.core.model)
            .into_iter()
            .map(str::to_string)
            .collect()
    }

    /// The named frames.
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.core
            .model
            .frames()
            .iter()
            .map(|f| f.name.clone())
            .collect()
    }

    fn __repr__(&self) -> String {
        format!(
            "kanegen.Model({:?}, base={:?}, nq={}, nv={})",
            self.core.model.name(),
            self.base(),
            self.core.nq(),
            self.core.nv()
        )
    }

    /// `M(q)`, `(nv, nv)` (CRBA; Pinocchio's `crba`).
    fn mass_matrix(&self, py: Python<'_>, q: Arg) -> Res {
        let c = &self.core;
        self.each(py, &[("q", &q, c.nq())], &[&[c.nv(), c.nv()]], |x, o| {
            put(o, &[&c.mass_matrix(x[0])?])
        })
    }

    /// `c(q, v)`, `(nv,)`: velocity products and gravity (RNEA; Pinocchio's `nonLinearEffects`).
    fn nonlinear_effects(&self, py: Python<'_>, q: Arg, v: Arg) -> Res {
        let c = &self.core;
        let args = [("q", &q, c.nq()), ("v", &v, c.nv())];
        self.each(py, &args, &[&[c.nv()]], |x, o| {
            negated(o, &c.tau_minus_c(x[0], x[1], None)?)
        })
    }

    /// `g(q)`, `(nv,)`: `c` at zero velocity (Pinocchio's `computeGeneralizedGravity`).
    fn gravity_effects(&self, py: Python<'_>, q: Arg) -> Res {
        let c = &self.core;
        let zero = vec![0.0; c.nv()];
        self.each(py, &[("q", &q, c.nq())], &[&[c.nv()]], |x, o| {
            negated(o, &c.tau_minus_c(x[0], &zero, None)?)
        })
    }

    /// `τ = M(q) a + c(q, v)`, `(nv,)` (RNEA; Pinocchio's `rnea`). On a free-floating base the
    /// first six entries are the wrench on the base (force, moment; base coordinates).
    fn inverse_dynamics(&self, py: Python<'_>, q: Arg, v: Arg, a: Arg) -> Res {
        let c = &self.core;
        let args = [("q", &q, c.nq()), ("v", &v, c.nv()), ("a", &a, c.nv())];
        self.each(py, &args, &[&[c.nv()]], |x, o| {
            o.copy_from_slice(&c.inverse_dynamics(x[0], x[1], x[2])?);
            Ok(())
        })
    }

    /// `q̈ = M⁻¹ (τ − c)`, `(nv,)` (the run-time path's articulated-body kernel; Pinocchio's
    /// `aba`). `tau`: the `N` joint drives.
    fn forward_dynamics(&self, py: Python<'_>, q: Arg, v: Arg, tau: Arg) -> Res {
        let c = &self.core;
        let args = [("q", &q, c.nq()), ("v", &v, c.nv()), ("tau", &tau, c.n())];
        let shapes: &[&[usize]] = &[&[c.nv()]];
        let states = States::new(&args)?;
        let out = match &c.lanes {
            // A fixed-base batch: four states per call of the kernels.
            Some(lt) if states.is_batch() => states.eval_chunked(
                py,
                shapes,
                lanes::LANES,
                || LaneData::new(c.n()),
                |d, [q, v, tau], o| {
                    lanes::forward_dynamics(lt, &c.tables, d, [q, v, tau], o);
                    Ok(())
                },
            ),
            _ => states.eval(
                py,
                shapes,
                || c.scratch(),
                |ws, x, o| c.forward_dynamics(ws, x[0], x[1], x[2], o),
            ),
        };
        out.map(Bound::unbind)
    }

    /// `(∂τ/∂q, ∂τ/∂v)`, `(nv, nv)` each, row `i` = `τ_i`, column `j` = input `j` (Pinocchio's
    /// `computeRNEADerivatives`; free-floating base: `∂/∂q` in the tangent space).
    fn inverse_dynamics_derivatives(&self, py: Python<'_>, q: Arg, v: Arg, a: Arg) -> Res {
        let c = &self.core;
        let args = [("q", &q, c.nq()), ("v", &v, c.nv()), ("a", &a, c.nv())];
        self.each(py, &args, &[&[c.nv(), c.nv()][..]; 2], |x, o| {
            let (dq, dv) = c.inverse_dynamics_derivatives(x[0], x[1], x[2])?;
            put(o, &[&dq, &dv])
        })
    }

    /// `(∂q̈/∂q, ∂q̈/∂v, M⁻¹)`, `(nv, nv)` each (Pinocchio's `computeABADerivatives`;
    /// free-floating base: `∂/∂q` in the tangent space). `tau`: the `N` joint drives.
    fn forward_dynamics_derivatives(&self, py: Python<'_>, q: Arg, v: Arg, tau: Arg) -> Res {
        let c = &self.core;
        let args = [("q", &q, c.nq()), ("v", &v, c.nv()), ("tau", &tau, c.n())];
        self.each(py, &args, &[&[c.nv(), c.nv()][..]; 3], |x, o| {
            let (dq, dv, minv) = c.forward_dynamics_derivatives(x[0], x[1], x[2])?;
            put(o, &[&dq, &dv, &minv])
        })
    }

    /// `M(q)⁻¹`, `(nv, nv)` (Pinocchio's `computeMinverse`).
    fn mass_matrix_inverse(&self, py: Python<'_>, q: Arg) -> Res {
        let c = &self.core;
        self.each(py, &[("q", &q, c.nq())], &[&[c.nv(), c.nv()]], |x, o| {
            put(o, &[&c.mass_matrix_inverse(x[0])?])
        })
    }

    /// The placement of frame `name`: `(position (3,), rotation (3, 3))`, in the base frame
    /// (fixed base) or the inertial frame (free-floating); `x_outer = R x_frame + position`.
    fn frame_placement(&self, py: Python<'_>, name: &str, q: Arg) -> Res {
        let c = &self.core;
        let f = c.frame(name).map_err(|e| to_py(&e))?;
        self.each(py, &[("q", &q, c.nq())], &[&[3], &[3, 3]], |x, o| {
            let (p, r) = c.frame_placement(f, x[0])?;
            o[..3].copy_from_slice(&p.0);
            let rows: Matrix<f64> = r.0.iter().map(|row| row.to_vec()).collect();
            put(&mut o[3..], &[&rows])
        })
    }

    /// The Jacobian of frame `name`, `(6, nv)`: rows `[v; ω]` of the frame origin, axes of the
    /// base frame (fixed base) or the inertial frame (free-floating): Pinocchio's
    /// `LOCAL_WORLD_ALIGNED`.
    fn frame_jacobian(&self, py: Python<'_>, name: &str, q: Arg) -> Res {
        let c = &self.core;
        let f = c.frame(name).map_err(|e| to_py(&e))?;
        self.each(py, &[("q", &q, c.nq())], &[&[6, c.nv()]], |x, o| {
            put(o, &[&c.frame_jacobian(f, x[0])?])
        })
    }
}
