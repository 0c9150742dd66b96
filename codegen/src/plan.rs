//! What one generation emits, decided once from `(model, options)` before anything is emitted:
//! the model actually traced (on the asked base, float noise snapped), its canonical frames and
//! regrouping, the form (unrolled or compact, and why), and per function its name, arguments,
//! result shape, and either the chosen unrolled candidate (with its traced graph) or the compact
//! kernel. The emitters ([`crate::emit`], [`crate::compact`], [`crate::header`], the items of
//! [`crate::generate_items`]) read the plan; only the graphs are handed over separately, to be
//! consumed one at a time as their bodies are emitted.
//!
//! # The form from prefixes
//!
//! [`Form::Auto`] compares the cheapest unrolled `M + c` with [`compact::AUTO_LIMIT`]. Tracing
//! it whole costs O(N²) operations per candidate (and `generate` at N = 500 took 161 s and 5.6 GB
//! when every unrolled candidate was traced), so it is traced on the model's first
//! [`FIRST_PREFIX`] joints, then twice as many, until the prefix is above the limit (compact:
//! no unrolled candidate of a function in loops is traced at all) or is the whole model (its
//! choices are the ones emitted). The O(N) Newton–Euler functions of a compact model are sized
//! against [`compact::LINEAR_AUTO_LIMIT`] the same way.

use crate::api;
use crate::choose::{self, BodyFrames, Choice, Subjects};
use crate::compact::{self, Decision, Size};
use crate::emit::Shape;
use crate::options::{Error, Form, Options};
use kanegen_dynamics::regroup::RegroupReport;
use kanegen_dynamics::MassMatrixMethod;
use kanegen_model::canonical::CanonicalReport;
use kanegen_model::{BaseKind, Model, Validation};
use kanegen_trace::{Arg, Counts, Function, Traced};

/// Joints of the first prefix traced for the form decision: random chains of 16 joints already
/// emit about twice [`compact::AUTO_LIMIT`] in `M + c` (8,401 operations in canonical frames).
pub const FIRST_PREFIX: usize = 16;

/// How a function's body is produced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// Straight-line code from the chosen candidate's traced graph.
    Unrolled,
    /// The compact form's loops ([`compact::body`]): a kernel of `kanegen_runtime::compact`,
    /// with its traced counts ([`compact::counts`]).
    Compact(Counts),
    /// `forward_dynamics_derivatives` of an unrolled model past the size rule, composed from
    /// the type's own `mass_matrix_inverse`, `nonlinear_effects` and
    /// `inverse_dynamics_derivatives` (`kanegen_runtime::composed`): their counts and the
    /// composition's.
    Composed(Counts),
}

/// One generated function.
#[derive(Clone, Debug)]
pub struct FunctionPlan {
    /// The function.
    pub function: Function,
    /// Its name in the generated code ([`api::fn_name`]).
    pub name: String,
    /// Its arguments (before the runtime payload) with their lengths.
    pub args: Vec<(Arg, usize)>,
    /// How it returns its results.
    pub shape: Shape,
    /// The traced candidates and the chosen one (unrolled), or the compact kernel's methods and
    /// no candidate.
    pub choice: Choice,
    /// How its body is produced.
    pub kernel: Kernel,
}

/// Everything one generation emits, decided.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The model traced and emitted: on the asked base ([`Options::base`]), float noise snapped
    /// ([`Options::snap`]).
    pub model: Model,
    /// What snapping changed.
    pub snap: CanonicalReport,
    /// The model's canonical frames and placements, as traced.
    pub subjects: Subjects,
    /// What regrouping moved (`None`: [`Options::regroup`] off).
    pub regroup: Option<RegroupReport>,
    /// The form and why.
    pub decision: Decision,
    /// The functions, in emission order.
    pub functions: Vec<FunctionPlan>,
    /// Whether the derivative functions were asked for ([`Options::derivatives`]).
    pub derivatives_asked: bool,
    /// Whether they are generated: asked for and [`derivatives_fit`].
    pub derivatives_generated: bool,
}

impl FunctionPlan {
    /// Its operation counts: the chosen candidate's emitted counts, or its kernel's.
    #[must_use]
    pub fn counts(&self) -> Counts {
        match self.kernel {
            Kernel::Unrolled => self.choice.counts(),
            Kernel::Compact(c) | Kernel::Composed(c) => c,
        }
    }

    /// The side of its square matrices (the speeds) for [`Shape::Matrices`], else 0.
    pub(crate) fn speeds(&self) -> usize {
        match self.shape {
            Shape::Matrices(_, nv) => nv,
            _ => 0,
        }
    }
}

/// The most speeds (`N`, or `6 + N` free-floating) the derivative functions are generated for:
/// straight-line, `forward_dynamics_derivatives` is O(NV³) (`M⁻¹` times two `NV × NV`
/// matrices), some 10⁵ operations at 32 speeds, which is what the compact form exists to avoid.
pub const DERIVATIVES_MAX_NV: usize = 24;

/// Whether the derivative functions can be generated for `model` in the form `decision` under
/// `opts`: in the compact form at any size (`kanegen_runtime::compact::derivatives`); in the
/// unrolled form straight-line up to [`DERIVATIVES_MAX_NV`] speeds, and above it in loops when
/// [`compact::loops_derivatives`] allows (under [`Form::Auto`]).
#[must_use]
pub fn derivatives_fit(model: &Model, decision: &Decision, opts: &Options) -> bool {
    decision.form == Form::Compact
        || speeds(model) <= DERIVATIVES_MAX_NV
        || compact::loops_derivatives(opts)
}

/// The speeds of `model`: `N`, or `6 + N` on a free-floating base.
#[must_use]
pub fn speeds(model: &Model) -> usize {
    model.dof()
        + if model.base_kind() == BaseKind::FreeFloating {
            6
        } else {
            0
        }
}

/// The traced graph of each function of a [`Plan`] with an unrolled body (`None` for a compact
/// one), in the plan's order.
pub type Graphs = Vec<Option<Traced>>;

impl Plan {
    /// The plan for `model` under `opts`, with the graphs of its unrolled functions.
    ///
    /// # Errors
    /// A base the model cannot take, a snap tolerance outside `[0, 0.1)`, `form = "compact"` for
    /// a model it does not support, a function that cannot be traced, or two functions of the
    /// same name.
    pub fn new(model: &Model, opts: &Options) -> Result<(Plan, Graphs), Error> {
        let model = traced_model(model, opts)?;
        let snap = model.report;
        let model = model.model;
        let subjects = Subjects::new(&model, opts);
        let (decision, mut decided) = decide_form(&model, &subjects, opts)?;
        let regroup = opts.regroup.then(|| regroup_report(&model, opts));
        let mut functions = Vec::new();
        let mut graphs = Vec::new();
        let mut mass = MassMatrixMethod::Crba;
        let derivatives = opts.derivatives && derivatives_fit(&model, &decision, opts);
        for f in api::functions(&model, opts) {
            if f.is_derivative() && !derivatives {
                continue; // `Plan::not_generated` names them
            }
            let (choice, graph) = match decided.iter().position(|(c, _)| c.function == f) {
                Some(k) => {
                    let (choice, graph) = decided.swap_remove(k);
                    (choice, Some(graph))
                }
                None => plan_body(&model, &subjects, &decision, f, mass, opts)?,
            };
            if f == Function::MassMatrix {
                mass = choice.chosen.mass_matrix;
            }
            let kernel = match &graph {
                Some(_) => Kernel::Unrolled,
                None if composes(&decision, f) => Kernel::Composed(Counts::default()),
                None => Kernel::Compact(compact::kernel_counts(&model, opts, f)?),
            };
            functions.push(function_plan(&model, f, choice, kernel));
            graphs.push(graph);
        }
        composed_counts(&mut functions);
        check_names(&functions)?;
        let plan = Plan {
            derivatives_asked: opts.derivatives,
            derivatives_generated: derivatives,
            model,
            snap,
            subjects,
            regroup,
            decision,
            functions,
        };
        Ok((plan, graphs))
    }

    /// The functions not generated, as the header names them (`` `name` ``): the derivatives
    /// when not asked for, or when they do not fit (above [`DERIVATIVES_MAX_NV`] speeds
    /// unrolled without loops, [`derivatives_fit`]). Empty when they are generated.
    #[must_use]
    pub fn not_generated(&self) -> Vec<String> {
        if self.derivatives_generated {
            return Vec::new();
        }
        Function::ALL
            .into_iter()
            .filter(|f| f.is_derivative())
            .map(|f| format!("`{}`", f.name()))
            .collect()
    }

    /// Whether the base is free-floating.
    #[must_use]
    pub fn floating(&self) -> bool {
        self.model.base_kind() == BaseKind::FreeFloating
    }

    /// Whether the compact form is emitted.
    #[must_use]
    pub fn compact(&self) -> bool {
        self.decision.form == Form::Compact
    }

    /// Whether some function has a body in loops ([`Kernel::Compact`]): in the compact form,
    /// or the derivatives of an unrolled model ([`compact::loops_derivatives`]).
    #[must_use]
    pub fn has_loops(&self) -> bool {
        self.functions
            .iter()
            .any(|fp| matches!(fp.kernel, Kernel::Compact(_)))
    }

    /// The derivative functions of an unrolled model emitted in loops, as the header names them:
    /// `` `name` `` (a composed one is not: [`Plan::composed`]).
    #[must_use]
    pub fn looped_derivatives(&self) -> Vec<String> {
        if self.compact() {
            return Vec::new();
        }
        self.named(|k| matches!(k, Kernel::Compact(_)))
    }

    /// The composed functions ([`Kernel::Composed`]), as the header names them: `` `name` ``.
    #[must_use]
    pub fn composed(&self) -> Vec<String> {
        self.named(|k| matches!(k, Kernel::Composed(_)))
    }

    /// The functions whose kernel is `kind`, as the header names them: `` `name` ``.
    fn named(&self, kind: impl Fn(Kernel) -> bool) -> Vec<String> {
        self.functions
            .iter()
            .filter(|fp| kind(fp.kernel))
            .map(|fp| format!("`{}`", fp.name))
            .collect()
    }

    /// The choices, in emission order.
    pub fn choices(&self) -> impl Iterator<Item = &Choice> {
        self.functions.iter().map(|f| &f.choice)
    }

    /// The functions with a compact body that kept their unrolled one (under [`Form::Auto`]):
    /// the derivative functions ([`compact::may_keep_inverse_unrolled`]) when `derivatives`,
    /// else the others ([`compact::keeps_unrolled`]), as the header names them:
    /// `` `name` (ops) ``.
    #[must_use]
    pub fn kept_unrolled(&self, derivatives: bool) -> Vec<String> {
        if !self.compact() {
            return Vec::new();
        }
        self.functions
            .iter()
            .filter(|fp| {
                fp.kernel == Kernel::Unrolled
                    && compact::has_body(fp.function, self.floating())
                    && fp.function.is_derivative() == derivatives
            })
            .map(|fp| format!("`{}` ({})", fp.function.name(), fp.choice.counts().total()))
            .collect()
    }
}

/// The form [`Plan::new`] decides for `model` under `opts`, without planning the functions.
///
/// # Errors
/// As [`Plan::new`] for the form: a bad base or snap tolerance, `form = "compact"` for a model
/// it does not support, or an `M + c` that cannot be traced.
pub fn form(model: &Model, opts: &Options) -> Result<Decision, Error> {
    let model = traced_model(model, opts)?.model;
    let subjects = Subjects::new(&model, opts);
    Ok(decide_form(&model, &subjects, opts)?.0)
}

/// The model on the asked base, its float noise snapped.
fn traced_model(
    model: &Model,
    opts: &Options,
) -> Result<kanegen_model::canonical::Canonical, Error> {
    if !(opts.snap.is_finite() && (0.0..0.1).contains(&opts.snap)) {
        return Err(Error(format!(
            "snap tolerance {} is not in [0, 0.1)",
            opts.snap
        )));
    }
    Ok(match opts.base {
        Some(kind) if kind != model.base_kind() => model
            .clone()
            .with_base_kind(kind)
            .map_err(|e| Error(e.to_string()))?
            .snapped(opts.snap),
        _ => model.snapped(opts.snap),
    })
}

/// What regrouping moves in `model` (the last body kept as it is for a runtime payload).
fn regroup_report(model: &Model, opts: &Options) -> RegroupReport {
    let keep: &[usize] = if opts.runtime_payload {
        &[model.dof() - 1]
    } else {
        &[]
    };
    kanegen_dynamics::regroup::regrouped::<f64>(model, model.base_inertial(), keep).report
}

/// The form ([`compact::decide`]): under [`Form::Auto`] for a supported model, from the cheapest
/// unrolled `M + c` traced on prefixes of the model ([`size_on_prefixes`], with the
/// mass-matrix method `M` chooses, as the unrolled code would emit it). When the whole model was
/// traced, its choices of `M` and `(M, c)` are returned for the emitter to use rather than trace
/// again.
fn decide_form(
    model: &Model,
    subjects: &Subjects,
    opts: &Options,
) -> Result<(Decision, Vec<(Choice, Traced)>), Error> {
    let why_not = compact::unsupported(opts);
    let (size, traced) = match (opts.form, why_not) {
        (Form::Auto, None) => {
            let fs = [
                Function::MassMatrix,
                Function::MassMatrixAndNonlinearEffects,
            ];
            let (size, traced) = size_on_prefixes(
                model,
                subjects,
                opts,
                compact::AUTO_LIMIT,
                &fs,
                MassMatrixMethod::Crba,
            )?;
            (Some(size), traced)
        }
        _ => (None, Vec::new()),
    };
    let mut decision = compact::decide(opts, model.dof(), why_not, size)?;
    if decision.form == Form::Compact && model.has_mimics() {
        decision.line.push_str(
            " Mimic joints: the loops run on the full joint list (`CX_COUPLING`: the state \
             expanded, `q_full = G q + o`, `q̇_full = G q̇`), the results reduced (`M = Gᵀ M_full \
             G`, `c = Gᵀ c_full`, `J G`, `Gᵀ ∂τ G`); forward dynamics, its derivatives and `M⁻¹` \
             solve the reduced `M` by LDLᵀ; `f_ext` has one row per body of the full tree.",
        );
    }
    // Compact: the whole model's unrolled `M` and `(M, c)` are not emitted.
    let traced = if decision.form == Form::Compact {
        Vec::new()
    } else {
        traced
    };
    Ok((decision, traced))
}

/// The choice and graph of `f` (no graph for a compact body): traced unless the form is
/// compact and `f` has a compact body; an O(N) Newton–Euler function under [`Form::Auto`]
/// keeps its unrolled body (traced whole) when that is within [`compact::LINEAR_AUTO_LIMIT`],
/// sized on prefixes first ([`size_on_prefixes`]).
fn plan_body(
    model: &Model,
    subjects: &Subjects,
    decision: &Decision,
    f: Function,
    mass: MassMatrixMethod,
    opts: &Options,
) -> Result<(Choice, Option<Traced>), Error> {
    let floating = model.base_kind() == BaseKind::FreeFloating;
    let traced = if decision.form != Form::Compact && f.is_derivative() {
        unrolled_derivative(model, subjects, f, mass, opts)?
    } else if decision.form != Form::Compact || !compact::has_body(f, floating) {
        Some(choose_in(model, subjects, f, mass, opts)?)
    } else if compact::may_keep_inverse_unrolled(opts, f) {
        let limit = compact::DERIVATIVES_AUTO_LIMIT;
        let (size, traced) = size_on_prefixes(model, subjects, opts, limit, &[f], mass)?;
        traced.into_iter().next().filter(|_| !size.above(limit))
    } else if compact::may_keep_unrolled(opts, f) && f.frame().is_some() {
        // A frame function is O(depth) and the prefixes have no frames: traced whole.
        let (choice, graph) = choose_in(model, subjects, f, mass, opts)?;
        let size = compact::Size {
            ops: choice.counts().total(),
            joints: model.dof(),
        };
        compact::keeps_unrolled(opts, f, size).then_some((choice, graph))
    } else if compact::may_keep_unrolled(opts, f) {
        let limit = compact::LINEAR_AUTO_LIMIT;
        let (size, traced) = size_on_prefixes(model, subjects, opts, limit, &[f], mass)?;
        traced
            .into_iter()
            .next()
            .filter(|_| compact::keeps_unrolled(opts, f, size))
    } else {
        None
    };
    Ok(match traced {
        Some((choice, graph)) => (choice, Some(graph)),
        None => (compact_choice(f), None),
    })
}

/// The choice and graph of the derivative function `f` of an unrolled model, `None` when it
/// is emitted in loops: above [`DERIVATIVES_MAX_NV`] speeds (not traced), or when its cheapest
/// unrolled body is larger than [`compact::derivative_keeps_unrolled`] allows against the
/// compact kernel's traced operations.
fn unrolled_derivative(
    model: &Model,
    subjects: &Subjects,
    f: Function,
    mass: MassMatrixMethod,
    opts: &Options,
) -> Result<Option<(Choice, Traced)>, Error> {
    if !compact::loops_derivatives(opts) {
        return choose_in(model, subjects, f, mass, opts).map(Some);
    }
    if speeds(model) > DERIVATIVES_MAX_NV {
        return Ok(None);
    }
    let (choice, graph) = choose_in(model, subjects, f, mass, opts)?;
    let ops = choice.counts().total();
    let kernel_ops = compact::kernel_counts(model, opts, f)?.total();
    Ok(compact::derivative_keeps_unrolled(f, ops, kernel_ops).then_some((choice, graph)))
}

/// Whether `f` without a straight-line body is composed ([`Kernel::Composed`]): the
/// forward-dynamics derivatives of an unrolled model.
fn composes(decision: &Decision, f: Function) -> bool {
    decision.form != Form::Compact && f == Function::ForwardDynamicsDerivatives
}

/// The counts of a composed function: those of the three functions it calls and of
/// `kanegen_runtime::composed`'s loops ([`compact::composed_counts`]).
fn composed_counts(functions: &mut [FunctionPlan]) {
    let counts_of = |fs: &[FunctionPlan], f: Function| {
        fs.iter()
            .find(|fp| fp.function == f)
            .map_or_else(Counts::default, FunctionPlan::counts)
    };
    let parts = [
        Function::MassMatrixInverse,
        Function::NonlinearEffects,
        Function::InverseDynamicsDerivatives,
    ];
    for k in 0..functions.len() {
        if let Kernel::Composed(_) = functions[k].kernel {
            let nv = functions[k].speeds();
            let own = compact::composed_counts(nv);
            let total = parts
                .iter()
                .map(|&f| counts_of(functions, f))
                .fold(own, |a, b| a + b);
            functions[k].kernel = Kernel::Composed(total);
        }
    }
}

/// The choice of a compact body: the methods of its loops, no candidate traced.
fn compact_choice(f: Function) -> Choice {
    Choice {
        function: f,
        candidates: Vec::new(),
        chosen: compact::methods(f),
        frames: BodyFrames::Model,
    }
}

/// [`choose::choose_in`], its error as the generator's.
fn choose_in(
    model: &Model,
    subjects: &Subjects,
    f: Function,
    mass: MassMatrixMethod,
    opts: &Options,
) -> Result<(Choice, Traced), Error> {
    choose::choose_in(model, subjects, f, mass, opts).map_err(|e| Error(e.to_string()))
}

/// The cheapest unrolled candidate of the last of `fs` (each traced after the ones before it,
/// `M`'s chosen mass-matrix method feeding the later ones, from `mass`), traced on the first
/// [`FIRST_PREFIX`] joints of `model`, then on twice as many, until a prefix is above `limit`
/// or the whole model is traced. The choices are returned when they are of the whole model.
fn size_on_prefixes(
    model: &Model,
    subjects: &Subjects,
    opts: &Options,
    limit: u64,
    fs: &[Function],
    mass: MassMatrixMethod,
) -> Result<(Size, Vec<(Choice, Traced)>), Error> {
    let n = model.dof();
    let mut joints = FIRST_PREFIX;
    while joints < n {
        // A prefix that fails validation is skipped: a longer one (at last the model) is traced.
        if let Some(prefix) = prefix(model, joints) {
            let traced = choose_each(&prefix, &Subjects::new(&prefix, opts), fs, mass, opts)?;
            let size = size_of(&traced, joints);
            if size.above(limit) {
                return Ok((size, Vec::new()));
            }
        }
        joints *= 2;
    }
    let traced = choose_each(model, subjects, fs, mass, opts)?;
    Ok((size_of(&traced, n), traced))
}

/// The emitted operations of the last choice of `traced`, on `joints` joints.
fn size_of(traced: &[(Choice, Traced)], joints: usize) -> Size {
    Size {
        ops: traced.last().map_or(0, |(c, _)| c.counts().total()),
        joints,
    }
}

/// The choice of each of `fs` in turn, the mass-matrix method `M` chooses (from `mass`) used by
/// the later ones.
fn choose_each(
    model: &Model,
    subjects: &Subjects,
    fs: &[Function],
    mut mass: MassMatrixMethod,
    opts: &Options,
) -> Result<Vec<(Choice, Traced)>, Error> {
    let mut traced = Vec::new();
    for &f in fs {
        let c = choose_in(model, subjects, f, mass, opts)?;
        if f == Function::MassMatrix {
            mass = c.0.chosen.mass_matrix;
        }
        traced.push(c);
    }
    Ok(traced)
}

/// The model of the first `joints` joints of `model` (parents come first, so they form a chain
/// or tree of their own) on a fixed base, without frames; `None` when it fails validation.
fn prefix(model: &Model, joints: usize) -> Option<Model> {
    Model::new_with(
        model.name(),
        model.base(),
        model.base_inertial().cloned(),
        model.joints().get(..joints)?.to_vec(),
        Validation {
            allow_nonphysical_inertia: true,
        },
    )
    .ok()
}

/// The plan of `f`: its name, arguments and shape, with its choice and kernel.
fn function_plan(model: &Model, f: Function, choice: Choice, kernel: Kernel) -> FunctionPlan {
    let floating = model.base_kind() == BaseKind::FreeFloating;
    // The arguments are the independent coordinates (mimic joints follow theirs); `f_ext` has
    // a row per body, mimic joints' bodies included (the trace reads one per joint).
    let n = model.coordinate_count();
    let len = |a: Arg| match a {
        Arg::FExt => a.len(model.dof(), floating),
        _ => a.len(n, floating),
    };
    FunctionPlan {
        function: f,
        name: api::fn_name(f, model),
        args: f.args(floating).iter().map(|a| (*a, len(*a))).collect(),
        shape: api::shape(f, n, floating),
        choice,
        kernel,
    }
}

/// An error when two functions have the same name.
fn check_names(functions: &[FunctionPlan]) -> Result<(), Error> {
    let mut names = std::collections::HashSet::new();
    for fp in functions {
        if !names.insert(fp.name.as_str()) {
            return Err(Error(format!(
                "two generated functions are called `{}` (rename a frame of the model)",
                fp.name
            )));
        }
    }
    Ok(())
}
