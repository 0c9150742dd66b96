//! The expansion of `kanegen::scene!`: a simulator specialized at compile time for one scene file
//! (`kanegen_scene`, the parser the interpreted simulator uses as `kanegen_sim::scene`).
//!
//! It emits the scene model's generated dynamics ([`kanegen_codegen::generate_items`], type
//! `NameDynamics`, with the scene's base, gravity and payload), a state type `NameState`, a
//! provider `NameModel` of the generated functions ([`crate::scene_provider`]) and `Name`,
//! whose right-hand side is the one of `kanegen_runtime::scene` (what the interpreted
//! `kanegen_sim::simulate::SceneSystem` runs) over the scene's effects as a `const`, so that only
//! the effects the scene names cost time, and whose `run` calls the integrators of
//! `kanegen-runtime` (`kanegen::ode`) on the stack, the code `kanegen_sim::integrate` runs.
//! Payload captures and releases (`[[events]]`) are in [`crate::scene_events`]: one dynamics
//! type per model phase, a run segment by segment, and the capture impulse. A scene error is a
//! compile error naming the key and the scene file. The emitted code names every primitive type
//! and prelude item by its full path ([`kanegen_codegen::paths`]), as the generated dynamics do:
//! the including module may call something `f64`, `Option`, `Ok` or `core`.

use crate::scene_linearize;
use crate::scene_provider::{self, arr, lit, Shape};
use kanegen_codegen::kanegen_dynamics::base::BASE_BODY;
use kanegen_codegen::kanegen_model::{BaseKind, Frame, Model, Placement};
use kanegen_codegen::paths;
use kanegen_scene::{BaseSpec, Drives, EventKind, Integrator, Scene};
use proc_macro2::{Literal, Span, TokenStream};
use quote::{format_ident, quote};
use syn::{Ident, LitStr};

/// The scene file of `scene!(…, "rel")`: the scene, its absolute path and its model's path.
struct Source {
    scene: Scene,
    abs: String,
    model_path: std::path::PathBuf,
}

/// Loads the scene at `rel` (relative to the calling crate), errors naming `rel`.
fn load(rel: &str) -> Result<Source, String> {
    let dir = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| ".".into());
    let path = std::path::Path::new(&dir).join(rel);
    let abs = path.display().to_string();
    let scene_dir = path.parent().unwrap_or(std::path::Path::new("."));
    let clean = |s: String| {
        s.replace(&abs, rel)
            .replace(&format!("{}/", scene_dir.display()), "")
    };
    let scene = Scene::load(&path).map_err(|e| clean(format!("{e:#}")))?;
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{rel}: {e}"))?;
    let model_path = Scene::model_path(&text, scene_dir)
        .ok_or_else(|| format!("{rel}: model: no model path"))?;
    Ok(Source {
        scene,
        abs,
        model_path,
    })
}

/// The model the dynamics are generated for: the scene's payload merged already; its base kind
/// and inertial the scene's; one identity frame on each body loaded by a wrench (its generated
/// `<frame>_placement` gives the body's rotation for an inertial-frame wrench, its Jacobian
/// maps the wrench to the joints for a computed-torque drive and the step Jacobians); one frame
/// at each
/// captured payload's centre of mass (its Jacobian and placement give the capture impulse).
/// Also the frame name of each wrench that has one.
fn scene_model(scene: &Scene, rel: &str) -> Result<(Model, Vec<Option<String>>), String> {
    let mut model = scene.model.clone();
    if let BaseSpec::FreeFloating { inertial, .. } = &scene.base {
        if model.base_inertial() != Some(inertial) {
            model = model
                .with_base_inertial(inertial.clone())
                .map_err(|e| format!("{rel}: base: {e}"))?;
        }
    }
    model = model
        .with_base_kind(base_kind(scene))
        .map_err(|e| format!("{rel}: base: {e}"))?;
    let mut frames: Vec<Frame> = model.frames().to_vec();
    let mut wrench_frames = Vec::new();
    for (k, w) in scene.wrenches.iter().enumerate() {
        let needs = w.body != BASE_BODY;
        wrench_frames.push(needs.then(|| {
            let name = unused_name(&format!("scene_wrench_{k}"), &frames);
            frames.push(Frame {
                name: name.clone(),
                parent: Some(w.body),
                placement: Placement::default(),
            });
            name
        }));
    }
    for (k, e) in scene.events.iter().enumerate() {
        if let EventKind::Capture { payload, .. } = &e.kind {
            frames.push(Frame {
                name: unused_name(&format!("scene_capture_{k}"), &frames),
                parent: Some(e.body),
                placement: Placement {
                    translation: payload.com,
                    ..Placement::default()
                },
            });
        }
    }
    let model = model
        .with_frames(frames)
        .map_err(|e| format!("{rel}: model frames: {e}"))?;
    Ok((model, wrench_frames))
}

/// `stem`, or `stem` with underscores appended until no frame of `frames` has the name: the
/// frames `scene!` adds never clash with the model's own.
fn unused_name(stem: &str, frames: &[Frame]) -> String {
    let mut name = stem.to_string();
    while frames.iter().any(|f| f.name == name) {
        name.push('_');
    }
    name
}

fn base_kind(scene: &Scene) -> BaseKind {
    if scene.is_floating() {
        BaseKind::FreeFloating
    } else {
        BaseKind::Fixed
    }
}

/// The generated dynamics: the items of `NameDynamics` and of the types of later model phases,
/// the type of each phase (phase 0 first), and whether they carry the derivatives.
fn dynamics(
    scene: &Scene,
    model: &Model,
    runtime: &syn::Path,
    dyn_name: &str,
    rel: &str,
) -> Result<(TokenStream, Vec<Ident>, bool), String> {
    let mut opts = kanegen_codegen::Options::new(dyn_name.to_string());
    opts.gravity = scene.gravity;
    opts.base = Some(base_kind(scene));
    opts.libm_path = "kanegen::__private::libm".into();
    opts.libm_tokens = Some(quote!(#runtime::__private::libm));
    opts.runtime_path = "kanegen::__private::runtime".into();
    opts.runtime_tokens = Some(quote!(#runtime::__private::runtime));
    opts.payload_name = format!("{dyn_name}Payload");
    opts.op_count_name = format!("{dyn_name}OpCount");
    let g = kanegen_codegen::generate_items(model, &opts).map_err(|e| format!("{rel}: {e}"))?;
    let (phase_tys, phase_items) =
        crate::scene_events::phase_dynamics(scene, &opts, dyn_name, rel)?;
    let (items, derivatives) = (&g.items, g.has_derivatives());
    Ok((quote!(#items #phase_items), phase_tys, derivatives))
}

/// Sizes and names of the state of `Name`.
struct Layout {
    n: usize,
    nq: usize,
    nv: usize,
    dim: usize,
    floating: bool,
    flexible: bool,
    state_ty: Ident,
    /// `v` (free-floating) or `qd`.
    vname: Ident,
}

impl Layout {
    fn of(scene: &Scene, name: &Ident) -> Layout {
        let n = scene.dof();
        let floating = scene.is_floating();
        let flexible = scene.flexible.is_some();
        let (nq, nv) = if floating { (n + 7, n + 6) } else { (n, n) };
        Layout {
            n,
            nq,
            nv,
            dim: nq + nv + if flexible { 2 * n } else { 0 },
            floating,
            flexible,
            state_ty: format_ident!("{}State", name),
            vname: format_ident!("{}", if floating { "v" } else { "qd" }),
        }
    }
}

/// The items of `scene!(runtime; name, "rel")`; `Err` is the compile error's message.
pub fn expand(runtime: &syn::Path, name: &Ident, rel: &str) -> Result<TokenStream, String> {
    let src = load(rel)?;
    let scene = &src.scene;
    let (model, wrench_frames) = scene_model(scene, rel)?;
    let dyn_name = format!("{name}Dynamics");
    let (dyn_items, phase_tys, has_derivatives) = dynamics(scene, &model, runtime, &dyn_name, rel)?;
    let layout = Layout::of(scene, name);
    let model_ty = format_ident!("{}Model", name);
    let shape = Shape {
        rt: quote!(#runtime::__private::runtime),
        ty: &model_ty,
        phases: &phase_tys,
        n: layout.n,
        bodies: scene.model.dof(),
        nq: layout.nq,
        nv: layout.nv,
        wrench_frames: &wrench_frames,
    };
    let provider = scene_provider::provider(scene, &shape).map_err(|e| format!("{rel}: {e}"))?;
    let rt = &shape.rt;
    let state = state_items(scene, &layout, name, &dyn_name);
    let profiles = scene.wrench_profiles();
    let linearize =
        scene_linearize::availability(scene, &scene.effects(&profiles), has_derivatives);
    let (derivatives, step_jacobians) = match linearize {
        Ok(()) => (
            scene_linearize::derivatives(scene, &shape),
            scene_linearize::step_jacobians(
                rt,
                scene,
                &layout.state_ty,
                &model_ty,
                (layout.n, layout.dim, scene.effects(&profiles).floating),
            ),
        ),
        Err(_) => (TokenStream::new(), TokenStream::new()),
    };
    let simulator = simulator_items(runtime, (name, rel), scene, &layout, &model_ty, &phase_tys);
    let docs = Docs::of(scene, &model, &layout, name, rel);
    let (struct_doc, integrator_doc) = (docs.scene, docs.integrator);
    let linearize_doc = scene_linearize::doc(name, &linearize);
    let include_scene = crate::include_file(&src.abs);
    let include_model = crate::include_file(&src.model_path.display().to_string());
    let usize = paths::primitive("usize");
    let model_doc = format!(
        " The generated dynamics of [`{name}`] as the provider of its right-hand side, in the \
         model phase `.0` (0 before the first event, `k` after event `k − 1`)."
    );
    Ok(quote! {
        #include_scene
        #include_model

        #dyn_items
        #state

        #[doc = #model_doc]
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct #model_ty(pub #usize);

        #[allow(clippy::unreadable_literal, clippy::excessive_precision)]
        #provider

        #derivatives

        impl #rt::scene::SceneModel for #model_ty {
            const EFFECTS: #rt::scene::SceneEffects<'static> = #name::EFFECTS;
        }

        #[doc = #struct_doc]
        #[doc = ""]
        #[doc = #integrator_doc]
        #[doc = ""]
        #[doc = #linearize_doc]
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct #name;

        #simulator

        impl #name {
            #step_jacobians
        }
    })
}

/// The documentation of `Name`: the scene, its effects and its integrator.
struct Docs {
    scene: String,
    integrator: String,
}

impl Docs {
    fn of(scene: &Scene, model: &Model, l: &Layout, name: &Ident, rel: &str) -> Docs {
        let (sim, n, floating) = (&scene.simulation, l.n, l.floating);
        let integrator_doc = match sim.integrator {
            Integrator::Dopri5 => format!(
                " The scene's integrator: adaptive Dormand–Prince 5(4) (`kanegen::ode::dopri5`, \
                 tolerance {:e}, first step {} s, dense output every {} s). [`{name}::step`] is one \
                 fixed RK4 step (an adaptive step has no fixed size).",
                sim.tolerance,
                sim.step,
                sim.step * sim.output_every as f64
            ),
            Integrator::Rosenbrock => format!(
                " The scene's integrator: adaptive Rodas4, the stiff Rosenbrock method \
                 (`kanegen::ode::rosenbrock`, tolerance {:e}, first step {} s, steps landing on the \
                 output times every {} s). [`{name}::step`] is one Rodas4 step with no step control.",
                sim.tolerance,
                sim.step,
                sim.step * sim.output_every as f64
            ),
            Integrator::Rk4 => format!(
                " The scene's integrator: fixed-step RK4 (`kanegen::ode::rk4`), step {} s, a sample \
                 every {} steps.",
                sim.step, sim.output_every
            ),
            Integrator::Midpoint => format!(
                " The scene's integrator: the fixed-step Lie-group implicit midpoint rule \
                 (`kanegen::ode::midpoint`), step {} s, a sample every {} steps.",
                sim.step, sim.output_every
            ),
        };
        let effects = {
            let mut e = Vec::new();
            if let Some(g) = scene.gravity {
                e.push(format!("gravity {g:?}"));
            }
            e.push(
                match &scene.drives {
                    Drives::None => "no drives",
                    Drives::Constant { .. } => "constant drive torques",
                    Drives::Pd { .. } => "joint PD drives",
                    Drives::ComputedTorque { .. } => "computed-torque drives along a quintic",
                }
                .to_string(),
            );
            if scene.damping.is_some() {
                e.push("joint viscous damping".into());
            }
            if scene.coulomb.is_some() {
                e.push("Coulomb drive friction".into());
            }
            if scene.rotor.is_some() {
                e.push("reflected rotor inertia".into());
            }
            if scene.flexible.is_some() {
                e.push("flexible joints (Spong)".into());
            }
            if !scene.wrenches.is_empty() {
                e.push(format!("{} external wrench(es)", scene.wrenches.len()));
            }
            e.join(", ")
        };
        let struct_doc = format!(
            " The simulator of scene `{rel}` (model `{}`, N = {n}, {} base): {effects}.",
            kanegen_codegen::header::doc_safe(model.name()),
            if floating { "free-floating" } else { "fixed" },
        );
        Docs {
            scene: struct_doc,
            integrator: integrator_doc,
        }
    }
}

/// `NameState` with its conversions to and from the flat state vector.
fn state_items(scene: &Scene, l: &Layout, name: &Ident, dyn_name: &str) -> TokenStream {
    let n = l.n;
    let (nl, nql, nvl) = (
        Literal::usize_unsuffixed(n),
        Literal::usize_unsuffixed(l.nq),
        Literal::usize_unsuffixed(l.nv),
    );
    let dim = Literal::usize_unsuffixed(l.dim);
    let (state_ty, vname) = (&l.state_ty, &l.vname);
    let f64 = paths::primitive("f64");
    let state_doc = if l.flexible {
        format!(
            " The state of [`{name}`]: link positions `q` and rates `qd`, motor positions \
             `theta` and rates `thetad` ({n} each; Spong's flexible joints). A derivative has \
             the same layout."
        )
    } else if l.floating {
        format!(
            " The state of [`{name}`]: `q = [p₀ (3), quaternion x y z w (4), joints ({n})]` and \
             `v = [v_b (3), ω_b (3), q̇ ({n})]` (base coordinates), the free-flyer layout of \
             [`{dyn_name}`]. A derivative has the same layout (`q` holds `[ṗ₀, q̇uat, q̇]`)."
        )
    } else {
        format!(
            " The state of [`{name}`]: joint positions `q` and rates `qd` ({n} each). A \
             derivative has the same layout."
        )
    };
    let vdoc = if l.floating {
        " Base linear and angular velocity (base coordinates), joint rates."
    } else {
        " Joint rates."
    };
    let motor_fields = if l.flexible {
        quote! {
            /// Motor positions (link side, `θ`).
            pub theta: [#f64; #nl],
            /// Motor rates.
            pub thetad: [#f64; #nl],
        }
    } else {
        quote!()
    };
    let (to_array, from_array) = if l.flexible {
        let two = Literal::usize_unsuffixed(2 * n);
        let three = Literal::usize_unsuffixed(3 * n);
        (
            quote! {
                ::core::array::from_fn(|i| match i / #nl {
                    0 => self.q[i],
                    1 => self.qd[i - #nl],
                    2 => self.theta[i - #two],
                    _ => self.thetad[i - #three],
                })
            },
            quote! {
                #state_ty {
                    q: ::core::array::from_fn(|i| x[i]),
                    qd: ::core::array::from_fn(|i| x[#nl + i]),
                    theta: ::core::array::from_fn(|i| x[#two + i]),
                    thetad: ::core::array::from_fn(|i| x[#three + i]),
                }
            },
        )
    } else {
        (
            quote!(::core::array::from_fn(|i| if i < #nql { self.q[i] } else { self.#vname[i - #nql] })),
            quote! {
                #state_ty {
                    q: ::core::array::from_fn(|i| x[i]),
                    #vname: ::core::array::from_fn(|i| x[#nql + i]),
                }
            },
        )
    };
    let x0 = arr(&scene.initial_state());
    quote! {
        #[doc = #state_doc]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct #state_ty {
            /// Positions.
            pub q: [#f64; #nql],
            #[doc = #vdoc]
            pub #vname: [#f64; #nvl],
            #motor_fields
        }

        impl #state_ty {
            /// The state as one vector `[q, v]` (the interpreted simulator's layout).
            #[must_use]
            pub fn to_array(&self) -> [#f64; #dim] {
                #to_array
            }

            /// The state of a vector `[q, v]`.
            #[must_use]
            pub fn from_array(x: &[#f64; #dim]) -> Self {
                #from_array
            }

            /// The scene's initial state.
            const INITIAL: [#f64; #dim] = #x0;
        }
    }
}

/// The integrators `run` and `step` call, and their scratch on the stack.
struct Methods {
    run_fn: Ident,
    step_fn: Ident,
    run_scratch: TokenStream,
    step_scratch: TokenStream,
    options: TokenStream,
}

impl Methods {
    fn of(sim: &kanegen_scene::SimulationSpec, ode: &TokenStream, dim: &Literal) -> Methods {
        // The scratch of `run` (of the scene's method) and of `step` (RK4 for a dopri5 scene),
        // sized by the runtime for this state.
        let (run_mod, step_mod, step_fn) = match sim.integrator {
            Integrator::Rk4 => ("rk4", "rk4", "rk4_step"),
            Integrator::Dopri5 => ("dopri5", "rk4", "rk4_step"),
            Integrator::Midpoint => ("midpoint", "midpoint", "midpoint_step"),
            Integrator::Rosenbrock => ("rosenbrock", "rosenbrock", "rosenbrock_step"),
        };
        let scratch = |module: &str| {
            let module = format_ident!("{module}");
            let pivots = if module == "rosenbrock" {
                dim.clone()
            } else {
                Literal::usize_unsuffixed(0)
            };
            quote!(#ode::ArrayScratch::<{ #ode::#module::scratch_len(#dim) }, #pivots>::new())
        };
        let (max_step, f64) = (lit(sim.max_step), paths::primitive("f64"));
        let options = if matches!(sim.integrator, Integrator::Rk4 | Integrator::Midpoint) {
            quote! {
                #ode::Rk4Options {
                    step: Self::STEP,
                    output_every: Self::OUTPUT_EVERY,
                }
            }
        } else {
            quote! {
                #ode::Dopri5Options {
                    tolerance: Self::TOLERANCE,
                    max_step: #max_step,
                    initial_step: Self::STEP,
                    output_interval: Self::STEP * Self::OUTPUT_EVERY as #f64,
                }
            }
        };
        Methods {
            run_fn: format_ident!("{run_mod}"),
            step_fn: format_ident!("{step_fn}"),
            run_scratch: scratch(run_mod),
            step_scratch: scratch(step_mod),
            options,
        }
    }
}

/// The scene's right-hand side in model phase `phase` as an `ode::System`
/// (`kanegen_runtime::scene::SceneOde`: the one right-hand side over the provider `model_ty`
/// and its `SceneModel::EFFECTS`, in the memory `work` of the enclosing function).
fn system(rt: &TokenStream, model_ty: &Ident, phase: TokenStream) -> TokenStream {
    quote! {
        #rt::scene::SceneOde {
            dynamics: #model_ty(#phase),
            work: &mut work,
        }
    }
}

/// The body of `run`: one integration over the scene's duration, or (with events) one a
/// segment between events with the event applied at its end.
fn run_body(
    runtime: &syn::Path,
    scene: &Scene,
    l: &Layout,
    model_ty: &Ident,
    m: &Methods,
) -> TokenStream {
    let rt = quote!(#runtime::__private::runtime);
    let (run_fn, options) = (&m.run_fn, &m.options);
    let integrate = |t0: TokenStream, t1: TokenStream, obs: TokenStream| quote!(#rt::ode::#run_fn(&mut sys, #t0, #t1, &#options, &mut x, &mut scratch, #obs));
    if scene.events.is_empty() {
        let call = integrate(quote!(0.0), quote!(Self::DURATION), quote!(obs));
        let sys = system(&rt, model_ty, quote!(0));
        quote! {
            let mut sys = #sys;
            #call
        }
    } else {
        let call = integrate(quote!(t0), quote!(t1), quote!(&mut obs));
        let sys = system(&rt, model_ty, quote!(phase));
        crate::scene_events::run_segments(runtime, &l.state_ty, &sys, &call)
    }
}

/// The signature of `rhs` (`rhs_in` with the model phase as its first argument when the scene
/// has events) and the phase it runs in.
fn rhs_signature(scene: &Scene, state_ty: &Ident) -> (TokenStream, TokenStream) {
    let (f64, usize) = (paths::primitive("f64"), paths::primitive("usize"));
    if scene.events.is_empty() {
        let sig = quote! {
            /// The right-hand side `ẋ = f(t, x)` with the scene's effects only.
            #[must_use]
            pub fn rhs(t: #f64, s: &#state_ty) -> #state_ty
        };
        (sig, quote!(0))
    } else {
        let sig = quote! {
            /// The right-hand side `ẋ = f(t, x)` with the scene's effects only, with the model
            /// of `phase` (0 before the first event, `k` after event `k − 1`).
            #[must_use]
            pub fn rhs_in(phase: #usize, t: #f64, s: &#state_ty) -> #state_ty
        };
        (sig, quote!(phase))
    }
}

/// The doc of `step` for the scene's integrator.
fn step_doc(integrator: Integrator) -> &'static str {
    match integrator {
        Integrator::Rosenbrock => {
            " One Rodas4 step of size `h` from `(t, state)` (no step control)."
        }
        Integrator::Midpoint => {
            " One implicit midpoint step of size `h` from `(t, state)` (the scene's integrator)."
        }
        _ => {
            " One fixed RK4 step of size `h` from `(t, state)`, then the projection (the \
             quaternion renormalized on a free-floating base)."
        }
    }
}

/// `impl Name`: the scene's constants and effects, `initial_state`, `rhs`, `step`, `run` and
/// (with events) the event items.
fn simulator_items(
    runtime: &syn::Path,
    (name, rel): (&Ident, &str),
    scene: &Scene,
    l: &Layout,
    model_ty: &Ident,
    phase_tys: &[Ident],
) -> TokenStream {
    let rt = quote!(#runtime::__private::runtime);
    let ode = quote!(#rt::ode);
    let dim = Literal::usize_unsuffixed(l.dim);
    let state_ty = &l.state_ty;
    let m = Methods::of(&scene.simulation, &ode, &dim);
    let step_system = system(&rt, model_ty, quote!(0));
    let run_body = run_body(runtime, scene, l, model_ty, &m);
    let events =
        crate::scene_events::event_items(runtime, scene, state_ty, &phase_tys[0], phase_tys);
    let (rhs_sig, phase) = rhs_signature(scene, state_ty);
    let step_doc = step_doc(scene.simulation.integrator);
    let constants = constants(&rt, scene, l, rel);
    let (step_fn, run_scratch, step_scratch) = (&m.step_fn, &m.run_scratch, &m.step_scratch);
    let f64 = paths::primitive("f64");
    let step_result = paths::result_type(&quote!(()), &quote!(#ode::Stop));
    let run_result = paths::result_type(&quote!(#ode::Stats), &quote!(#ode::Stop));
    let (done, sample) = (paths::ok(quote!(())), paths::ok(quote!(x)));
    quote! {
        #[allow(clippy::too_many_lines, clippy::unreadable_literal, clippy::excessive_precision)]
        impl #name {
            #constants

            /// The scene's initial state.
            #[must_use]
            pub fn initial_state() -> #state_ty {
                #state_ty::from_array(&#state_ty::INITIAL)
            }

            #rhs_sig {
                let mut dx = [0.0f64; #dim];
                let mut work = [0.0f64; Self::WORK];
                #rt::scene::deriv(&mut #model_ty(#phase), &Self::EFFECTS, t, &s.to_array(), &mut dx, &mut work);
                #state_ty::from_array(&dx)
            }

            #[doc = #step_doc]
            ///
            /// # Errors
            /// A `kanegen::ode::Stop` when the new state is not finite (or the midpoint
            /// iterations do not converge); `state` is then unchanged.
            pub fn step(
                t: #f64,
                state: &mut #state_ty,
                h: #f64,
            ) -> #step_result {
                let mut x = state.to_array();
                let mut work = [0.0f64; Self::WORK];
                #ode::#step_fn(&mut #step_system, t, h, &mut x, &mut #step_scratch)?;
                *state = #state_ty::from_array(&x);
                #done
            }

            /// Integrates the scene from its initial state over its duration with its
            /// integrator, calling `observe(t, &state)` at the scene's output times (the
            /// interpreted simulator's samples), and returns the work done.
            ///
            /// # Errors
            /// A `kanegen::ode::Stop` when the state becomes non-finite (or, dopri5, the step
            /// size underflows or its error estimate overflows); the observer has seen every
            /// sample up to there.
            pub fn run(
                mut observe: impl ::core::ops::FnMut(#f64, &#state_ty),
            ) -> #run_result {
                let mut x = Self::initial_state().to_array();
                let mut scratch = #run_scratch;
                let mut work = [0.0f64; Self::WORK];
                #[allow(unused_mut)]
                let mut obs = |t: #f64, x: &[#f64]| {
                    if let #sample = <&[#f64; #dim]>::try_from(x) {
                        observe(t, &#state_ty::from_array(x));
                    }
                };
                #run_body
            }

            #events
        }
    }
}

/// The constants of `Name`: sizes, the scene file, the integrator's settings and the scene's
/// effects (`EFFECTS`, the data of the right-hand side) with the length of its work memory.
fn constants(rt: &TokenStream, scene: &Scene, l: &Layout, rel: &str) -> TokenStream {
    let sim = &scene.simulation;
    let profiles = scene.wrench_profiles();
    let effects = scene_provider::effects(rt, &scene.effects(&profiles));
    let (duration, step, tolerance) = (lit(sim.duration), lit(sim.step), lit(sim.tolerance));
    let every = Literal::usize_unsuffixed(sim.output_every);
    let (nl, dim) = (
        Literal::usize_unsuffixed(l.n),
        Literal::usize_unsuffixed(l.dim),
    );
    let rel_lit = LitStr::new(rel, Span::call_site());
    let (f64, usize, str) = (
        paths::primitive("f64"),
        paths::primitive("usize"),
        paths::static_str(),
    );
    let dim_doc = if l.flexible {
        format!(
            " Length of the flat state vector ({} + {} + {} + {}).",
            l.nq, l.nv, l.n, l.n
        )
    } else {
        format!(" Length of the flat state vector ({} + {}).", l.nq, l.nv)
    };
    quote! {
            /// Joint degrees of freedom.
            pub const N: #usize = #nl;
            #[doc = #dim_doc]
            pub const DIM: #usize = #dim;
            /// The scene file (relative to the crate).
            pub const SCENE: #str = #rel_lit;
            /// Simulated duration, s.
            pub const DURATION: #f64 = #duration;
            /// Step (RK4), or first step tried (dopri5), s.
            pub const STEP: #f64 = #step;
            /// dopri5 tolerance (`rtol = atol`; unused by RK4 scenes).
            pub const TOLERANCE: #f64 = #tolerance;
            /// An output sample every this many steps (RK4), or every `OUTPUT_EVERY · STEP`
            /// seconds (dopri5).
            pub const OUTPUT_EVERY: #usize = #every;
            /// The scene's effects: the data of its right-hand side
            /// (`kanegen::runtime::scene::deriv`).
            pub const EFFECTS: #rt::scene::SceneEffects<'static> = #effects;
            /// Length of the work memory of the right-hand side.
            pub const WORK: #usize = Self::EFFECTS.work_len();
    }
}

#[cfg(test)]
mod tests {
    /// Every scene of `scenes/` and `tests/data/scenes/` (every integrator, drive and effect,
    /// events, wrenches, flexible joints, step Jacobians) expands to code that names every
    /// primitive type and prelude item by its full path (`kanegen_codegen::paths`).
    #[test]
    fn expansion_names_primitives_and_prelude_items_by_full_paths() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let runtime: syn::Path = syn::parse_quote!(::kanegen);
        let name = quote::format_ident!("Scene");
        let mut scenes = 0;
        for dir in ["scenes", "tests/data/scenes"] {
            for entry in std::fs::read_dir(root.join(dir)).unwrap() {
                let entry = entry.unwrap();
                if entry.file_type().unwrap().is_dir() {
                    continue; // scenes/sweeps: sweep files, not scenes
                }
                let file = entry.file_name().into_string().unwrap();
                let rel = format!("../{dir}/{file}");
                let items = super::expand(&runtime, &name, &rel).unwrap();
                let unqualified = kanegen_codegen::paths::unqualified(items).unwrap();
                assert!(unqualified.is_empty(), "{rel}: {unqualified:?}");
                scenes += 1;
            }
        }
        assert!(scenes > 20, "{scenes} scenes");
    }
}
