//! Payload capture and release (`[[events]]`) in `kanegen::scene!`, as the interpreted
//! simulator does them (`kanegen_sim::events`): one generated dynamics type per distinct model
//! phase, a run integrated segment by segment between the event times, and at a capture the
//! impulse `H' ν⁺ = H ν⁻ + J_pᵀ h_p` (`kanegen_runtime::scene::capture_velocity`) over the
//! generated mass matrices of the phases before and after and the generated Jacobian and
//! placement of a frame at the payload's centre of mass.

use crate::scene_provider::{arr, lit};
use kanegen_codegen::kanegen_model::{BaseKind, Model};
use kanegen_codegen::paths;
use kanegen_scene::{BaseSpec, EventKind, Scene};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use syn::Ident;

/// The dynamics type of each phase (phase 0 is `NameDynamics`, phase `k` follows event
/// `k − 1`; a phase whose model is an earlier phase's reuses its type) and the items of the
/// types it adds (no frames, the scene's base and gravity).
pub fn phase_dynamics(
    scene: &Scene,
    opts: &kanegen_codegen::Options,
    dyn_name: &str,
    rel: &str,
) -> Result<(Vec<Ident>, TokenStream), String> {
    let mut tys = vec![format_ident!("{}", dyn_name)];
    let mut models: Vec<&Model> = vec![&scene.model];
    let mut items = TokenStream::new();
    for (k, e) in scene.events.iter().enumerate() {
        if let Some(j) = models.iter().position(|m| **m == e.model) {
            tys.push(tys[j].clone());
            models.push(&e.model);
            continue;
        }
        let mut model = e.model.clone();
        if let BaseSpec::FreeFloating { inertial, .. } = &scene.base {
            if model.base_inertial() != Some(inertial) {
                model = model
                    .with_base_inertial(inertial.clone())
                    .map_err(|err| format!("{rel}: base: {err}"))?;
            }
        }
        let model = model
            .with_base_kind(BaseKind::FreeFloating)
            .and_then(|m| m.with_frames(Vec::new()))
            .map_err(|err| format!("{rel}: events[{k}]: {err}"))?;
        let name = format!("{dyn_name}Phase{}", k + 1);
        let mut o = opts.clone();
        o.type_name = name.clone();
        o.payload_name = format!("{name}Payload");
        o.op_count_name = format!("{name}OpCount");
        let g = kanegen_codegen::generate_items(&model, &o)
            .map_err(|err| format!("{rel}: events[{k}]: {err}"))?;
        items.extend(g.items);
        tys.push(format_ident!("{}", name));
        models.push(&e.model);
    }
    Ok((tys, items))
}

/// The body of `run` for a scene with events: one integration (`call`, from `t0` to `t1` of
/// `sys`, the system of `phase`, with `x`) per segment between the event times, the event
/// applied between segments.
pub fn run_segments(
    runtime: &syn::Path,
    state_ty: &Ident,
    sys: &TokenStream,
    call: &TokenStream,
) -> TokenStream {
    let done = paths::ok(quote!(stats));
    quote! {
        let mut stats = #runtime::__private::runtime::ode::Stats::default();
        let mut t0 = 0.0;
        for phase in 0..=Self::EVENT_TIMES.len() {
            let t1 = if phase < Self::EVENT_TIMES.len() {
                Self::EVENT_TIMES[phase]
            } else {
                Self::DURATION
            };
            if phase > 0 {
                let mut st = #state_ty::from_array(&x);
                Self::apply_event(phase - 1, &mut st);
                x = st.to_array();
            }
            let mut sys = #sys;
            stats.accumulate(#call?);
            t0 = t1;
        }
        #done
    }
}

/// `EVENT_TIMES`, `phase_at`, `rhs` (through `rhs_in`) and `apply_event` of a scene with events
/// (nothing without).
pub fn event_items(
    runtime: &syn::Path,
    scene: &Scene,
    state_ty: &Ident,
    dyn_ty: &Ident,
    phase_tys: &[Ident],
) -> TokenStream {
    if scene.events.is_empty() {
        return TokenStream::new();
    }
    let times: Vec<f64> = scene.events.iter().map(|e| e.time).collect();
    let count = Literal::usize_unsuffixed(times.len());
    let times = arr(&times);
    let rt = quote!(#runtime::__private::runtime);
    let (f64, usize) = (paths::primitive("f64"), paths::primitive("usize"));
    let arms = scene.events.iter().enumerate().map(|(k, e)| {
        let kl = Literal::usize_unsuffixed(k);
        match &e.kind {
            EventKind::Release { .. } => quote!(#kl => {}),
            EventKind::Capture { payload, v, omega } => {
                let (before, after) = (&phase_tys[k], &phase_tys[k + 1]);
                let frame = format!("scene_capture_{k}");
                let (jac, pl) = (
                    format_ident!("{}_jacobian", frame),
                    format_ident!("{}_placement", frame),
                );
                let (m, v, w) = (lit(payload.mass), arr(v), arr(omega));
                let rows = payload.inertia.iter().map(|r| arr(r));
                quote!(#kl => {
                    const PAYLOAD: #rt::scene::CapturedPayload = #rt::scene::CapturedPayload {
                        mass: #m,
                        inertia: [#(#rows),*],
                        v: #v,
                        omega: #w,
                    };
                    s.v = #rt::scene::capture_velocity(
                        #before::mass_matrix(&s.q),
                        #after::mass_matrix(&s.q),
                        Self::EFFECTS.armature,
                        &#dyn_ty::#pl(&s.q).1,
                        &#dyn_ty::#jac(&s.q),
                        &PAYLOAD,
                        &s.v,
                    );
                })
            }
        }
    });
    quote! {
        /// The event times (`[[events]]`), s.
        pub const EVENT_TIMES: [#f64; #count] = #times;

        /// The model phase at `t`: the number of events at or before `t` (at an event time, the
        /// model after it).
        #[must_use]
        pub fn phase_at(t: #f64) -> #usize {
            Self::EVENT_TIMES.iter().filter(|te| **te <= t).count()
        }

        /// The right-hand side `ẋ = f(t, x)` with the scene's effects only, with the model of
        /// [`Self::phase_at`]`(t)`.
        #[must_use]
        pub fn rhs(t: #f64, s: &#state_ty) -> #state_ty {
            Self::rhs_in(Self::phase_at(t), t, s)
        }

        /// Applies event `k` to the state at its time: a capture replaces `v` by the solution
        /// of the plastic-impact equation `H' v⁺ = H v⁻ + J_pᵀ h_p` (total linear and angular
        /// momentum conserved); a release keeps the state (the model of the next phase lets
        /// go of the payload).
        pub fn apply_event(k: #usize, s: &mut #state_ty) {
            match k {
                #(#arms)*
                _ => {}
            }
        }
    }
}
