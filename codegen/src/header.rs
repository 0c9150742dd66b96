//! The doc header of generated code: model, joints, conventions, precision, and the emitted
//! operation counts of every candidate.

use crate::compact;
use crate::options::{Float, Options, VERSION};
use crate::plan::Plan;
use kanegen_dynamics::regroup::RegroupReport;
use kanegen_model::{BaseKind, JointKind, Model};

/// Text fit for a doc comment: control and bidirectional-override characters dropped.
#[must_use]
pub fn doc_safe(s: &str) -> String {
    s.chars()
        .filter(|c| {
            !c.is_control()
                && !matches!(*c as u32, 0x200E | 0x200F | 0x202A..=0x202E | 0x2066..=0x2069)
        })
        .collect()
}

fn joint_list(model: &Model) -> String {
    model
        .joints()
        .iter()
        .zip(model.mimics())
        .map(|(j, m)| {
            let k = match j.kind {
                JointKind::Revolute => "revolute",
                JointKind::Prismatic => "prismatic",
            };
            match m {
                // A mimic joint has no entry of `q`: it follows its primary.
                Some(m) => format!(
                    "`{}` ({k}, mimic: {} · `{}` + {}, no entry of `q`)",
                    doc_safe(&j.name),
                    m.multiplier,
                    doc_safe(&model.joints()[m.primary].name),
                    m.offset
                ),
                None => format!("`{}` ({k})", doc_safe(&j.name)),
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The header lines (without comment markers) of `plan`: the model, the conventions, the form,
/// and the counts of every traced candidate. `fmas`: fused multiply-adds per emitted function.
#[must_use]
pub fn lines(plan: &Plan, opts: &Options, fmas: &[u64]) -> Vec<String> {
    let mut h = description(plan, opts, fmas, Lang::Rust);
    h.push(form_line(plan));
    h.push(lanes_line(plan, opts));
    h.extend(count_table(plan));
    h
}

/// The language a header describes: the calls it names differ.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Lang<'a> {
    /// Rust, generic over the lane type `S`.
    Rust,
    /// C, its functions and types named `PREFIX_…`.
    C {
        /// The prefix.
        prefix: &'a str,
    },
}

/// The header lines of C output ([`crate::c`]): [`lines`] with the calls and types C has, and
/// no lanes.
#[must_use]
pub(crate) fn c_lines(plan: &Plan, opts: &Options, fmas: &[u64], prefix: &str) -> Vec<String> {
    let mut h = description(plan, opts, fmas, Lang::C { prefix });
    h.push(form_line(plan));
    h.extend(count_table(plan));
    h
}

/// The lanes line: every function `NAME` has a `NAME_lanes` form over
/// `kanegen_runtime::lanes::Lanes<F>`, several states per call on SIMD vectors.
fn lanes_line(plan: &Plan, opts: &Options) -> String {
    let f = opts.float.name();
    let mut line = format!(
        "Lanes: every function `NAME` has a `NAME_lanes<S: Lanes<{f}>>` form \
         (`kanegen_runtime::lanes`) taking and returning `S` in place of `{f}`: `S::LANES` \
         states per call, one per lane of a SIMD vector (`wide`'s `{}`), each lane's results \
         bit for bit those of `NAME` for that lane's state; `NAME_batch<S>` runs it over slices \
         of states, `S::LANES` at a time.",
        match opts.float {
            Float::F64 => "f64x2`, `f64x4",
            Float::F32 => "f32x4`, `f32x8",
        }
    );
    if plan
        .functions
        .iter()
        .any(|fp| !matches!(fp.kernel, crate::plan::Kernel::Unrolled))
    {
        line.push_str(" A straight-line `NAME` is its `NAME_lanes` at `S = ");
        line.push_str(f);
        line.push_str(
            "` (one body); a function in loops runs its kernel on `kanegen_runtime::lanes::Lane<S>` \
             (the tables' numbers splat over the lanes) where it has a lane body \
             (`kanegen_codegen::compact::lanes_body`: fixed-base `f64` code of at most 64 \
             joints without a runtime payload or mimic joints, but for `M`, `(M, c)` and the \
             frames), a composed one composes its parts' lane forms, and any other \
             evaluates `NAME` lane by lane.",
        );
    } else {
        line.push_str(" `NAME` is its `NAME_lanes` at `S = ");
        line.push_str(f);
        line.push_str("` (one body).");
    }
    line
}

/// The form line ([`crate::compact::decide`]), naming the functions a compact model keeps
/// straight-line.
fn form_line(plan: &Plan) -> String {
    let mut line = plan.decision.line.clone();
    let kept = plan.kept_unrolled(false);
    if !kept.is_empty() {
        line.push_str(&format!(
            " Straight-line all the same: {} (an O(N) function within {} emitted operations \
             measured faster unrolled).",
            kept.join(", "),
            compact::LINEAR_AUTO_LIMIT
        ));
    }
    let kept = plan.kept_unrolled(true);
    if !kept.is_empty() {
        line.push_str(&format!(
            " Straight-line too: {} (the CRBA and the LDLᵀ inverse unrolled, within {} emitted \
             operations, measured faster than the dense kernel's loops).",
            kept.join(", "),
            compact::DERIVATIVES_AUTO_LIMIT
        ));
    }
    let looped = plan.looped_derivatives();
    if !looped.is_empty() {
        line.push_str(&format!(
            " In loops all the same: {} (the compact form's derivative kernels, \
             `kanegen_runtime::compact::derivatives`, on the model's constant tables: a \
             straight-line body above {} emitted operations and {} % of the kernel's, or above \
             {} speeds, measured slower).",
            looped.join(", "),
            compact::DERIVATIVES_AUTO_LIMIT,
            compact::DERIVATIVES_UNROLLED_SHARE,
            crate::plan::DERIVATIVES_MAX_NV
        ));
    }
    let composed = plan.composed();
    if !composed.is_empty() {
        line.push_str(&format!(
            " Composed: {} (`q̈ = M⁻¹ (τ − c)` from `mass_matrix_inverse` and \
             `nonlinear_effects`, then `−M⁻¹ ∂τ/∂x` from `inverse_dynamics_derivatives`, \
             `kanegen_runtime::composed`: its straight-line body is past the size rule).",
            composed.join(", ")
        ));
    }
    let missing = plan.not_generated();
    if !missing.is_empty() {
        let why = if plan.derivatives_asked {
            format!(
                "generated straight-line up to {} speeds and in loops at any size, but \
                 `form = \"unrolled\"` or a forced algorithm has no loops; docs/limits.md",
                crate::plan::DERIVATIVES_MAX_NV
            )
        } else {
            "not asked for: `derivatives = false`, `--no-derivatives`".to_string()
        };
        line.push_str(&format!(" Not generated: {} ({why}).", missing.join(", ")));
    }
    line
}

/// The model, the conventions, the options and the precision.
fn description(plan: &Plan, opts: &Options, fmas: &[u64], lang: Lang) -> Vec<String> {
    let model = &plan.model;
    let snap = &plan.snap;
    let mut h = vec![
        format!(
            "Dynamics of `{}` (N = {}), generated by kanegen-codegen {VERSION}. Do not edit.",
            doc_safe(model.name()),
            model.coordinate_count()
        ),
        String::new(),
        format!("Joints: {}.", joint_list(model)),
        String::new(),
        "Convention: `M(q) q̈ + c(q, q̇) = τ` (Pinocchio's signs; the paper's `A q̈ = b` has `A = M`, \
         `b = τ − c`)."
            .into(),
        match model.base_kind() {
            BaseKind::Fixed => "Base: fixed.".into(),
            BaseKind::FreeFloating => format!(
                "Base: free-floating (`{}`, {} kg). `q = [p₀ (3), quaternion x, y, z, w (4), \
                 joints ({})]`, `v = [v_b (3), ω_b (3), q̇ ({})]`: the base origin's position in \
                 the inertial frame, the base's attitude (base to inertial), its linear and \
                 angular velocity in base coordinates (Pinocchio's free-flyer).",
                doc_safe(model.base()),
                model.base_inertial().map_or(0.0, |i| i.mass),
                model.coordinate_count(),
                model.coordinate_count()
            ),
        },
        match opts.gravity {
            Some(g) => format!(
                "Gravity: [{}, {}, {}] m/s² in the {} frame (inside `c`).",
                g[0],
                g[1],
                g[2],
                match model.base_kind() {
                    BaseKind::Fixed => "base",
                    BaseKind::FreeFloating => "inertial",
                }
            ),
            None => "Gravity: none (space).".into(),
        },
        if opts.runtime_payload {
            match lang {
                Lang::Rust => format!(
                    "Runtime payload: the last body's mass properties are the argument \
                     `payload: &{}`.",
                    opts.payload_name
                ),
                Lang::C { prefix } => format!(
                    "Runtime payload: the last body's mass properties are the argument \
                     `const {prefix}_payload *payload`."
                ),
            }
        } else {
            "Runtime payload: no (every model number is a constant).".into()
        },
        regroup_line(model, plan.regroup.as_ref()),
        if opts.snap == 0.0 {
            "Float noise: kept (snapping off).".into()
        } else if snap.snapped == 0 {
            format!(
                "Float noise: nothing within {:e} of 0 or ±1 to snap.",
                opts.snap
            )
        } else {
            format!(
                "Float noise: {} {} snapped to exact 0 or ±1 (tolerance {:e}, the largest \
                 change {:.1e}).",
                snap.snapped,
                if snap.snapped == 1 { "number" } else { "numbers" },
                opts.snap,
                snap.largest_snap
            )
        },
        match opts.algorithm {
            None => "Algorithm: per function the cheapest candidate (below).".into(),
            Some(m) => format!(
                "Algorithm: forced to `{}` (`algorithm` option) for every function with a \
                 mass-matrix, nonlinear-effects or forward method; without it each takes the cheapest \
                 candidate.",
                m.name()
            ),
        },
    ];
    if opts.table_sincos() && crate::choose::takes_trig(plan.choices()) {
        h.push(match lang {
            Lang::Rust => "Sines and cosines: every joint angle's in one `S::sincos_n` (the runtime's table \
             sine–cosine, lane by lane) at the top of each function, inlined, branch-free for |x| < 32768 and vectorized across the angles (a \
             table of 128 sines and Taylor polynomials to r⁶ for the remainder, |r| ≤ π/256), \
             `libm::sincos` beyond; within 1 ulp of 1 of libm's (`kanegen accuracy` measures it)."
                .into(),
            Lang::C { prefix } => format!(
                "Sines and cosines: every joint angle's in one `{prefix}_sincos_n` at the top of \
                 each function: the runtime's table sine–cosine (`kanegen_runtime::sincos`, its \
                 table and constants printed from it), branch-free for |x| < 32768 (a table of \
                 128 sines and Taylor polynomials to r⁶ for the remainder, |r| ≤ π/256), `sin` \
                 and `cos` of <math.h> beyond; within 1 ulp of 1 of libm's."
            ),
        });
    }
    let total: u64 = fmas.iter().sum();
    let per = plan
        .functions
        .iter()
        .zip(fmas)
        .map(|(fp, k)| format!("`{}` {k}", fp.name))
        .collect::<Vec<_>>()
        .join(", ");
    // Precision lines only for a non-default precision.
    if opts.float != Float::F64 || opts.fma {
        h.push(match opts.float {
            Float::F64 => "Precision: `f64`.".into(),
            Float::F32 => "Precision: `f32`: inputs, outputs and every intermediate; the model's \
                           numbers rounded to `f32` constants; libm's `sincosf`, `sinf`, `cosf`, \
                           `sqrtf`."
                .into(),
        });
        h.push(if opts.fma {
            let fma = opts.float.libm_fn("fma");
            let call = match (&opts.fma_path, lang) {
                (_, Lang::C { .. }) => format!("`{fma}(a, b, c)` of <math.h>"),
                (Some(path), Lang::Rust) => {
                    format!("`S::fma_with(a, b, c, {path})`, `{path}` on each lane")
                }
                (None, Lang::Rust) => format!("`S::fma(a, b, c)`, libm's `{fma}`"),
            };
            format!(
                "Fused multiply-adds: {total} ({per}), each {call}: a·b + c rounded once; the \
                 counts below count each as 1 mul + 1 add."
            )
        } else {
            "Fused multiply-adds: none.".into()
        });
    }
    if !opts.fma && opts.target_fma && total > 0 {
        h.push(match lang {
            Lang::Rust => format!(
                "Fused multiply-adds where the target has them: {total} ({per}), each \
                 `S::mul_add(a, b, c)`: one instruction, rounded once, when the build targets FMA \
                 (x86-64 with `target_feature = \"fma\"`, e.g. `-C target-cpu=native`; AArch64), \
                 and `a·b + c` otherwise, where the code is bit-identical to unfused code. The \
                 counts below count each as 1 mul + 1 add."
            ),
            Lang::C { prefix } => format!(
                "Fused multiply-adds where the target has them: {total} ({per}), each \
                 `{prefix}_mul_add(a, b, c)`: `{}(a, b, c)` where <math.h> defines `{}` (the \
                 target has a fused instruction, e.g. `-march=native` on x86-64 with FMA; \
                 AArch64), and `a * b + c` otherwise, where the code is bit-identical to \
                 unfused code. The counts below count each as 1 mul + 1 add.",
                opts.float.libm_fn("fma"),
                match opts.float {
                    Float::F64 => "FP_FAST_FMA",
                    Float::F32 => "FP_FAST_FMAF",
                }
            ),
        });
    }
    h
}

/// The table of every traced candidate's emitted counts, the chosen ones starred.
fn count_table(plan: &Plan) -> Vec<String> {
    let mut h = vec![
        String::new(),
        "Emitted operation counts per candidate (the cheapest in mul + add is emitted, *; forward \
         dynamics by `ldlt` on `M` and `c`, or by `aba`, the articulated-body algorithm, which \
         uses neither; frames: the model's own body frames, or its canonical ones, every joint \
         axis z and modified-DH x, `Model::canonical`, which give the same joint-space results):"
            .into(),
        String::new(),
        "| function | mass matrix | nonlinear effects | forward | frames | mul | add | div | sqrt | sincos | mul + add |"
            .into(),
        "|---|---|---|---|---|---:|---:|---:|---:|---:|---:|".into(),
    ];
    for fp in &plan.functions {
        let ch = &fp.choice;
        for cand in &ch.candidates {
            let (m, c) = (&cand.methods, &cand.counts);
            let star = if ch.is_chosen(cand) { " *" } else { "" };
            let name = |x: Option<&str>| x.map_or_else(|| "—".to_string(), |x| format!("`{x}`"));
            h.push(format!(
                "| `{}`{star} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                fp.name,
                name(ch.mass_matrix_method(*m)),
                name(ch.nonlinear_effects_method(*m)),
                name(ch.forward_method(*m)),
                cand.frames.name(),
                c.mul,
                c.add,
                c.div,
                c.sqrt,
                c.sincos,
                c.total()
            ));
        }
    }
    h
}

/// What regrouping did (`None`: it is off).
fn regroup_line(model: &Model, regroup: Option<&RegroupReport>) -> String {
    let Some(r) = regroup else {
        return "Inertial parameters: the model's own (regrouping off).".into();
    };
    format!(
        "Inertial parameters: regrouped for the local-frame algorithms as Khalil and Kleinfinger \
         regroup them (what a joint cannot move is carried by its parent): {} of {} bodies \
         gave, {} → {} non-zero numbers in the spatial inertias{}. The same joint-space \
         dynamics; `base_reaction`, where generated, reads the model's own numbers.",
        r.moved,
        model.dof(),
        r.nonzero_before,
        r.nonzero_after,
        if model.base_kind() == BaseKind::FreeFloating {
            ", the base included"
        } else {
            "; what reaches the fixed base is dropped"
        }
    )
}
