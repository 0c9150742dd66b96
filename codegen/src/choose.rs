//! Which methods a generated function uses: every candidate is traced and the one with the
//! fewest emitted operations (`mul + add`) wins, the first in report order on ties. Forward
//! dynamics has two kinds of candidate: LDLᵀ on `M` and `c` (one per nonlinear-effects method) and the
//! articulated-body algorithm ([`Methods::ABA`], which uses neither), last. Each candidate of a
//! joint-space function is traced twice: in the model's own body frames and in its canonical
//! frames ([`BodyFrames`]).

use crate::options::Options;
use kanegen_dynamics::params::{
    axis_turn, coordinate_axis, is_near_signed_permutation, mdh_split, NEAR_PERMUTATION,
};
use kanegen_dynamics::{ForwardMethod, MassMatrixMethod, Methods, NonlinearEffectsMethod};
use kanegen_model::{BaseKind, JointKind, Model};
use kanegen_trace::{trace, Base, Convention, Counts, Function, Spec, Subject, TraceError, Traced};

/// The body frames a candidate is traced in.
///
/// Joint-space results (`M`, `c`, `g`, `τ`, `q̈`) do not depend on them, their cost does: in
/// canonical frames ([`Model::canonical`]: every joint axis `z`, each body's `x` along the common
/// normal to its child's axis, as in the modified Denavit–Hartenberg convention) a joint
/// rotation is two sines and cosines and the joint placements are sparse. On random chains with
/// general geometry (N = 2, 8, 16) they take `(M, c)` from 525, 4077 and 9521 emitted operations
/// to 150, 2955 and 8401; on the example-robot-data arms, whose frames already are nearly that,
/// they win or lose by a few per cent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BodyFrames {
    /// The model's own frames (float noise snapped, [`Options::snap`]).
    Model,
    /// [`Model::canonical_with`] the same snap tolerance.
    Canonical,
}

impl BodyFrames {
    /// `model` or `canonical`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            BodyFrames::Model => "model",
            BodyFrames::Canonical => "canonical",
        }
    }

    /// The frames `f` is traced in: canonical ones too when [`Options::canonical`] is on, no
    /// algorithm is forced ([`Options::algorithm`]: the paper's algorithm on the model as given),
    /// `f` is [`Function::is_joint_space`] and there is no runtime payload (given in its body's
    /// own frame).
    #[must_use]
    pub fn for_function(f: Function, opts: &Options) -> &'static [BodyFrames] {
        if f.is_joint_space() && Self::canonical_wanted(opts) {
            &[BodyFrames::Model, BodyFrames::Canonical]
        } else {
            &[BodyFrames::Model]
        }
    }

    /// Whether canonical frames are traced at all: [`Options::canonical`] on, no algorithm
    /// forced and no runtime payload.
    fn canonical_wanted(opts: &Options) -> bool {
        opts.canonical && opts.algorithm.is_none() && !opts.runtime_payload
    }
}

/// One traced candidate: its methods, its body frames and its emitted counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Candidate {
    /// The methods.
    pub methods: Methods,
    /// The body frames.
    pub frames: BodyFrames,
    /// Emitted counts.
    pub counts: Counts,
}

/// The candidates of one function, their emitted counts, and the winner.
#[derive(Clone, Debug)]
pub struct Choice {
    /// The function.
    pub function: Function,
    /// Every candidate traced.
    pub candidates: Vec<Candidate>,
    /// The methods of the cheapest candidate.
    pub chosen: Methods,
    /// The body frames of the cheapest candidate.
    pub frames: BodyFrames,
}

impl Choice {
    /// The chosen candidate (`None` only for a `Choice` built by hand without it).
    #[must_use]
    pub fn candidate(&self) -> Option<&Candidate> {
        self.candidates.iter().find(|c| self.is_chosen(c))
    }

    /// Emitted counts of the chosen candidate.
    #[must_use]
    pub fn counts(&self) -> Counts {
        self.candidate().map(|c| c.counts).unwrap_or_default()
    }

    /// Whether `c` is the chosen candidate.
    #[must_use]
    pub fn is_chosen(&self, c: &Candidate) -> bool {
        c.methods == self.chosen && c.frames == self.frames
    }

    /// The mass-matrix method's name when the candidate `m` uses one (forward dynamics by the
    /// articulated-body algorithm does not).
    #[must_use]
    pub fn mass_matrix_method(&self, m: Methods) -> Option<&'static str> {
        (self.function.uses_mass_matrix() && !self.is_aba(m)).then(|| m.mass_matrix.name())
    }

    /// The nonlinear-effects method's name when the candidate `m` uses one (forward dynamics by the
    /// articulated-body algorithm does not).
    #[must_use]
    pub fn nonlinear_effects_method(&self, m: Methods) -> Option<&'static str> {
        (self.function.uses_nonlinear_effects() && !self.is_aba(m))
            .then(|| m.nonlinear_effects.name())
    }

    /// The forward method's name (`ldlt`, `aba`) for forward dynamics, `None` otherwise.
    #[must_use]
    pub fn forward_method(&self, m: Methods) -> Option<&'static str> {
        self.function
            .is_forward_dynamics()
            .then(|| m.forward.name())
    }

    fn is_aba(&self, m: Methods) -> bool {
        self.function.is_forward_dynamics() && m.forward == ForwardMethod::Aba
    }
}

/// The spec of the generated code: the model's base, and gravity and the runtime payload of
/// `opts`.
#[must_use]
pub fn spec(model: &Model, opts: &Options) -> Spec {
    Spec {
        base: match (model.base_kind(), model.base_inertial()) {
            (BaseKind::FreeFloating, Some(i)) => Base::FreeFloating(i.clone()),
            _ => Base::Fixed,
        },
        gravity: opts.gravity,
        runtime_payload: opts.runtime_payload,
        ..Spec::default()
    }
}

/// The candidates of `f`: every mass-matrix method for `M`; every nonlinear-effects method (with the chosen
/// mass-matrix method `mass`, and for a function with `M` on a chain also with `crba` and
/// `crba-inertial`) for a function with `c`, and for forward dynamics then the articulated-body
/// algorithm ([`Methods::ABA`]); the chosen method alone for the others.
/// On a tree only the local-frame methods (`crba`, `rnea`, `newton-euler`, `aba`) are
/// candidates: the paper's
/// inertial-frame algorithms handle serial chains only.
#[must_use]
pub fn candidates(f: Function, mass: MassMatrixMethod, chain: bool) -> Vec<Methods> {
    let mass_methods: &[MassMatrixMethod] = if chain {
        &MassMatrixMethod::ALL
    } else {
        &[MassMatrixMethod::Crba]
    };
    let nonlinear_effects_methods: &[NonlinearEffectsMethod] = if chain {
        &NonlinearEffectsMethod::ALL
    } else {
        &[
            NonlinearEffectsMethod::Rnea,
            NonlinearEffectsMethod::NewtonEuler,
        ]
    };
    if f == Function::MassMatrix {
        mass_methods
            .iter()
            .map(|&mass_matrix| Methods {
                mass_matrix,
                nonlinear_effects: NonlinearEffectsMethod::Rnea,
                forward: ForwardMethod::Ldlt,
            })
            .collect()
    } else if f.uses_nonlinear_effects() {
        // With `M` too: the mass-matrix method chosen for `M` and the two CRBAs, whose counts
        // are close (random N = 16: `crba` 6122 against `crba-inertial` 6134 for `M`, but 8672
        // against 8401 with `c`, which shares more with the inertial-frame one).
        let mut masses = vec![mass];
        if f.uses_mass_matrix() && chain {
            for m in [MassMatrixMethod::Crba, MassMatrixMethod::CrbaInertial] {
                if !masses.contains(&m) {
                    masses.push(m);
                }
            }
        }
        let mut c: Vec<Methods> = masses
            .iter()
            .flat_map(|&mass_matrix| {
                nonlinear_effects_methods
                    .iter()
                    .map(move |&nonlinear_effects| Methods {
                        mass_matrix,
                        nonlinear_effects,
                        forward: ForwardMethod::Ldlt,
                    })
            })
            .collect();
        if f.is_forward_dynamics() {
            c.push(Methods::ABA);
        }
        c
    } else {
        vec![Methods {
            mass_matrix: mass,
            nonlinear_effects: NonlinearEffectsMethod::Rnea,
            forward: ForwardMethod::Ldlt,
        }]
    }
}

/// Above this many joints the candidates that cannot win are not traced (see [`can_win`]).
pub const SIZE_RULE_N: usize = 24;

/// Whether candidate `m` of `f` can win on a chain of `n` joints. Up to [`SIZE_RULE_N`] joints
/// every candidate can. Above it the direct Kane sums (`kane-direct`, O(N³) for `M` and O(N²)
/// for `c`) and the recurrent mass matrices (`recurrent`, `recurrent-r1`: O(N²) with a larger
/// constant than `crba-inertial`) are skipped. Measured on random chains (emitted `mul + add`, `A`
/// and `b` alone): at N = 16 `kane-direct` M costs 2.8×, `recurrent` 2.2× and `kane-direct` b
/// 1.6× the cheapest, at N = 24 4.1×, 2.6× and 1.9×, and the ratios grow with N; tracing them
/// is what made `generate` O(N³) in memory (2.3 M emitted operations for `kane-direct` M at
/// N = 100).
#[must_use]
pub fn can_win(f: Function, m: Methods, n: usize) -> bool {
    if n <= SIZE_RULE_N {
        return true;
    }
    let mass_ok = f != Function::MassMatrix
        || !matches!(
            m.mass_matrix,
            MassMatrixMethod::KaneDirect
                | MassMatrixMethod::Recurrent
                | MassMatrixMethod::RecurrentR1
        );
    let c_ok =
        !f.uses_nonlinear_effects() || m.nonlinear_effects != NonlinearEffectsMethod::KaneDirect;
    mass_ok && c_ok
}

/// The models a function's candidates are traced on: the model in its own frames and, where
/// [`Options::canonical`] asks for them, in its canonical frames, each with whether its
/// placements are worth a second, two-step trace. Derived once per model and shared by every
/// function traced on it.
#[derive(Clone, Debug)]
pub struct Subjects {
    /// [`Model::canonical_with`] the snap tolerance: `None` when canonical frames are off (see
    /// [`BodyFrames::for_function`]) or the turned model fails validation (numbers at its
    /// bounds), then only the model's own frames are traced.
    pub canonical: Option<Model>,
    /// Placements of the model near a signed permutation or made of turns about coordinate
    /// axes: the two-step carries through them are traced as well
    /// ([`has_two_step_placements`]).
    near_model: bool,
    /// The same of the canonical model.
    near_canonical: bool,
}

impl Subjects {
    /// The subjects of `model` under `opts`.
    #[must_use]
    pub fn new(model: &Model, opts: &Options) -> Self {
        let canonical = BodyFrames::canonical_wanted(opts)
            .then(|| model.canonical_with(opts.snap).ok())
            .flatten()
            .map(|c| c.model);
        Subjects {
            near_model: has_two_step_placements(model),
            near_canonical: canonical.as_ref().is_some_and(has_two_step_placements),
            canonical,
        }
    }
}

/// Traces every candidate of `f` that [`can_win`], in every [`BodyFrames::for_function`], and
/// keeps the cheapest (the model's own frames on ties); with [`Options::algorithm`], traces that
/// one for a function with a mass-matrix or nonlinear-effects method. Derives the model's [`Subjects`] first;
/// [`choose_in`] takes them derived.
///
/// # Errors
/// As [`trace`].
pub fn choose(
    model: &Model,
    f: Function,
    mass: MassMatrixMethod,
    opts: &Options,
) -> Result<(Choice, Traced), TraceError> {
    choose_in(model, &Subjects::new(model, opts), f, mass, opts)
}

/// [`choose`] on `model` with its [`Subjects`] already derived.
///
/// # Errors
/// As [`trace`].
pub fn choose_in(
    model: &Model,
    subjects: &Subjects,
    f: Function,
    mass: MassMatrixMethod,
    opts: &Options,
) -> Result<(Choice, Traced), TraceError> {
    let spec = Spec {
        regroup: opts.regroup && f != Function::BaseReaction,
        ..spec(model, opts)
    };
    let mut best: Option<(u64, Methods, BodyFrames, Traced)> = None;
    let mut traced = Vec::new();
    let frames = BodyFrames::for_function(f, opts);
    let all = match opts.algorithm {
        // Forced: the one algorithm for whatever it computes, the others as usual.
        Some(m) if f.uses_mass_matrix() || f.uses_nonlinear_effects() => vec![m],
        _ => candidates(f, mass, model.is_chain()),
    };
    // Mimic joints: forward dynamics solves the reduced `M` (no articulated-body pass).
    let all: Vec<Methods> = all
        .into_iter()
        .filter(|m| {
            !(model.has_mimics() && f.is_forward_dynamics() && m.forward == ForwardMethod::Aba)
        })
        .collect();
    let n = model.dof();
    let kept: Vec<Methods> = all.iter().copied().filter(|m| can_win(f, *m, n)).collect();
    for m in if kept.is_empty() { all } else { kept } {
        for &fr in frames {
            let (subject, near) = match (fr, &subjects.canonical) {
                (BodyFrames::Canonical, Some(c)) => (c, subjects.near_canonical),
                (BodyFrames::Canonical, None) => continue,
                (BodyFrames::Model, _) => (model, subjects.near_model),
            };
            let mut t = trace(Subject::Model(subject), f, m, &spec)?;
            let mut c = t.trace.counts(Convention::Emitted);
            // It changes the CRBA's carries and Newton–Euler's rotations (not ABA's); kept where cheaper.
            if near && takes_two_steps(f, m, n) {
                let near = Spec {
                    two_step_placement: NEAR_PERMUTATION,
                    ..spec.clone()
                };
                let t2 = trace(Subject::Model(subject), f, m, &near)?;
                let c2 = t2.trace.counts(Convention::Emitted);
                if c2.total() < c.total() {
                    (t, c) = (t2, c2);
                }
            }
            traced.push(Candidate {
                methods: m,
                frames: fr,
                counts: c,
            });
            if best.as_ref().is_none_or(|(b, ..)| c.total() < *b) {
                best = Some((c.total(), m, fr, t));
            }
        }
    }
    let (_, chosen, frames, winner) = best.expect("every function has a candidate");
    Ok((
        Choice {
            function: f,
            candidates: traced,
            chosen,
            frames,
        },
        winner,
    ))
}

/// Whether any chosen candidate takes a sine or a cosine (then the generated type carries its
/// own `sincos`, [`crate::sincos`], and the header says so).
#[must_use]
pub fn takes_trig<'a>(choices: impl IntoIterator<Item = &'a Choice>) -> bool {
    choices
        .into_iter()
        .any(|ch| ch.candidate().is_some_and(|c| c.counts.sincos > 0))
}

/// Whether a revolute joint about a coordinate axis of `model` is placed near a signed
/// permutation ([`NEAR_PERMUTATION`]), by a turn about one coordinate axis ([`axis_turn`]) or by
/// two whose second is about the joint's axis ([`mdh_split`]), but not exactly on a permutation:
/// the two-step carries are then worth a second trace.
fn has_two_step_placements(model: &Model) -> bool {
    model.joints().iter().any(|j| {
        let rot = &j.origin.rotation;
        j.kind == JointKind::Revolute
            && coordinate_axis(j.axis).is_some_and(|k| {
                (is_near_signed_permutation(rot, NEAR_PERMUTATION)
                    || axis_turn(rot).is_some()
                    || mdh_split(rot, k).is_some())
                    && !is_near_signed_permutation(rot, 0.0)
            })
    })
}

/// Whether `f` by `m` runs an algorithm whose carries ([`NEAR_PERMUTATION`]) may go in two
/// steps: the CRBA (its inertia and force carries) or the classical Newton–Euler `c` (its vector
/// rotations, `kanegen_dynamics::joint::rotate_up`); not forward dynamics by ABA. Above
/// [`SIZE_RULE_N`] joints not for a function of the mass matrix: its code is compact there (loops
/// over the model's own tables, [`crate::compact`]) and a second trace of O(N²) operations only
/// costs memory (`generate` at N = 200 went from under 1 GB to 1066 MB with it).
fn takes_two_steps(f: Function, m: Methods, n: usize) -> bool {
    if f.uses_mass_matrix() && n > SIZE_RULE_N {
        return false;
    }
    let crba = f.uses_mass_matrix() && m.mass_matrix == MassMatrixMethod::Crba;
    let newton_euler =
        f.uses_nonlinear_effects() && m.nonlinear_effects == NonlinearEffectsMethod::NewtonEuler;
    (crba || newton_euler) && !(f.is_forward_dynamics() && m.forward == ForwardMethod::Aba)
}
