//! The one entry point that traces a function of a model's dynamics: Table 1, `kanegen count`,
//! the code generator and the accuracy report all call [`trace`].
//!
//! ```
//! use kanegen_dynamics::Methods;
//! use kanegen_model::random::{random_chain, ChainSpec};
//! use kanegen_trace::{trace, Convention, Function, Spec, Subject};
//! let model = random_chain(&ChainSpec { n: 3, ..Default::default() }, 1);
//! let t = trace(Subject::Model(&model), Function::MassMatrix, Methods::SPATIAL, &Spec::default())
//!     .unwrap();
//! assert_eq!(t.trace.outputs().len(), 6); // the upper triangle of a 3×3 matrix
//! assert!(t.trace.counts(Convention::Emitted).total() > 0);
//! // M q̈ + c = τ: inverse dynamics at q̈ = 0 is c.
//! let id = trace(Subject::Model(&model), Function::InverseDynamics, Methods::SPATIAL,
//!     &Spec::default()).unwrap();
//! let c = trace(Subject::Model(&model), Function::NonlinearEffects, Methods::SPATIAL,
//!     &Spec::default()).unwrap();
//! let (q, qd) = ([0.1, 0.2, 0.3], [0.4, -0.5, 0.6]);
//! let x = id.trace.eval(&[q, qd, [0.0; 3]].concat());
//! let y = c.trace.eval(&[q, qd].concat());
//! assert!(x.iter().zip(&y).all(|(a, b)| (a - b).abs() < 1e-12));
//! ```

use crate::coupled::{self, upper};
use crate::function::{Arg, Function, Input, PayloadField};
use crate::spec::{Base, Spec, Subject, WrenchValue};
use crate::sym::{Sym, Trace, Tracer};
use kanegen_dynamics::algorithms::derivatives::{
    aba as fd_derivatives, coupled as coupled_derivatives, minverse, rnea as id_derivatives,
};
use kanegen_dynamics::algorithms::kinematics::BodyKinematics;
use kanegen_dynamics::algorithms::{floating, frames, newton_euler, recurrent, rnea};
use kanegen_dynamics::base::{
    quat_to_matrix, FloatingBase, FloatingState, BASE_BODY, FLOATING_BASE_DOF,
};
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::mimic::Coupling;
use kanegen_dynamics::params::{axis_turn, is_near_signed_permutation};
use kanegen_dynamics::regroup::regrouped;
use kanegen_dynamics::spatial::RbInertia;
use kanegen_dynamics::{
    ExternalWrench, ForwardMethod, JointParams, LoadFrame, Loads, MassMatrixMethod, Methods,
    NonlinearEffectsMethod, Params, Scalar,
};
use kanegen_model::JointKind;
use std::collections::HashMap;

/// A traced function: the frozen graph and, per input in creation order, what it reads.
#[derive(Debug)]
pub struct Traced {
    /// The graph; its outputs are the function's results (a symmetric matrix as its upper
    /// triangle, row-major).
    pub trace: Trace,
    /// `inputs[i]` is the runtime input `i` of [`Trace::eval`] and of the graph's `Input` nodes.
    pub inputs: Vec<Input>,
}

/// A request [`trace`] cannot honour.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("cannot trace {function} ({methods}): {reason}")]
pub struct TraceError {
    /// The function asked for.
    pub function: &'static str,
    /// The methods asked for.
    pub methods: String,
    /// Why not.
    pub reason: String,
}

/// Traces `function` of `subject` under `methods` with the effects of `spec`.
///
/// Inputs are created in this order: the payload (with [`Spec::runtime_payload`]: mass, centre
/// of mass, the inertia's upper triangle) or the generic parameters, then the function's
/// arguments ([`Function::args`]; a free-floating base's state is part of `q` and `v`, in
/// Pinocchio's free-flyer layout), then the runtime wrenches. Only the effects `spec` names are
/// traced.
///
/// # Errors
/// A combination that makes no sense: gravity's term without gravity, an inertial-frame subject with
/// a local-frame method or with effects, the paper's (14b) bookkeeping outside Table 1's setting,
/// a runtime payload without a model, a wrench on a body that does not exist, or a function not
/// (yet) traced for a free-floating base.
pub fn trace(
    subject: Subject,
    function: Function,
    methods: Methods,
    spec: &Spec,
) -> Result<Traced, TraceError> {
    check(&subject, function, methods, spec).map_err(|reason| TraceError {
        function: function.name(),
        methods: methods.name(),
        reason,
    })?;
    let n = subject.dof();
    let t = Tracer::new();
    let mut inputs: Vec<Input> = Vec::new();
    let mut input = |i: Input| {
        let s = t.input(i.to_string());
        inputs.push(i);
        s
    };
    let (params, regrouped_base) = parameters(subject, spec, &mut input);
    let Some(p) = params else {
        let out = inertial_frame_mass_matrix(n, methods, spec, &mut input);
        return Ok(Traced {
            trace: t.finish(&out),
            inputs,
        });
    };
    let floating = matches!(spec.base, Base::FreeFloating(_));
    let coupling = match subject {
        Subject::Model(m) if m.has_mimics() => Some(Coupling::new(m.mimics())),
        _ => None,
    };
    let args = Arguments::new(function, n, floating, coupling.as_ref(), &mut input);
    // Damping per independent coordinate acts at its joint of the full tree (none on mimic joints).
    let damping = spec.damping.as_ref().map(|d| match &coupling {
        Some(c) => c.full_drives(d),
        None => d.clone(),
    });
    let effects = Effects::new(spec, damping.as_deref(), &args, floating, &mut input);
    let base = match (&spec.base, &args.state) {
        (Base::FreeFloating(inertial), Some(state)) => Some((
            regrouped_base.unwrap_or_else(|| FloatingBase::<Sym>::from_inertial(inertial)),
            state,
        )),
        _ => None,
    };
    let system = match &base {
        Some((base, state)) => System::Floating(FloatingSystem { p: &p, base, state }),
        None => System::Fixed(&p),
    };
    let out = match &coupling {
        Some(c) => coupled_outputs(function, methods, c, &system, &args, &effects),
        None => system.outputs(function, methods, &args, &effects),
    };
    Ok(Traced {
        trace: t.finish(&out),
        inputs,
    })
}

/// The subject's parameters (`None` for an inertial-frame subject, whose inputs are the paper's
/// kinematic quantities), and the free-floating base the regrouping hands back (`None` when it
/// does not run or the base is fixed). A runtime payload's inputs are created here.
fn parameters(
    subject: Subject,
    spec: &Spec,
    input: &mut impl FnMut(Input) -> Sym,
) -> (Option<Params<Sym>>, Option<FloatingBase<Sym>>) {
    let model = match subject {
        Subject::Model(model) => model,
        Subject::Generic { n } => return (Some(generic_params(n, input)), None),
        Subject::InertialFrame { .. } => return (None, None),
    };
    let mut regrouped_base = None;
    let mut p = if spec.regroup {
        let base = match &spec.base {
            Base::FreeFloating(i) => Some(i),
            Base::Fixed => None,
        };
        let keep: &[usize] = if spec.runtime_payload {
            &[model.dof() - 1]
        } else {
            &[]
        };
        let r = regrouped::<Sym>(model, base, keep);
        regrouped_base = r.base;
        r.params
    } else {
        Params::<Sym>::new(model)
    };
    if spec.two_step_placement > 0.0 {
        for (jp, j) in p.joints.iter_mut().zip(model.joints()) {
            jp.placement_permutation = jp.placement_permutation
                || is_near_signed_permutation(&j.origin.rotation, spec.two_step_placement)
                || axis_turn(&j.origin.rotation).is_some();
            jp.split_placement(j);
        }
    }
    if spec.runtime_payload {
        payload_inputs(&mut p, input);
    }
    (Some(p), regrouped_base)
}

/// Table 1's subject: the mass matrix (upper triangle) of `n` bodies from the paper's
/// inertial-frame inputs, by `methods.mass_matrix` or, with [`Spec::paper_14b`], by the paper's
/// printed (14b).
fn inertial_frame_mass_matrix(
    n: usize,
    methods: Methods,
    spec: &Spec,
    input: &mut impl FnMut(Input) -> Sym,
) -> Vec<Sym> {
    let kin = inertial_frame_inputs(n, input);
    let a = if spec.paper_14b {
        recurrent::mass_matrix_paper_bookkeeping(&kin)
    } else {
        methods
            .mass_matrix
            .from_inertial_frame(&kin)
            .expect("the CRBA is rejected by check")
    };
    upper(&a)
}

/// The function's arguments as inputs: the joint parts `q`, `q̇`, `q̈` (`q̇` zero when not an
/// argument), a free-floating base's state from `q[..7]`, `v[..6]`, and the rows of `f_ext`.
struct Arguments {
    /// Every argument but `f_ext`, whole.
    args: HashMap<Arg, Vec<Sym>>,
    /// `f_ext`: one body-frame wrench per body (free-floating: the base first).
    rows: Vec<[Sym; 6]>,
    /// `N` zeros.
    zeros: Vec<Sym>,
    q: Vec<Sym>,
    qd: Vec<Sym>,
    qdd: Option<Vec<Sym>>,
    state: Option<FloatingState<Sym>>,
}

impl Arguments {
    /// Creates the inputs of `function`'s arguments ([`Function::args`]), in order, for `n`
    /// joints (one `f_ext` row per body); with mimic joints (`coupling`) the joint arguments
    /// are the independent coordinates, expanded to the `n` joints ([`crate::coupled`]).
    fn new(
        function: Function,
        n: usize,
        floating: bool,
        coupling: Option<&Coupling>,
        input: &mut impl FnMut(Input) -> Sym,
    ) -> Self {
        let mut args: HashMap<Arg, Vec<Sym>> = HashMap::new();
        let mut rows: Vec<[Sym; 6]> = Vec::new();
        let coords = coupling.map_or(n, Coupling::reduced);
        for &a in function.args(floating) {
            if a == Arg::FExt {
                rows = (0..a.len(n, floating))
                    .map(|r| core::array::from_fn(|c| input(Input::Row(a, r, c))))
                    .collect();
            } else {
                let v = (0..a.len(coords, floating))
                    .map(|i| input(Input::Joint(a, i)))
                    .collect();
                args.insert(a, v);
            }
        }
        if let Some(c) = coupling {
            expand(&mut args, c, floating);
        }
        let arg = |a: Arg| args.get(&a).cloned();
        let zeros = vec![Sym::zero(); n];
        let full_q = arg(Arg::Q).expect("every function takes q");
        let (q, qd, qdd, state) = if floating {
            let v = arg(Arg::V);
            let a = arg(Arg::A);
            let v3 = |x: &[Sym], k: usize| Vec3([x[k], x[k + 1], x[k + 2]]);
            let state = FloatingState {
                position: v3(&full_q, 0),
                rotation: quat_to_matrix(&[full_q[3], full_q[4], full_q[5], full_q[6]]),
                v_b: v.as_ref().map_or_else(Vec3::zero, |v| v3(v, 0)),
                omega_b: v.as_ref().map_or_else(Vec3::zero, |v| v3(v, 3)),
            };
            let joints = |x: Option<Vec<Sym>>, skip| x.map(|x| x[skip..].to_vec());
            (
                full_q[7..].to_vec(),
                joints(v, 6).unwrap_or_else(|| zeros.clone()),
                a,
                Some(state),
            )
        } else {
            (
                full_q,
                arg(Arg::Qd).unwrap_or_else(|| zeros.clone()),
                arg(Arg::Qdd),
                None,
            )
        };
        Arguments {
            args,
            rows,
            zeros,
            q,
            qd,
            qdd,
            state,
        }
    }

    /// Argument `a`, whole (`None` when the function does not take it).
    fn arg(&self, a: Arg) -> Option<Vec<Sym>> {
        self.args.get(&a).cloned()
    }
}

/// The arguments in the independent coordinates of `c` expanded to the full joint list: the
/// joint parts of `q` (`G q + o`), of the rates and accelerations (`G x`), and the drives (the
/// independent joints', zero on mimic joints); a free-floating base's parts kept.
fn expand(args: &mut HashMap<Arg, Vec<Sym>>, c: &Coupling, floating: bool) {
    for (a, v) in args.iter_mut() {
        let head = match (a, floating) {
            (Arg::Q, true) => 7,
            (Arg::V | Arg::A, true) => FLOATING_BASE_DOF,
            _ => 0,
        };
        let (base, joints) = v.split_at(head.min(v.len()));
        let joints = match a {
            Arg::Q => c.full_positions(joints),
            Arg::Tau => c.full_drives(joints),
            Arg::Qd | Arg::Qdd | Arg::V | Arg::A => c.full_rates(joints),
            Arg::FExt => continue,
        };
        *v = [base, &joints].concat();
    }
}

/// The spec's effects on the traced system: the external wrenches (the spec's, then `f_ext`'s
/// rows), gravity and the damping drive `τ_d = −d q̇`.
struct Effects {
    external: Vec<ExternalWrench<Sym>>,
    gravity: Option<Vec3<Sym>>,
    damping: Option<Vec<Sym>>,
}

impl Effects {
    /// Creates the runtime wrenches' inputs (after the arguments'); `damping` per joint of the
    /// traced tree.
    fn new(
        spec: &Spec,
        damping: Option<&[f64]>,
        args: &Arguments,
        floating: bool,
        input: &mut impl FnMut(Input) -> Sym,
    ) -> Self {
        let mut external: Vec<ExternalWrench<Sym>> = spec
            .wrenches
            .iter()
            .enumerate()
            .map(|(index, w)| {
                let (force, moment) = match &w.value {
                    WrenchValue::Constant { force, moment } => {
                        (Vec3::from_f64(*force), Vec3::from_f64(*moment))
                    }
                    WrenchValue::Runtime => {
                        let mut c = |k: usize| {
                            input(Input::Wrench {
                                index,
                                component: k,
                            })
                        };
                        (Vec3::new(c(0), c(1), c(2)), Vec3::new(c(3), c(4), c(5)))
                    }
                };
                ExternalWrench {
                    body: w.body,
                    frame: w.frame,
                    force,
                    moment,
                }
            })
            .collect();
        external.extend(args.rows.iter().enumerate().map(|(r, w)| ExternalWrench {
            body: match (floating, r) {
                (true, 0) => BASE_BODY,
                (true, r) => r - 1,
                (false, r) => r,
            },
            frame: LoadFrame::Body,
            force: Vec3([w[0], w[1], w[2]]),
            moment: Vec3([w[3], w[4], w[5]]),
        }));
        let gravity = spec.gravity.map(Vec3::from_f64);
        let damping: Option<Vec<Sym>> = damping.map(|d| {
            d.iter()
                .zip(&args.qd)
                .map(|(di, qdi)| Sym::constant(*di) * *qdi)
                .collect()
        });
        Effects {
            external,
            gravity,
            damping,
        }
    }

    /// The joint drives: `tau` minus the damping force.
    fn drives(&self, tau: Option<Vec<Sym>>) -> Option<Vec<Sym>> {
        match (tau, &self.damping) {
            (Some(t), Some(d)) => Some(t.iter().zip(d).map(|(t, d)| *t - *d).collect()),
            (Some(t), None) => Some(t),
            (None, Some(d)) => Some(d.iter().map(|d| -*d).collect()),
            (None, None) => None,
        }
    }

    /// Every load, with the drives `tau`.
    fn loads(&self, tau: Option<Vec<Sym>>) -> Loads<Sym> {
        Loads {
            tau: self.drives(tau),
            gravity: self.gravity.clone(),
            external: self.external.clone(),
        }
    }

    /// Gravity alone.
    fn gravity_only(&self) -> Loads<Sym> {
        Loads {
            tau: None,
            gravity: self.gravity.clone(),
            external: Vec::new(),
        }
    }
}

/// The arm's parameters on its free-floating base, in the traced state.
struct FloatingSystem<'a> {
    p: &'a Params<Sym>,
    base: &'a FloatingBase<Sym>,
    state: &'a FloatingState<Sym>,
}

/// The traced system: an arm on a fixed base, or on its free-floating base.
enum System<'a> {
    Fixed(&'a Params<Sym>),
    Floating(FloatingSystem<'a>),
}

impl System<'_> {
    /// The speeds of the base (6 free-floating, 0 fixed).
    fn base_speeds(&self) -> usize {
        match self {
            System::Fixed(_) => 0,
            System::Floating(_) => FLOATING_BASE_DOF,
        }
    }

    /// The outputs of `function` (on the full joint list).
    fn outputs(
        &self,
        function: Function,
        methods: Methods,
        args: &Arguments,
        effects: &Effects,
    ) -> Vec<Sym> {
        match self {
            System::Fixed(p) => fixed_outputs(function, methods, p, args, effects),
            System::Floating(s) => floating_outputs(function, methods, s, args, effects),
        }
    }

    /// The full mass matrix by `method`.
    fn mass_matrix(&self, method: MassMatrixMethod, q: &[Sym]) -> Vec<Vec<Sym>> {
        match self {
            System::Fixed(p) => method.mass_matrix(p, q),
            System::Floating(s) => floating::mass_matrix(method, s.p, s.base, s.state, q),
        }
    }

    /// `τ − c` under `loads` by `method`.
    fn tau_minus_c(
        &self,
        method: NonlinearEffectsMethod,
        args: &Arguments,
        loads: &Loads<Sym>,
    ) -> Vec<Sym> {
        let (q, qd) = (&args.q, &args.qd);
        match self {
            System::Fixed(p) => method.tau_minus_c(p, q, qd, loads),
            System::Floating(s) => {
                floating::tau_minus_c(method, s.p, s.base, s.state, q, qd, loads)
            }
        }
    }

    /// `(∂τ/∂q, ∂τ/∂q̇)` at the accelerations `acc` (`[a_b; q̈]` on a free-floating base).
    fn id_derivatives(
        &self,
        args: &Arguments,
        acc: &[Sym],
        gravity: Option<&Vec3<Sym>>,
    ) -> (Vec<Vec<Sym>>, Vec<Vec<Sym>>) {
        let (q, qd) = (&args.q, &args.qd);
        match self {
            System::Fixed(p) => id_derivatives::derivatives(p, q, qd, acc, gravity),
            System::Floating(s) => {
                let base_acc: [Sym; 6] = core::array::from_fn(|k| acc[k]);
                id_derivatives::floating_derivatives(
                    s.p,
                    s.base,
                    s.state,
                    q,
                    qd,
                    &base_acc,
                    &acc[6..],
                    gravity,
                )
            }
        }
    }
}

/// The outputs of `function` in the independent coordinates of mimic joints `c`
/// ([`crate::coupled`]): forward dynamics, its derivatives and `M⁻¹` from the reduced `M`; every
/// other function traced on the full joint list and reduced after.
fn coupled_outputs(
    function: Function,
    methods: Methods,
    c: &Coupling,
    system: &System,
    args: &Arguments,
    effects: &Effects,
) -> Vec<Sym> {
    let offset = system.base_speeds();
    let m_full = || system.mass_matrix(methods.mass_matrix, &args.q);
    let b_full = || {
        let loads = effects.loads(args.arg(Arg::Tau));
        system.tau_minus_c(methods.nonlinear_effects, args, &loads)
    };
    match function {
        f if f.is_forward_dynamics() => coupled::forward_dynamics(c, offset, &m_full(), &b_full()),
        Function::MassMatrixInverse => upper(&coupled_derivatives::mass_matrix_inverse(
            c,
            offset,
            &m_full(),
        )),
        Function::ForwardDynamicsDerivatives => {
            let g = effects.gravity.as_ref();
            let (dq, dv, minv) = coupled_derivatives::forward_dynamics_derivatives(
                c,
                offset,
                &m_full(),
                &b_full(),
                |acc| system.id_derivatives(args, acc, g),
            );
            [dq, dv, minv].concat().concat()
        }
        _ => coupled::reduce(
            function,
            c,
            offset,
            system.outputs(function, methods, args, effects),
        ),
    }
}

/// The outputs of `function` on a free-floating base.
fn floating_outputs(
    function: Function,
    methods: Methods,
    system: &FloatingSystem,
    args: &Arguments,
    effects: &Effects,
) -> Vec<Sym> {
    let FloatingSystem { p, base, state } = *system;
    let (q, qd) = (&args.q, &args.qd);
    let loads = |tau| effects.loads(tau);
    let m = |method| floating::mass_matrix(method, p, base, state, q);
    let b = |qd: &[Sym], l: &Loads<Sym>| {
        floating::tau_minus_c(methods.nonlinear_effects, p, base, state, q, qd, l)
    };
    let fd = |l: &Loads<Sym>| floating::forward_dynamics(methods, p, base, state, q, qd, l);
    match function {
        Function::MassMatrix => upper(&m(methods.mass_matrix)),
        Function::GeneralizedForces => b(qd, &loads(args.arg(Arg::Tau))),
        Function::NonlinearEffects => negated(b(qd, &loads(None))),
        Function::Gravity => {
            let rest = FloatingState {
                v_b: Vec3::zero(),
                omega_b: Vec3::zero(),
                ..state.clone()
            };
            negated(floating::tau_minus_c(
                methods.nonlinear_effects,
                p,
                base,
                &rest,
                q,
                &args.zeros,
                &effects.gravity_only(),
            ))
        }
        Function::ForwardDynamics | Function::ForwardDynamicsWithWrenches => {
            fd(&loads(args.arg(Arg::Tau)))
        }
        Function::MassMatrixAndNonlinearEffects => {
            let mut v = upper(&m(methods.mass_matrix));
            v.extend(negated(b(qd, &loads(None))));
            v
        }
        Function::Momentum => {
            let (lin, ang) = floating::momentum(p, base, state, q, qd);
            lin.0.into_iter().chain(ang.0).collect()
        }
        Function::InverseDynamics | Function::BaseReaction => {
            floating_inverse_dynamics(function, methods, system, args, effects)
        }
        Function::FramePlacement(k) => {
            let (x, r) = frames::floating_placement(p, state, q, &p.frames[k]);
            placement_outputs(x, r)
        }
        Function::FrameJacobian(k) => frames::floating_jacobian(p, state, q, &p.frames[k]).concat(),
        Function::GeneralizedJacobian(k) => {
            frames::generalized_jacobian(p, base, state, q, &p.frames[k]).concat()
        }
        Function::InverseDynamicsDerivatives => {
            let a = args.qdd.as_ref().expect("takes a");
            let base_acc: [Sym; 6] = core::array::from_fn(|k| a[k]);
            let g = effects.gravity.as_ref();
            let (dq, dv) =
                id_derivatives::floating_derivatives(p, base, state, q, qd, &base_acc, &a[6..], g);
            [dq, dv].concat().concat()
        }
        Function::ForwardDynamicsDerivatives => {
            let tau = args.arg(Arg::Tau).expect("takes tau");
            let g = effects.gravity.as_ref();
            let (dq, dv, minv) =
                fd_derivatives::floating_derivatives(p, base, state, q, qd, &tau, g);
            [dq, dv, minv].concat().concat()
        }
        Function::MassMatrixInverse => upper(&minverse::floating_mass_matrix_inverse(p, base, q)),
    }
}

/// Inverse dynamics on a free-floating base (`τ` with the base's wrench first, damping inside
/// `c`), or the arm's reaction on its base, from the accelerations `a = [a_b; q̈]`.
fn floating_inverse_dynamics(
    function: Function,
    methods: Methods,
    system: &FloatingSystem,
    args: &Arguments,
    effects: &Effects,
) -> Vec<Sym> {
    let FloatingSystem { p, base, state } = *system;
    let (q, qd) = (&args.q, &args.qd);
    let a = args.qdd.as_ref().expect("takes a");
    let base_acc: [Sym; 6] = core::array::from_fn(|k| a[k]);
    let joints = &a[6..];
    if function == Function::BaseReaction {
        return rnea::base_reaction(p, state, q, qd, &base_acc, joints, &effects.loads(None))
            .to_vec();
    }
    let id = if methods.nonlinear_effects == NonlinearEffectsMethod::NewtonEuler {
        newton_euler::floating_inverse_dynamics
    } else {
        rnea::floating_inverse_dynamics
    };
    let mut tau = id(
        p,
        base,
        state,
        q,
        qd,
        &base_acc,
        joints,
        &effects.loads(None),
    );
    if let Some(d) = &effects.damping {
        for (t, d) in tau[6..].iter_mut().zip(d) {
            *t = *t + *d;
        }
    }
    tau
}

/// The outputs of `function` on a fixed base.
fn fixed_outputs(
    function: Function,
    methods: Methods,
    p: &Params<Sym>,
    args: &Arguments,
    effects: &Effects,
) -> Vec<Sym> {
    let (q, qd) = (&args.q, &args.qd);
    let loads = |tau| effects.loads(tau);
    let tau_minus_c =
        |qd: &[Sym], l: &Loads<Sym>| methods.nonlinear_effects.tau_minus_c(p, q, qd, l);
    match function {
        Function::MassMatrix => upper(&methods.mass_matrix.mass_matrix(p, q)),
        Function::GeneralizedForces => tau_minus_c(qd, &loads(args.arg(Arg::Tau))),
        Function::NonlinearEffects => negated(tau_minus_c(qd, &loads(None))),
        Function::Gravity => negated(tau_minus_c(&args.zeros, &effects.gravity_only())),
        Function::InverseDynamics => {
            let qdd = args.qdd.as_ref().expect("inverse dynamics takes q̈");
            let tau = methods.inverse_dynamics(p, q, qd, qdd, &loads(None));
            match &effects.damping {
                // τ = M q̈ + c with the damping force d q̇ inside c.
                Some(d) => tau.iter().zip(d).map(|(t, d)| *t + *d).collect(),
                None => tau,
            }
        }
        Function::ForwardDynamics | Function::ForwardDynamicsWithWrenches => {
            methods.forward_dynamics(p, q, qd, &loads(args.arg(Arg::Tau)))
        }
        Function::MassMatrixAndNonlinearEffects => {
            let mut v = upper(&methods.mass_matrix.mass_matrix(p, q));
            v.extend(negated(tau_minus_c(qd, &loads(None))));
            v
        }
        Function::FramePlacement(k) => {
            let (x, r) = frames::placement(p, q, &p.frames[k]);
            placement_outputs(x, r)
        }
        Function::FrameJacobian(k) => frames::jacobian(p, q, &p.frames[k]).concat(),
        Function::InverseDynamicsDerivatives => {
            let qdd = args.qdd.as_ref().expect("takes q̈");
            let (dq, dv) = id_derivatives::derivatives(p, q, qd, qdd, effects.gravity.as_ref());
            [dq, dv].concat().concat()
        }
        Function::ForwardDynamicsDerivatives => {
            let tau = args.arg(Arg::Tau).expect("takes tau");
            let (dq, dv, minv) =
                fd_derivatives::derivatives(p, q, qd, &tau, effects.gravity.as_ref());
            [dq, dv, minv].concat().concat()
        }
        Function::MassMatrixInverse => upper(&minverse::mass_matrix_inverse(p, q)),
        Function::Momentum | Function::BaseReaction | Function::GeneralizedJacobian(_) => {
            unreachable!("rejected by check: free-floating only")
        }
    }
}

fn check(
    subject: &Subject,
    function: Function,
    methods: Methods,
    spec: &Spec,
) -> Result<(), String> {
    let n = subject.dof();
    if n == 0 {
        return Err("the model has no joint".into());
    }
    if function == Function::Gravity && spec.gravity.is_none() {
        return Err("the gravity term needs gravity".into());
    }
    if spec.paper_14b
        && !(matches!(subject, Subject::InertialFrame { .. })
            && methods.mass_matrix == MassMatrixMethod::RecurrentR1
            && function == Function::MassMatrix)
    {
        return Err(
            "the printed (14b) (inexact for N ≥ 3) is traced only as Table 1 counts it: the \
             recurrent-r1 mass matrix from inertial-frame inputs"
                .into(),
        );
    }
    let effects = spec.gravity.is_some()
        || !spec.wrenches.is_empty()
        || spec.damping.is_some()
        || spec.runtime_payload
        || spec.base != Base::Fixed;
    match subject {
        Subject::InertialFrame { .. } => {
            if function != Function::MassMatrix {
                return Err("an inertial-frame subject has only the mass matrix".into());
            }
            if methods.mass_matrix == MassMatrixMethod::Crba {
                return Err(
                    "the local-frame CRBA does not start from inertial-frame inputs".into(),
                );
            }
            if effects {
                return Err("an inertial-frame subject takes no effects".into());
            }
        }
        Subject::Generic { .. } if effects => {
            return Err("a generic subject takes no effects (fixed base, no loads)".into());
        }
        _ => {}
    }
    if spec.regroup {
        if !matches!(subject, Subject::Model(_)) {
            return Err("regrouped inertial parameters need a model's numbers".into());
        }
        if function == Function::BaseReaction {
            return Err(
                "the arm's reaction on its base changes under regrouping (a per-body wrench)"
                    .into(),
            );
        }
    }
    if let Some(d) = &spec.damping {
        // One entry per independent coordinate (the joints, or fewer with mimic joints).
        let coordinates = match subject {
            Subject::Model(m) => m.coordinate_count(),
            _ => n,
        };
        if d.len() != coordinates {
            return Err(format!(
                "damping has {} entries for {coordinates} coordinates",
                d.len()
            ));
        }
    }
    let floating = matches!(spec.base, Base::FreeFloating(_));
    for (i, w) in spec.wrenches.iter().enumerate() {
        if !(w.body < n || (floating && w.body == BASE_BODY)) {
            return Err(format!("wrench[{i}] acts on body {} of {n}", w.body));
        }
    }
    if function.is_derivative() && (spec.damping.is_some() || !spec.wrenches.is_empty()) {
        return Err(
            "the derivatives take gravity and a runtime payload, not wrenches or damping".into(),
        );
    }
    if function.floating_only() && !floating {
        return Err(format!("{} needs a free-floating base", function.name()));
    }
    if let Some(k) = function.frame() {
        match subject {
            Subject::Model(m) if k < m.frames().len() => {}
            _ => return Err(format!("the model has no frame #{k}")),
        }
    }
    if let Subject::Model(m) = subject {
        if m.has_mimics() {
            check_mimic(function, methods)?;
        }
        // The paper's inertial-frame algorithms handle serial chains only.
        let p = Params::<f64>::new(m);
        let uses = |b: bool| b || floating;
        if uses(function.uses_mass_matrix()) {
            methods.mass_matrix.check(&p).map_err(|e| e.to_string())?;
        }
        if uses(function.uses_nonlinear_effects()) {
            methods
                .nonlinear_effects
                .check(&p)
                .map_err(|e| e.to_string())?;
        }
    }
    let _ = NonlinearEffectsMethod::ALL; // every nonlinear-effects method traces every remaining combination
    Ok(())
}

/// What a model with mimic joints is not traced with ([`crate::coupled`]): forward dynamics by
/// the articulated-body algorithm (it runs on the full tree; the coupled forward dynamics solve
/// the reduced `M` by LDLᵀ).
fn check_mimic(function: Function, methods: Methods) -> Result<(), String> {
    if function.is_forward_dynamics() && methods.forward == ForwardMethod::Aba {
        return Err(
            "the articulated-body algorithm does not run in the independent coordinates of mimic \
             joints (forward dynamics solves the reduced M by LDLᵀ)"
                .into(),
        );
    }
    Ok(())
}

/// A placement as outputs: the origin, then the rotation row by row.
fn placement_outputs(x: Vec3<Sym>, r: Mat3<Sym>) -> Vec<Sym> {
    x.0.into_iter().chain(r.0.into_iter().flatten()).collect()
}

fn negated(v: Vec<Sym>) -> Vec<Sym> {
    v.into_iter().map(|x| -x).collect()
}

/// The last body's mass properties as inputs: mass, centre of mass, the inertia's upper triangle
/// (mirrored: the tensor is symmetric).
#[allow(clippy::needless_range_loop)] // the symmetric fill reads best with indices
fn payload_inputs(p: &mut Params<Sym>, input: &mut impl FnMut(Input) -> Sym) {
    let last = p.joints.last_mut().expect("a model has at least one joint");
    let mass = input(Input::Payload(PayloadField::Mass));
    let com = Vec3(core::array::from_fn(|k| {
        input(Input::Payload(PayloadField::Com(k)))
    }));
    let mut i = [[Sym::zero(); 3]; 3];
    for r in 0..3 {
        for c in r..3 {
            let s = input(Input::Payload(PayloadField::Inertia(r, c)));
            i[r][c] = s;
            i[c][r] = s;
        }
    }
    last.set_inertial(mass, com, Mat3(i));
}

/// Three inputs named `{name}x`, `{name}y`, `{name}z`.
fn vec_input(input: &mut impl FnMut(Input) -> Sym, name: &str) -> Vec3<Sym> {
    Vec3::new(
        input(Input::Parameter(format!("{name}x"))),
        input(Input::Parameter(format!("{name}y"))),
        input(Input::Parameter(format!("{name}z"))),
    )
}

/// A symmetric tensor's six inputs `{name}xx, yy, zz, xy, xz, yz`.
fn sym3_input(input: &mut impl FnMut(Input) -> Sym, name: &str) -> Mat3<Sym> {
    let mut i = |s: &str| input(Input::Parameter(format!("{name}{s}")));
    let (xx, yy, zz, xy, xz, yz) = (i("xx"), i("yy"), i("zz"), i("xy"), i("xz"), i("yz"));
    Mat3([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
}

/// `n` revolute joints whose every parameter is an input (inertia tensors symmetric).
fn generic_params(n: usize, input: &mut impl FnMut(Input) -> Sym) -> Params<Sym> {
    let joints = (0..n)
        .map(|j| {
            let l = vec_input(input, &format!("l{j}_"));
            let upsilon = Mat3(core::array::from_fn(|r| {
                core::array::from_fn(|c| input(Input::Parameter(format!("U{j}_{r}{c}"))))
            }));
            let axis = vec_input(input, &format!("u{j}_"));
            let mass = input(Input::Parameter(format!("m{j}")));
            let com = vec_input(input, &format!("d{j}_"));
            let inertia_com = sym3_input(input, &format!("Ic{j}_"));
            JointParams {
                inertia: RbInertia::from_com(&mass, &com, &inertia_com),
                kind: JointKind::Revolute,
                parent: j.checked_sub(1),
                l,
                upsilon,
                axis,
                coordinate_axis: None,
                placement_permutation: false,
                placement_turn: None,
                angle_offset: None,
                mass,
                com,
                inertia_com,
            }
        })
        .collect();
    Params {
        joints,
        frames: Vec::new(),
    }
}

/// `n` revolute bodies' inertial-frame quantities of eq. (1), (2), (6) as inputs (general geometry
/// and inertia; inertia tensors symmetric).
fn inertial_frame_inputs(
    n: usize,
    input: &mut impl FnMut(Input) -> Sym,
) -> Vec<BodyKinematics<Sym>> {
    (0..n)
        .map(|j| {
            let r = vec_input(input, &format!("r{j}_"));
            let axis = vec_input(input, &format!("a{j}_"));
            let m = input(Input::Parameter(format!("m{j}")));
            let c = vec_input(input, &format!("c{j}_"));
            let inertia = sym3_input(input, &format!("I{j}_"));
            BodyKinematics {
                kind: JointKind::Revolute,
                orientation: Mat3::identity(),
                r,
                axis,
                m,
                c,
                inertia,
            }
        })
        .collect()
}
