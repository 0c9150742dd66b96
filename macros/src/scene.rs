//! The expansion of `kanegen::scene!`: a simulator specialized at compile time for one scene file
//! (`kanegen_scene`, the parser the interpreted simulator uses as `kanegen_sim::scene`).
//!
//! It emits the scene model's generated dynamics ([`kanegen_codegen::generate_items`], type
//! `NameDynamics`, with the scene's base, gravity and payload), a state type `NameState` and
//! `Name`, whose right-hand side holds only the effects the scene names — drives, joint damping,
//! external wrenches — written as the interpreted `kanegen_sim::simulate::SceneSystem` writes
//! them, and whose `run` calls the integrators of `kanegen-runtime` (`kanegen::ode`) on the
//! stack, the code `kanegen_sim::integrate` runs. Payload captures and releases (`[[events]]`) are in
//! [`crate::scene_events`]: one dynamics type per model phase, a run segment by segment, and the
//! capture impulse. A scene error is a compile error naming the key and the scene file.

use kanegen_codegen::kanegen_model::{BaseKind, Frame, Placement};
use kanegen_scene::{BaseSpec, Drives, EventKind, Integrator, Scene, WrenchProfile};
use proc_macro2::{Literal, Span, TokenStream};
use quote::{format_ident, quote};
use syn::{Ident, LitStr};

/// `f64` literal.
fn lit(x: f64) -> Literal {
    Literal::f64_suffixed(x)
}

fn arr(v: &[f64]) -> TokenStream {
    let v = v.iter().map(|x| lit(*x));
    quote!([#(#v),*])
}

fn rows(v: &[[f64; 3]]) -> TokenStream {
    let v = v.iter().map(|r| arr(r));
    quote!([#(#v),*])
}

/// The expression of a wrench's `(force, moment)` at time `t`: constant, or interpolated in
/// its table (`kanegen::ode::table`, which the interpreted `SceneWrench::value_at` calls).
fn wrench_value(runtime: &syn::Path, profile: &WrenchProfile) -> TokenStream {
    match profile {
        WrenchProfile::Constant { force, moment } => {
            let (f, m) = (arr(force), arr(moment));
            quote!((#f, #m))
        }
        WrenchProfile::Table {
            time,
            force,
            moment,
        } => {
            let kl = Literal::usize_unsuffixed(time.len());
            let (tt, f, m) = (arr(time), rows(force), rows(moment));
            quote! {{
                const TIME: [f64; #kl] = #tt;
                const FORCE: [[f64; 3]; #kl] = #f;
                const MOMENT: [[f64; 3]; #kl] = #m;
                #runtime::__private::runtime::ode::table(t, &TIME, &FORCE, &MOMENT)
            }}
        }
    }
}

/// The items of `scene!(runtime; name, "rel")`; `Err` is the compile error's message.
pub fn expand(runtime: &syn::Path, name: &Ident, rel: &str) -> Result<TokenStream, String> {
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
    let sim = &scene.simulation;
    let computed_torque = matches!(scene.drives, Drives::ComputedTorque { .. });

    // The model: the scene's payload is merged already; its base kind and inertial are the
    // scene's; one identity frame on each body loaded by an inertial-frame wrench gives the
    // body's rotation (its generated `<frame>_placement`); with a computed-torque drive every
    // wrench gets one, whose Jacobian maps the wrench to the joints.
    let floating = scene.is_floating();
    let mut model = scene.model.clone();
    if let BaseSpec::FreeFloating { inertial, .. } = &scene.base {
        if model.base_inertial() != Some(inertial) {
            model = model
                .with_base_inertial(inertial.clone())
                .map_err(|e| format!("{rel}: base: {e}"))?;
        }
    }
    let kind = if floating {
        BaseKind::FreeFloating
    } else {
        BaseKind::Fixed
    };
    model = model
        .with_base_kind(kind)
        .map_err(|e| format!("{rel}: base: {e}"))?;
    let mut frames: Vec<Frame> = model.frames().to_vec();
    let mut wrench_frames = Vec::new();
    for (k, w) in scene.wrenches.iter().enumerate() {
        let needs = (w.frame == kanegen_codegen::kanegen_dynamics::LoadFrame::Base
            || computed_torque)
            && w.body != kanegen_codegen::kanegen_dynamics::base::BASE_BODY;
        if needs {
            let fname = format!("scene_wrench_{k}");
            frames.push(Frame {
                name: fname.clone(),
                parent: Some(w.body),
                placement: Placement::default(),
            });
            wrench_frames.push(Some(fname));
        } else {
            wrench_frames.push(None);
        }
    }
    // One frame at each captured payload's centre of mass: its generated Jacobian and
    // placement give the capture impulse `J_pᵀ h_p`.
    for (k, e) in scene.events.iter().enumerate() {
        if let EventKind::Capture { payload, .. } = &e.kind {
            frames.push(Frame {
                name: format!("scene_capture_{k}"),
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

    let dyn_name = format!("{name}Dynamics");
    let dyn_ty = format_ident!("{}", dyn_name);
    let mut opts = kanegen_codegen::Options::new(dyn_name.clone());
    opts.gravity = scene.gravity;
    opts.base = Some(kind);
    opts.libm_path = "kanegen::__private::libm".into();
    opts.libm_tokens = Some(quote!(#runtime::__private::libm));
    opts.runtime_path = "kanegen::__private::runtime".into();
    opts.runtime_tokens = Some(quote!(#runtime::__private::runtime));
    opts.payload_name = format!("{dyn_name}Payload");
    opts.op_count_name = format!("{dyn_name}OpCount");
    let g = kanegen_codegen::generate_items(&model, &opts).map_err(|e| format!("{rel}: {e}"))?;
    let dyn_items = g.items;
    let (phase_tys, phase_items) =
        crate::scene_events::phase_dynamics(&scene, &opts, &dyn_name, rel)?;

    let n = model.dof();
    let nl = Literal::usize_unsuffixed(n);
    let state_ty = format_ident!("{}State", name);
    let (nq, nv) = if floating { (n + 7, n + 6) } else { (n, n) };
    let (nql, nvl) = (Literal::usize_unsuffixed(nq), Literal::usize_unsuffixed(nv));
    // Flexible joints (fixed base, the scene checks) add the motor positions and rates.
    let flexible = scene.flexible.as_ref();
    let dim_n = nq + nv + if flexible.is_some() { 2 * n } else { 0 };
    let dim = Literal::usize_unsuffixed(dim_n);
    let vname = if floating {
        format_ident!("v")
    } else {
        format_ident!("qd")
    };

    // Joint positions and rates inside `rhs` (`s` the state).
    let (qj, qdj) = if flexible.is_some() {
        // The drives, damping and friction act on the motors.
        (quote!(let qj = s.theta;), quote!(let qdj = s.thetad;))
    } else if floating {
        (
            quote!(let qj: [f64; #nl] = core::array::from_fn(|i| s.q[7 + i]);),
            quote!(let qdj: [f64; #nl] = core::array::from_fn(|i| s.v[6 + i]);),
        )
    } else {
        (quote!(let qj = s.q;), quote!(let qdj = s.qd;))
    };

    // A computed-torque drive compensates the wrenches (at `t`) as the interpreted inverse
    // dynamics does: `τ −= J_vᵀ f + J_ωᵀ m`, force and moment in base axes at the body origin
    // (fixed base only: the scene rejects computed torque on a free-floating base).
    let mut compensate = Vec::new();
    if computed_torque {
        for (k, w) in scene.wrenches.iter().enumerate() {
            let value = wrench_value(runtime, &w.profile);
            let Some(fname) = &wrench_frames[k] else {
                return Err(format!("{rel}: effects.wrench[{k}]: no frame"));
            };
            let (pl, jac) = (
                format_ident!("{}_placement", fname),
                format_ident!("{}_jacobian", fname),
            );
            let to_base = if w.frame == kanegen_codegen::kanegen_dynamics::LoadFrame::Body {
                quote! {
                    let r = #dyn_ty::#pl(&qj).1;
                    let (f, m): ([f64; 3], [f64; 3]) = (
                        core::array::from_fn(|i| r[i][0] * f[0] + r[i][1] * f[1] + r[i][2] * f[2]),
                        core::array::from_fn(|i| r[i][0] * m[0] + r[i][1] * m[1] + r[i][2] * m[2]),
                    );
                }
            } else {
                quote!()
            };
            compensate.push(quote! {{
                let (f, m): ([f64; 3], [f64; 3]) = #value;
                #to_base
                let jac = #dyn_ty::#jac(&qj);
                for j in 0..#nl {
                    tau[j] -= jac[0][j] * f[0] + jac[1][j] * f[1] + jac[2][j] * f[2]
                        + jac[3][j] * m[0] + jac[4][j] * m[1] + jac[5][j] * m[2];
                }
            }});
        }
    }

    // Drives and damping: τ as the interpreted `SceneSystem::torques`.
    let drives = match &scene.drives {
        Drives::None => quote!(let mut tau = [0.0f64; #nl];),
        Drives::Constant { tau } => {
            let t = arr(tau);
            quote!(let mut tau: [f64; #nl] = #t;)
        }
        Drives::Pd { kp, kd, target } => {
            let (kp, kd, target) = (arr(kp), arr(kd), arr(target));
            quote! {
                const KP: [f64; #nl] = #kp;
                const KD: [f64; #nl] = #kd;
                const TARGET: [f64; #nl] = #target;
                let mut tau: [f64; #nl] =
                    core::array::from_fn(|i| KP[i] * (TARGET[i] - qj[i]) - KD[i] * qdj[i]);
            }
        }
        Drives::ComputedTorque {
            kp,
            kd,
            target,
            duration,
        } => {
            let (kp, kd, target, q0) = (arr(kp), arr(kd), arr(target), arr(&scene.q0));
            let d = lit(*duration);
            quote! {
                const KP: [f64; #nl] = #kp;
                const KD: [f64; #nl] = #kd;
                const TARGET: [f64; #nl] = #target;
                const Q0: [f64; #nl] = #q0;
                let (sq, dsq, ddsq) = #runtime::__private::runtime::ode::quintic(t, #d);
                let cmd: [f64; #nl] = core::array::from_fn(|i| {
                    let di = TARGET[i] - Q0[i];
                    ddsq * di + KD[i] * (dsq * di - qdj[i]) + KP[i] * ((Q0[i] + sq * di) - qj[i])
                });
                let mut tau: [f64; #nl] = #dyn_ty::inverse_dynamics(&qj, &qdj, &cmd);
                #(#compensate)*
            }
        }
    };
    let damping = match &scene.damping {
        None => quote!(),
        Some(c) => {
            let c = arr(c);
            quote! {
                const DAMPING: [f64; #nl] = #c;
                for i in 0..#nl {
                    tau[i] -= DAMPING[i] * qdj[i];
                }
            }
        }
    };

    // Coulomb drive friction, on the applied side as the interpreted `SceneSystem::torques`.
    let coulomb = match &scene.coulomb {
        None => quote!(),
        Some(c) => {
            let (tc, inv) = (arr(&c.tau_c), lit(1.0 / c.v_s));
            quote! {
                const COULOMB: [f64; #nl] = #tc;
                for i in 0..#nl {
                    tau[i] -= COULOMB[i] * #runtime::__private::libm::tanh(qdj[i] * #inv);
                }
            }
        }
    };

    // Wrenches: each in its body's frame at the body origin, summed per body (`f_ext` row; on a
    // free-floating base row 0 is the base's).
    let rows_n = Literal::usize_unsuffixed(n + usize::from(floating));
    let mut wrench_code = Vec::new();
    for (k, w) in scene.wrenches.iter().enumerate() {
        let value = wrench_value(runtime, &w.profile);
        let is_base = w.body == kanegen_codegen::kanegen_dynamics::base::BASE_BODY;
        let row = Literal::usize_unsuffixed(if is_base {
            0
        } else {
            w.body + usize::from(floating)
        });
        // Body-to-reference rotation of an inertial-frame wrench.
        let rot = match (&wrench_frames[k], is_base, w.frame) {
            (_, _, kanegen_codegen::kanegen_dynamics::LoadFrame::Body) => None,
            (Some(fname), _, _) => {
                let pl = format_ident!("{}_placement", fname);
                Some(quote!(#dyn_ty::#pl(&s.q).1))
            }
            (None, true, _) => Some(quote!(#runtime::__private::runtime::ode::quat_to_matrix(&[
                s.q[3], s.q[4], s.q[5], s.q[6]
            ]))),
            (None, false, _) => return Err(format!("{rel}: effects.wrench[{k}]: no frame")),
        };
        let apply = match rot {
            None => quote! {
                for i in 0..3 {
                    f_ext[#row][i] += f[i];
                    f_ext[#row][3 + i] += m[i];
                }
            },
            Some(r) => quote! {
                let r: [[f64; 3]; 3] = #r;
                for i in 0..3 {
                    f_ext[#row][i] += r[0][i] * f[0] + r[1][i] * f[1] + r[2][i] * f[2];
                    f_ext[#row][3 + i] += r[0][i] * m[0] + r[1][i] * m[1] + r[2][i] * m[2];
                }
            },
        };
        wrench_code.push(quote! {{
            let (f, m): ([f64; 3], [f64; 3]) = #value;
            #apply
        }});
    }
    // The acceleration with the dynamics type `dy` (one per model phase of a scene with
    // events; phase 0 is `NameDynamics`).
    let off = Literal::usize_unsuffixed(nv - n);
    let accel_for = |dy: &Ident| -> TokenStream {
        if let Some(r) = &scene.rotor {
            // (M + diag(I_m n²)) a = τ − c by a fixed-size LDLᵀ: the armature on the joint
            // diagonal (`M[6+i][6+i]` on a free-floating base). With wrenches, τ + Jᵀf − c =
            // M a_w, a_w the generated forward dynamics with the wrenches. A non-positive pivot
            // gives a NaN acceleration, so the step stops with `Stop::NonFinite`.
            let refl = arr(&r.reflected);
            let tau_v = if floating {
                quote! {
                    let tau_v: [f64; #nvl] =
                        core::array::from_fn(|i| if i < 6 { 0.0 } else { tau[i - 6] });
                }
            } else {
                quote!(let tau_v = tau;)
            };
            let rhs = if scene.wrenches.is_empty() {
                quote! {
                    let (mut m, c) = #dy::mass_matrix_and_nonlinear_effects(&s.q, &s.#vname);
                    #tau_v
                    let b: [f64; #nvl] = core::array::from_fn(|i| tau_v[i] - c[i]);
                }
            } else {
                quote! {
                    let mut f_ext = [[0.0f64; 6]; #rows_n];
                    #(#wrench_code)*
                    let a_w = #dy::forward_dynamics_with_wrenches(&s.q, &s.#vname, &tau, &f_ext);
                    let mut m = #dy::mass_matrix(&s.q);
                    let b: [f64; #nvl] = core::array::from_fn(|i| {
                        let mut x = 0.0;
                        for j in 0..#nvl {
                            x += m[i][j] * a_w[j];
                        }
                        x
                    });
                }
            };
            quote! {{
                const ROTOR: [f64; #nl] = #refl;
                #rhs
                for i in 0..#nl {
                    m[#off + i][#off + i] += ROTOR[i];
                }
                #runtime::__private::runtime::ode::solve_spd(&m, &b).unwrap_or([f64::NAN; #nvl])
            }}
        } else if scene.wrenches.is_empty() {
            quote!(#dy::forward_dynamics(&s.q, &s.#vname, &tau))
        } else {
            quote! {{
                let mut f_ext = [[0.0f64; 6]; #rows_n];
                #(#wrench_code)*
                #dy::forward_dynamics_with_wrenches(&s.q, &s.#vname, &tau, &f_ext)
            }}
        }
    };
    let accel = if scene.events.is_empty() {
        accel_for(&dyn_ty)
    } else {
        let arms = phase_tys.iter().enumerate().map(|(k, ty)| {
            let a = accel_for(ty);
            let k = Literal::usize_unsuffixed(k);
            quote!(#k => #a,)
        });
        quote!(match phase { #(#arms)* _ => [f64::NAN; #nvl] })
    };
    // Spong's model: the spring-damper torque drives the links, `tau` (the motor torque) the
    // motors, as the interpreted `SceneSystem::deriv`.
    let spring = match flexible {
        None => quote!(),
        Some(f) => {
            let (k, d, b) = (arr(&f.stiffness), arr(&f.damping), arr(&f.reflected));
            quote! {
                    const STIFFNESS: [f64; #nl] = #k;
                    const SPRING_DAMPING: [f64; #nl] = #d;
                    const MOTOR: [f64; #nl] = #b;
                    let tau_m = tau;
                    let tau: [f64; #nl] = core::array::from_fn(|i| {
                        STIFFNESS[i] * (s.theta[i] - s.q[i])
                            + SPRING_DAMPING[i] * (s.thetad[i] - s.qd[i])
                    });
            }
        }
    };
    let derivative = if flexible.is_some() {
        quote! {
            #spring
            let a = #accel;
            #state_ty {
                q: s.qd,
                qd: a,
                theta: s.thetad,
                thetad: core::array::from_fn(|i| (tau_m[i] - tau[i]) / MOTOR[i]),
            }
        }
    } else if floating {
        quote! {
            let a = #accel;
            let r = #runtime::__private::runtime::ode::quat_to_matrix(&[s.q[3], s.q[4], s.q[5], s.q[6]]);
            let (u, w, om) = ([s.q[3], s.q[4], s.q[5]], s.q[6], [s.v[3], s.v[4], s.v[5]]);
            let mut dq = [0.0f64; #nql];
            for i in 0..3 {
                dq[i] = r[i][0] * s.v[0] + r[i][1] * s.v[1] + r[i][2] * s.v[2];
            }
            // q̇uat = ½ quat ⊗ (ω, 0): u̇ = ½ (w ω + u × ω), ẇ = −½ u · ω.
            let cross = [
                u[1] * om[2] - u[2] * om[1],
                u[2] * om[0] - u[0] * om[2],
                u[0] * om[1] - u[1] * om[0],
            ];
            for i in 0..3 {
                dq[3 + i] = 0.5 * (om[i] * w + cross[i]);
            }
            dq[6] = -0.5 * (u[0] * om[0] + u[1] * om[1] + u[2] * om[2]);
            for i in 0..#nl {
                dq[7 + i] = qdj[i];
            }
            #state_ty { q: dq, v: a }
        }
    } else {
        quote! {
            let a = #accel;
            #state_ty { q: s.qd, qd: a }
        }
    };

    let x0: Vec<f64> = match &scene.base {
        BaseSpec::Fixed if flexible.is_some() => {
            [scene.q0.as_slice(), &scene.qd0, &scene.q0, &scene.qd0].concat()
        }
        BaseSpec::Fixed => [scene.q0.as_slice(), &scene.qd0].concat(),
        BaseSpec::FreeFloating {
            position,
            quaternion,
            v,
            omega,
            ..
        } => [
            position.as_slice(),
            quaternion,
            &scene.q0,
            v,
            omega,
            &scene.qd0,
        ]
        .concat(),
    };
    let (q0, v0) = (arr(&x0[..nq]), arr(&x0[nq..nq + nv]));
    let ode = quote!(#runtime::__private::runtime::ode);
    // The scratch of `run` (of the scene's method) and of `step` (RK4 for a dopri5 scene), on
    // the stack, sized by the runtime for this state.
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
    let (run_scratch, step_scratch) = (scratch(run_mod), scratch(step_mod));
    let step_fn = format_ident!("{step_fn}");
    // The scene's right-hand side `rhs(args…, t, state)` as an `ode::System` (the quaternion
    // projected and advanced by the exponential map on a free-floating base).
    let system = |rhs: TokenStream, args: TokenStream| {
        quote! {
            #ode::FnSystem::<#dim, _> {
                rhs: |t: f64, x: &[f64; #dim]| {
                    #rhs(#args t, &#state_ty::from_array(x)).to_array()
                },
                floating: #floating,
            }
        }
    };
    let step_system = system(quote!(Self::rhs), quote!());
    let (duration, step, tolerance, max_step) = (
        lit(sim.duration),
        lit(sim.step),
        lit(sim.tolerance),
        lit(sim.max_step),
    );
    let every = Literal::usize_unsuffixed(sim.output_every);
    let run_fn = format_ident!("{run_mod}");
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
                output_interval: Self::STEP * Self::OUTPUT_EVERY as f64,
            }
        }
    };
    let integrate = |t0: TokenStream, t1: TokenStream, obs: TokenStream| quote!(#ode::#run_fn(&mut sys, #t0, #t1, &#options, &mut x, &mut scratch, #obs));
    let run_body = if scene.events.is_empty() {
        let call = integrate(quote!(0.0), quote!(Self::DURATION), quote!(obs));
        let sys = system(quote!(Self::rhs), quote!());
        quote! {
            let mut sys = #sys;
            #call
        }
    } else {
        let call = integrate(quote!(t0), quote!(t1), quote!(&mut obs));
        let sys = system(quote!(Self::rhs_in), quote!(phase,));
        crate::scene_events::run_segments(runtime, &state_ty, &sys, &call)
    };
    let events =
        crate::scene_events::event_items(runtime, &scene, &state_ty, &dyn_ty, &phase_tys, nv, n);
    let rhs_sig = if scene.events.is_empty() {
        quote! {
            /// The right-hand side `ẋ = f(t, x)` with the scene's effects only.
            #[must_use]
            pub fn rhs(t: f64, s: &#state_ty) -> #state_ty
        }
    } else {
        quote! {
            /// The right-hand side `ẋ = f(t, x)` with the scene's effects only, with the model
            /// of `phase` (0 before the first event, `k` after event `k − 1`).
            #[must_use]
            pub fn rhs_in(phase: usize, t: f64, s: &#state_ty) -> #state_ty
        }
    };
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
    let step_doc = if sim.integrator == Integrator::Rosenbrock {
        " One Rodas4 step of size `h` from `(t, state)` (no step control)."
    } else if sim.integrator == Integrator::Midpoint {
        " One implicit midpoint step of size `h` from `(t, state)` (the scene's integrator)."
    } else {
        " One fixed RK4 step of size `h` from `(t, state)`, then the projection (the quaternion \
         renormalized on a free-floating base)."
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
    let state_doc = if flexible.is_some() {
        format!(
            " The state of [`{name}`]: link positions `q` and rates `qd`, motor positions \
             `theta` and rates `thetad` ({n} each; Spong's flexible joints). A derivative has \
             the same layout."
        )
    } else if floating {
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
    let vdoc = if floating {
        " Base linear and angular velocity (base coordinates), joint rates."
    } else {
        " Joint rates."
    };
    let scene_lit = LitStr::new(&abs, Span::call_site());
    let model_lit = LitStr::new(&model_path.display().to_string(), Span::call_site());
    let rel_lit = LitStr::new(rel, Span::call_site());
    let dim_doc = if flexible.is_some() {
        format!(" Length of the flat state vector ({nq} + {nv} + {n} + {n}).")
    } else {
        format!(" Length of the flat state vector ({nq} + {nv}).")
    };
    let motor_fields = if flexible.is_some() {
        quote! {
            /// Motor positions (link side, `θ`).
            pub theta: [f64; #nl],
            /// Motor rates.
            pub thetad: [f64; #nl],
        }
    } else {
        quote!()
    };
    let (to_array, from_array, init_motor) = if flexible.is_some() {
        let two = Literal::usize_unsuffixed(2 * n);
        let three = Literal::usize_unsuffixed(3 * n);
        (
            quote! {
                core::array::from_fn(|i| match i / #nl {
                    0 => self.q[i],
                    1 => self.qd[i - #nl],
                    2 => self.theta[i - #two],
                    _ => self.thetad[i - #three],
                })
            },
            quote! {
                #state_ty {
                    q: core::array::from_fn(|i| x[i]),
                    qd: core::array::from_fn(|i| x[#nl + i]),
                    theta: core::array::from_fn(|i| x[#two + i]),
                    thetad: core::array::from_fn(|i| x[#three + i]),
                }
            },
            {
                let (t0, td0) = (arr(&scene.q0), arr(&scene.qd0));
                quote!(, theta: #t0, thetad: #td0)
            },
        )
    } else {
        (
            quote!(core::array::from_fn(|i| if i < #nql { self.q[i] } else { self.#vname[i - #nql] })),
            quote! {
                #state_ty {
                    q: core::array::from_fn(|i| x[i]),
                    #vname: core::array::from_fn(|i| x[#nql + i]),
                }
            },
            quote!(),
        )
    };

    Ok(quote! {
        const _: &[u8] = include_bytes!(#scene_lit);
        const _: &[u8] = include_bytes!(#model_lit);

        #dyn_items
        #phase_items

        #[doc = #state_doc]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct #state_ty {
            /// Positions.
            pub q: [f64; #nql],
            #[doc = #vdoc]
            pub #vname: [f64; #nvl],
            #motor_fields
        }

        impl #state_ty {
            /// The state as one vector `[q, v]` (the interpreted simulator's layout).
            #[must_use]
            pub fn to_array(&self) -> [f64; #dim] {
                #to_array
            }

            /// The state of a vector `[q, v]`.
            #[must_use]
            pub fn from_array(x: &[f64; #dim]) -> Self {
                #from_array
            }
        }

        #[doc = #struct_doc]
        #[doc = ""]
        #[doc = #integrator_doc]
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct #name;

        #[allow(clippy::too_many_lines, clippy::unreadable_literal, clippy::excessive_precision)]
        impl #name {
            /// Joint degrees of freedom.
            pub const N: usize = #nl;
            #[doc = #dim_doc]
            pub const DIM: usize = #dim;
            /// The scene file (relative to the crate).
            pub const SCENE: &'static str = #rel_lit;
            /// Simulated duration, s.
            pub const DURATION: f64 = #duration;
            /// Step (RK4), or first step tried (dopri5), s.
            pub const STEP: f64 = #step;
            /// dopri5 tolerance (`rtol = atol`; unused by RK4 scenes).
            pub const TOLERANCE: f64 = #tolerance;
            /// An output sample every this many steps (RK4), or every `OUTPUT_EVERY · STEP`
            /// seconds (dopri5).
            pub const OUTPUT_EVERY: usize = #every;

            /// The scene's initial state.
            #[must_use]
            pub fn initial_state() -> #state_ty {
                #state_ty { q: #q0, #vname: #v0 #init_motor }
            }

            #rhs_sig {
                let _ = t;
                #qj
                #qdj
                let _ = (&qj, &qdj);
                #drives
                #damping
                #coulomb
                #derivative
            }

            #[doc = #step_doc]
            ///
            /// # Errors
            /// A `kanegen::ode::Stop` when the new state is not finite (or the midpoint
            /// iterations do not converge); `state` is then unchanged.
            pub fn step(
                t: f64,
                state: &mut #state_ty,
                h: f64,
            ) -> Result<(), #runtime::__private::runtime::ode::Stop> {
                let mut x = state.to_array();
                #ode::#step_fn(&mut #step_system, t, h, &mut x, &mut #step_scratch)?;
                *state = #state_ty::from_array(&x);
                Ok(())
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
                mut observe: impl FnMut(f64, &#state_ty),
            ) -> Result<#runtime::__private::runtime::ode::Stats, #runtime::__private::runtime::ode::Stop> {
                let mut x = Self::initial_state().to_array();
                let mut scratch = #run_scratch;
                #[allow(unused_mut)]
                let mut obs = |t: f64, x: &[f64]| {
                    if let Ok(x) = <&[f64; #dim]>::try_from(x) {
                        observe(t, &#state_ty::from_array(x));
                    }
                };
                #run_body
            }

            #events
        }
    })
}
