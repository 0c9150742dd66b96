//! The run-time dynamics under a scene's right-hand side ([`kanegen_runtime::scene`]): on the
//! run-time fast path, the articulated-body kernel of the compact form
//! ([`kanegen_runtime::compact::aba`]) over the model's tables built at run time (rotor inertia
//! as its armature, a free-floating base as its root); otherwise the algorithms of
//! `kanegen-dynamics`: `M` and `τ − c` of the scene's algorithm, then LDLᵀ. A model with mimic
//! joints runs in its coordinates ([`kanegen_dynamics::mimic`]): the state is expanded to the
//! full joint list, the algorithms run on the full tree (drives on the independent joints,
//! wrenches on their bodies), and `M`, `τ − c`, inverse dynamics and the derivatives are reduced
//! by the coupling `G` (`Gᵀ M_full G`, `Gᵀ (τ_full − c_full)`), then LDLᵀ.

use crate::scene::Scene;
use kanegen_dynamics::algorithms::derivatives;
use kanegen_dynamics::algorithms::floating;
use kanegen_dynamics::algorithms::frames;
use kanegen_dynamics::base::{quat_to_matrix, FloatingBase, FloatingState, BASE_BODY};
use kanegen_dynamics::kernels::{self, KernelData, KernelTables};
use kanegen_dynamics::linalg::Mat3;
use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::mimic::Coupling;
use kanegen_dynamics::{Dynamics, ForwardMethod, Loads, Methods, Params};
use kanegen_dynamics::{FrameParams, LoadFrame};
use kanegen_runtime::scene::{forward_with_armature, SceneDerivatives, SceneDynamics, WrenchBody};

/// The state of a free-floating base from the provider's positions `q = [p₀, quat, …]` and
/// speeds `v = [v_b, ω_b, …]`.
#[must_use]
pub fn floating_state(q: &[f64], v: &[f64]) -> FloatingState<f64> {
    FloatingState {
        position: Vec3::new(q[0], q[1], q[2]),
        rotation: quat_to_matrix(&[q[3], q[4], q[5], q[6]]),
        v_b: Vec3::new(v[0], v[1], v[2]),
        omega_b: Vec3::new(v[3], v[4], v[5]),
    }
}

/// The run-time dynamics of a scene as a [`SceneDynamics`] provider.
pub struct RunTimeDynamics {
    /// The model's numbers (changed by a payload event).
    pub params: Params<f64>,
    /// The free-floating base body, `None` on a fixed base.
    pub base: Option<FloatingBase<f64>>,
    /// The algorithm of `A`, `b` and inverse dynamics.
    pub algorithm: Methods,
    /// The kernels' tables and scratch on the fast path, `None` for LDLᵀ.
    fast: Option<(KernelTables, KernelData)>,
    /// The coupling of a model with mimic joints to its coordinates, `None` without.
    pub coupling: Option<Coupling>,
    /// Gravity, `τ` (preallocated) and the scene's wrenches (their values written per call).
    loads: Loads<f64>,
}

impl RunTimeDynamics {
    /// The dynamics of `scene`, solving for the accelerations by `forward`.
    #[must_use]
    pub fn new(scene: &Scene, forward: ForwardMethod) -> Self {
        let params = Params::new(&scene.model);
        let base = match &scene.base {
            crate::scene::BaseSpec::Fixed => None,
            crate::scene::BaseSpec::FreeFloating { inertial, .. } => {
                Some(FloatingBase::from_inertial(inertial))
            }
        };
        let gravity = scene.gravity.filter(|_| base.is_none());
        let coupling = scene
            .model
            .has_mimics()
            .then(|| Coupling::new(scene.model.mimics()));
        // The articulated-body kernels run on the full tree: mimic joints take LDLᵀ of the
        // reduced `M`.
        let aba = forward == ForwardMethod::Aba && coupling.is_none();
        RunTimeDynamics {
            fast: aba.then(|| kernel_model(&params, gravity)),
            coupling,
            params,
            base,
            algorithm: scene.simulation.algorithm,
            loads: Loads {
                tau: Some(vec![0.0; scene.dof()]),
                gravity: scene.gravity.map(Vec3::from_f64),
                external: scene.wrenches.iter().map(|w| w.at(0.0)).collect(),
            },
        }
    }

    /// Replaces the model's numbers (a payload captured or released).
    pub fn set_params(&mut self, params: Params<f64>) {
        if self.fast.is_some() {
            // The tables hold gravity on a fixed base only (a floating one takes it per call).
            let g = self.loads.gravity.as_ref().filter(|_| self.base.is_none());
            self.fast = Some(kernel_model(&params, g.map(|g| g.0)));
        }
        self.params = params;
    }

    /// Writes `tau` (when given) and the wrench values `w` (6 a wrench) into the loads.
    fn set_loads(&mut self, tau: Option<&[f64]>, w: &[f64]) {
        if let (Some(t), Some(tau)) = (self.loads.tau.as_mut(), tau) {
            t.copy_from_slice(tau);
        }
        for (l, wk) in self.loads.external.iter_mut().zip(w.chunks_exact(6)) {
            l.force = Vec3::new(wk[0], wk[1], wk[2]);
            l.moment = Vec3::new(wk[3], wk[4], wk[5]);
        }
    }

    /// Forward dynamics by the fast path (with `armature`) or by the scene's algorithm.
    fn accelerations(&mut self, q: &[f64], v: &[f64], armature: Option<&[f64]>, acc: &mut [f64]) {
        if self.fast.is_some() {
            self.kernel_accelerations(q, v, armature, acc);
            return;
        }
        if let Some(c) = &self.coupling {
            let Dynamics {
                mass_matrix,
                tau_minus_c,
            } = self.full_dynamics(q, v);
            acc.copy_from_slice(&c.forward_dynamics(self.offset(), &mass_matrix, &tau_minus_c));
            return;
        }
        let (p, loads) = (&self.params, &self.loads);
        match &self.base {
            Some(b) => {
                let st = floating_state(q, v);
                let alg = self.algorithm;
                let a = floating::forward_dynamics(alg, p, b, &st, &q[7..], &v[6..], loads);
                acc.copy_from_slice(&a);
            }
            None => acc.copy_from_slice(&self.algorithm.forward_dynamics(p, q, v, loads)),
        }
    }

    /// The speeds of the base that precede the joints' (6 free-floating, 0 fixed).
    fn offset(&self) -> usize {
        if self.base.is_some() {
            6
        } else {
            0
        }
    }

    /// The joint positions of the full joint list at the provider's joint positions `q` (without
    /// the base's): `G q + o` with mimic joints, else `q`.
    #[must_use]
    pub fn full_positions(&self, q: &[f64]) -> Vec<f64> {
        self.coupling
            .as_ref()
            .map_or_else(|| q.to_vec(), |c| c.full_positions(q))
    }

    /// The joint rates (or accelerations) of the full joint list: `G q̇` with mimic joints, else
    /// `q̇`.
    #[must_use]
    pub fn full_rates(&self, qd: &[f64]) -> Vec<f64> {
        self.coupling
            .as_ref()
            .map_or_else(|| qd.to_vec(), |c| c.full_rates(qd))
    }

    /// The joint positions and rates of the full joint list ([`Self::full_positions`],
    /// [`Self::full_rates`]).
    fn full_joints(&self, q: &[f64], qd: &[f64]) -> (Vec<f64>, Vec<f64>) {
        (self.full_positions(q), self.full_rates(qd))
    }

    /// `M_full` and `τ_full − c_full` of the full joint list at the provider's `q`, `v` (drives
    /// on the independent joints: the loads' `τ` is expanded), base first when free-floating.
    fn full_dynamics(&self, q: &[f64], v: &[f64]) -> Dynamics<f64> {
        let c = self.coupling.as_ref();
        let tau = self.loads.tau.as_deref();
        let loads = Loads {
            tau: tau.map(|t| c.map_or_else(|| t.to_vec(), |c| c.full_drives(t))),
            gravity: self.loads.gravity.clone(),
            external: self.loads.external.clone(),
        };
        let alg = self.algorithm;
        match &self.base {
            Some(b) => {
                let st = floating_state(q, v);
                let (qf, vf) = self.full_joints(&q[7..], &v[6..]);
                floating::dynamics(alg, &self.params, b, &st, &qf, &vf, &loads)
            }
            None => {
                let (qf, vf) = self.full_joints(q, v);
                alg.dynamics(&self.params, &qf, &vf, &loads)
            }
        }
    }

    /// The fast path: the run-time kernels ([`kernels::forward_dynamics`]).
    fn kernel_accelerations(
        &mut self,
        q: &[f64],
        v: &[f64],
        armature: Option<&[f64]>,
        acc: &mut [f64],
    ) {
        let Some((t, data)) = self.fast.as_mut() else {
            return;
        };
        let loads = &self.loads;
        match &self.base {
            Some(b) => {
                let st = floating_state(q, v);
                let fb = Some((b, &st));
                kernels::forward_dynamics(t, data, fb, &q[7..], &v[6..], loads, armature, acc);
            }
            None => kernels::forward_dynamics(t, data, None, q, v, loads, armature, acc),
        }
    }
}

/// The kernels' tables of `params` (gravity `g` as their `a₀`) and their scratch.
fn kernel_model(params: &Params<f64>, gravity: Option<[f64; 3]>) -> (KernelTables, KernelData) {
    let t = KernelTables::new(params, gravity);
    let data = KernelData::new(t.dof());
    (t, data)
}

impl SceneDynamics for RunTimeDynamics {
    fn forward(&mut self, q: &[f64], v: &[f64], tau: &[f64], w: &[f64], acc: &mut [f64]) {
        self.set_loads(Some(tau), w);
        self.accelerations(q, v, None, acc);
    }

    fn mass_matrix(&mut self, q: &[f64], m: &mut [f64]) {
        let a = match &self.base {
            Some(b) => {
                let st = floating_state(q, &[0.0; 6]);
                let qf = self.full_positions(&q[7..]);
                floating::mass_matrix(self.algorithm.mass_matrix, &self.params, b, &st, &qf)
            }
            None => {
                let qf = self.full_positions(q);
                self.algorithm.mass_matrix.mass_matrix(&self.params, &qf)
            }
        };
        match &self.coupling {
            Some(c) => copy_rows(&c.reduce_matrix(&a, self.offset()), m),
            None => copy_rows(&a, m),
        }
    }

    fn inverse(&mut self, q: &[f64], qd: &[f64], qdd: &[f64], w: &[f64], tau: &mut [f64]) {
        self.set_loads(None, w);
        let (qf, qdf) = self.full_joints(q, qd);
        let qddf = self.full_rates(qdd);
        let id = self
            .algorithm
            .inverse_dynamics(&self.params, &qf, &qdf, &qddf, &self.loads);
        match &self.coupling {
            Some(c) => tau.copy_from_slice(&c.reduce_vector(&id, 0)),
            None => tau.copy_from_slice(&id),
        }
    }

    /// The fast path takes the armature into the articulated-body algorithm (Pinocchio's
    /// `armature`); the LDLᵀ path adds it to the mass matrix ([`forward_with_armature`]).
    fn forward_armature(
        &mut self,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        w: &[f64],
        armature: &[f64],
        acc: &mut [f64],
        work: &mut [f64],
    ) {
        if self.fast.is_some() {
            self.set_loads(Some(tau), w);
            self.accelerations(q, v, Some(armature), acc);
        } else {
            forward_with_armature(self, q, v, tau, w, armature, acc, work);
        }
    }
}

/// Row-major copy of an `N × N` matrix.
fn copy_rows(src: &[Vec<f64>], dst: &mut [f64]) {
    for (row, d) in src.iter().zip(dst.chunks_exact_mut(src.len().max(1))) {
        d.copy_from_slice(row);
    }
}

/// The derivatives of the run-time algorithms (Carpentier & Mansard's, `kanegen-dynamics`), on
/// a fixed or free-floating base (mimic joints on a fixed one), and the frames of the wrenches'
/// bodies (what [`kanegen_runtime::scene::linearize`] takes external wrenches through).
impl SceneDerivatives for RunTimeDynamics {
    fn forward_derivatives(
        &mut self,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
        minv: &mut [f64],
    ) {
        if self.coupling.is_some() {
            self.set_loads(Some(tau), &[]);
        }
        let g = self.loads.gravity.as_ref();
        let (a, b, m) = match (&self.coupling, &self.base) {
            (None, Some(base)) => {
                let st = floating_state(q, v);
                let (qj, vj) = (&q[7..], &v[6..]);
                derivatives::aba::floating_derivatives(&self.params, base, &st, qj, vj, tau, g)
            }
            (Some(c), _) => {
                let (qf, vf) = self.full_joints(q, v);
                let d = self.full_dynamics(q, v);
                derivatives::coupled::forward_dynamics_derivatives(
                    c,
                    0,
                    &d.mass_matrix,
                    &d.tau_minus_c,
                    |qdd| derivatives::rnea::derivatives(&self.params, &qf, &vf, qdd, g),
                )
            }
            (None, None) => derivatives::aba::derivatives(&self.params, q, v, tau, g),
        };
        copy_rows(&a, dq);
        copy_rows(&b, dv);
        copy_rows(&m, minv);
    }

    fn gravity(&self) -> [f64; 3] {
        self.loads.gravity.as_ref().map_or([0.0; 3], |g| g.0)
    }

    fn inverse_derivatives(
        &mut self,
        q: &[f64],
        v: &[f64],
        qdd: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) {
        let g = self.loads.gravity.as_ref();
        if let (None, Some(base)) = (&self.coupling, &self.base) {
            let st = floating_state(q, v);
            let acc: [f64; 6] = core::array::from_fn(|k| qdd[k]);
            let (a, b) = derivatives::rnea::floating_derivatives(
                &self.params,
                base,
                &st,
                &q[7..],
                &v[6..],
                &acc,
                &qdd[6..],
                g,
            );
            copy_rows(&a, dq);
            return copy_rows(&b, dv);
        }
        let (qf, vf) = self.full_joints(q, v);
        let qddf = self.full_rates(qdd);
        let full = derivatives::rnea::derivatives(&self.params, &qf, &vf, &qddf, g);
        let (a, b) = match &self.coupling {
            Some(c) => derivatives::coupled::reduce_pair(c, 0, full),
            None => full,
        };
        copy_rows(&a, dq);
        copy_rows(&b, dv);
    }

    /// The frame algorithms at the body origin ([`frames::jacobian`], [`frames::placement`]) in
    /// base coordinates, the columns of a free-floating base's speeds before them (the base's own
    /// origin for a wrench on the base); NaN with mimic joints or for a wrench the scene does not
    /// have.
    fn wrench_body(&mut self, k: usize, q: &[f64], jac: &mut [f64]) -> WrenchBody {
        let (off, dof) = (self.offset(), self.params.dof());
        let nv = off + dof;
        let sizes = jac.len() == 6 * nv && q.len() == nv + usize::from(off > 0);
        let (Some(w), None, true) = (self.loads.external.get(k), &self.coupling, sizes) else {
            jac.fill(f64::NAN);
            return WrenchBody {
                rotation: [[f64::NAN; 3]; 3],
                body_fixed: false,
            };
        };
        let qj = &q[q.len() - dof..];
        jac.fill(0.0);
        let (x, r) = if w.body == BASE_BODY {
            (Vec3::zero(), Mat3::identity())
        } else {
            let origin = FrameParams {
                parent: Some(w.body),
                translation: Vec3::zero(),
                rotation: Mat3::identity(),
            };
            let j = frames::jacobian(&self.params, qj, &origin);
            for (row, d) in j.iter().zip(jac.chunks_exact_mut(nv)) {
                d[off..].copy_from_slice(row);
            }
            frames::placement(&self.params, qj, &origin)
        };
        if off > 0 {
            // v_b,m moves the origin by e_m; ω_b,m by e_m × x and turns it about e_m.
            for m in 0..3 {
                jac[m * nv + m] = 1.0;
                jac[(3 + m) * nv + 3 + m] = 1.0;
                let mut e = Vec3::zero();
                e.0[m] = 1.0;
                let ex = e.cross(&x);
                for i in 0..3 {
                    jac[i * nv + 3 + m] = ex.at(i);
                }
            }
        }
        WrenchBody {
            rotation: core::array::from_fn(|i| core::array::from_fn(|c| r.at(i, c))),
            body_fixed: w.frame == LoadFrame::Body,
        }
    }
}
