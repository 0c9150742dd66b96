//! The body frames the generator traces in (`choose::BodyFrames`): canonical frames win on
//! chains with general geometry, give the same joint-space results, and are never traced where
//! the inputs or outputs are tied to the bodies' own frames.

use kanegen_codegen::choose::{choose, BodyFrames};
use kanegen_codegen::{generate_items, Options};
use kanegen_dynamics::MassMatrixMethod;
use kanegen_model::random::{random_chain, ChainSpec};
use kanegen_trace::Function;

fn chain(n: usize) -> kanegen_model::Model {
    random_chain(
        &ChainSpec {
            n,
            ..Default::default()
        },
        1000 + n as u64,
    )
}

/// On random chains the canonical candidate is chosen and needs fewer operations, and it
/// evaluates to the same `(M, c)` as the model-frame one (to rounding).
#[test]
fn canonical_frames_win_on_general_chains_with_the_same_results() {
    for n in [2, 5, 8] {
        let model = chain(n);
        let f = Function::MassMatrixAndNonlinearEffects;
        let on = Options::new("Arm");
        let off = Options {
            canonical: false,
            ..on.clone()
        };
        let (c_on, t_on) = choose(&model, f, MassMatrixMethod::Crba, &on).unwrap();
        let (c_off, t_off) = choose(&model, f, MassMatrixMethod::Crba, &off).unwrap();
        assert_eq!(c_on.frames, BodyFrames::Canonical, "N = {n}");
        assert!(c_off
            .candidates
            .iter()
            .all(|c| c.frames == BodyFrames::Model));
        let (a, b) = (c_on.counts().total(), c_off.counts().total());
        assert!(a < b, "N = {n}: canonical {a} against own frames {b}");
        // Both candidates read q then q̇; the same random state for both.
        assert_eq!(t_on.inputs, t_off.inputs);
        let x: Vec<f64> = (0..t_on.inputs.len())
            .map(|i| (1.7 * i as f64 + 0.3).sin() * 2.0)
            .collect();
        let (ya, yb) = (t_on.trace.eval(&x), t_off.trace.eval(&x));
        let scale = yb.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        let err = ya
            .iter()
            .zip(&yb)
            .fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()));
        assert!(err < 1e-12 * scale, "N = {n}: {err:e} of {scale:e}");
    }
}

/// A runtime payload (given in its body's own frame), body-frame wrenches and the frame
/// functions stay in the model's frames; the header says which frames each function took.
#[test]
fn frame_bound_functions_stay_in_the_model_frames() {
    let model = chain(4);
    let g = generate_items(&model, &Options::new("Arm")).unwrap();
    for ch in &g.choices {
        let bound = matches!(ch.function, Function::ForwardDynamicsWithWrenches);
        if bound {
            assert_eq!(ch.frames, BodyFrames::Model, "{}", ch.function.name());
        }
        assert!(ch
            .candidates
            .iter()
            .all(|c| !bound || c.frames == BodyFrames::Model));
    }
    assert!(g
        .header
        .iter()
        .any(|l| l.contains("| frames |") && l.contains("| function |")));
    let payload = generate_items(
        &model,
        &Options {
            runtime_payload: true,
            ..Options::new("Arm")
        },
    )
    .unwrap();
    assert!(payload
        .choices
        .iter()
        .all(|ch| ch.candidates.iter().all(|c| c.frames == BodyFrames::Model)));
}
