//! What `scene!` emits for the Jacobians of one step, `x⁺ = Φ(t, x, u)` (`u` the joint torques
//! added to the scene's drive): the provider's derivatives, forwards to the generated
//! `forward_dynamics_derivatives` and `inverse_dynamics_derivatives` ([`derivatives`]), and
//! `Name::step_jacobians` ([`step_jacobians`]), which calls the runtime's exact chain rule
//! through the step (`kanegen_runtime::ode::linearize`) over the scene's right-hand side with
//! its input (`kanegen_runtime::scene::linearize`) — the code `kanegen simulate --linearize`
//! runs over the run-time algorithms.

use crate::scene_provider::{as_arrays, phase_match, Shape};
use kanegen_codegen::kanegen_dynamics::LoadFrame;
use kanegen_codegen::paths;
use kanegen_runtime::scene::SceneEffects;
use kanegen_scene::{Integrator, Scene};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use syn::Ident;

/// Whether `scene!` emits `step_jacobians`, or why not (the sentence of the scene's doc).
pub fn availability(
    scene: &Scene,
    effects: &SceneEffects<'_>,
    has_derivatives: bool,
) -> Result<(), String> {
    if scene.simulation.integrator == Integrator::Rosenbrock {
        return Err("its step is a Rodas4 step".into());
    }
    if effects.floating && scene.model.has_mimics() {
        return Err("its free-floating model has mimic joints".into());
    }
    if !effects.wrenches.is_empty() && scene.model.has_mimics() {
        return Err("it has external wrenches on a model with mimic joints".into());
    }
    if !has_derivatives {
        return Err(
            "the generated dynamics carry no derivatives (unrolled with more than 24 speeds)"
                .into(),
        );
    }
    Ok(())
}

/// The doc line of `Name` on its step Jacobians.
pub fn doc(name: &Ident, available: &Result<(), String>) -> String {
    match available {
        Ok(()) => format!(
            " [`{name}::step_jacobians`] gives the Jacobians `(A, B)` of one [`{name}::step`] with \
             joint torques `u` added to the drive, exact for the scheme (the chain rule through \
             its stages, from the generated derivatives)."
        ),
        Err(why) => format!(" No `step_jacobians`: {why}."),
    }
}

/// `impl SceneDerivatives for <shape.ty>`: forwards to the generated derivative functions of
/// the provider's phase.
pub fn derivatives(scene: &Scene, sh: &Shape<'_>) -> TokenStream {
    let Shape { rt, ty, .. } = sh;
    let gravity = crate::scene_provider::arr(&scene.gravity.unwrap_or([0.0; 3]));
    let nvl = Literal::usize_unsuffixed(sh.nv);
    let f64 = paths::primitive("f64");
    let nan = quote!([[#f64::NAN; #nvl]; #nvl]);
    let forward = phase_match(
        sh,
        &quote!((#nan, #nan, #nan)),
        |dy| quote!(#dy::forward_dynamics_derivatives(q, v, tau)),
    );
    let inverse = phase_match(
        sh,
        &quote!((#nan, #nan)),
        |dy| quote!(#dy::inverse_dynamics_derivatives(q, v, qdd)),
    );
    let forward_args = as_arrays(
        &[("q", sh.nq), ("v", sh.nv), ("tau", sh.n)],
        &quote! {
            dq.fill(#f64::NAN);
            dv.fill(#f64::NAN);
            return minv.fill(#f64::NAN);
        },
    );
    let inverse_args = as_arrays(
        &[("q", sh.nq), ("v", sh.nv), ("qdd", sh.nv)],
        &quote! {
            dq.fill(#f64::NAN);
            return dv.fill(#f64::NAN);
        },
    );
    let wrench_body = wrench_body(scene, sh);
    quote! {
        impl #rt::scene::SceneDerivatives for #ty {
            fn forward_derivatives(
                &mut self,
                q: &[#f64],
                v: &[#f64],
                tau: &[#f64],
                dq: &mut [#f64],
                dv: &mut [#f64],
                minv: &mut [#f64],
            ) {
                #forward_args
                let (a, b, c) = #forward;
                for (m, dst) in [(a, dq), (b, dv), (c, minv)] {
                    for (row, d) in m.iter().zip(dst.chunks_exact_mut(#nvl)) {
                        #rt::scene::copy_into(d, row);
                    }
                }
            }

            fn gravity(&self) -> [#f64; 3] {
                #gravity
            }

            fn inverse_derivatives(
                &mut self,
                q: &[#f64],
                v: &[#f64],
                qdd: &[#f64],
                dq: &mut [#f64],
                dv: &mut [#f64],
            ) {
                #inverse_args
                let (a, b) = #inverse;
                for (m, dst) in [(a, dq), (b, dv)] {
                    for (row, d) in m.iter().zip(dst.chunks_exact_mut(#nvl)) {
                        #rt::scene::copy_into(d, row);
                    }
                }
            }

            #wrench_body
        }
    }
}

/// `wrench_body` of `SceneDerivatives`: the generated Jacobian and placement of the frame
/// `scene!` puts at the origin of each wrench's body, on a free-floating base evaluated with the
/// base at the inertial origin unturned (so inertial axes are base coordinates); the base's
/// speed columns for a wrench on the base; NaN otherwise.
fn wrench_body(scene: &Scene, sh: &Shape<'_>) -> TokenStream {
    let Shape { rt, .. } = sh;
    let (f64, usize) = (paths::primitive("f64"), paths::primitive("usize"));
    let nl = Literal::usize_unsuffixed(sh.nv);
    let nan = quote! {{
        jac.fill(#f64::NAN);
        #rt::scene::WrenchBody { rotation: [[#f64::NAN; 3]; 3], body_fixed: false }
    }};
    let dyn_ty = &sh.phases[0];
    let floating = scene.is_floating();
    let arms = scene.wrenches.iter().enumerate().map(|(k, w)| {
        let body_fixed = w.frame == LoadFrame::Body;
        let frame = sh.wrench_frames[k].as_ref();
        let k = Literal::usize_unsuffixed(k);
        let Some(fname) = frame else {
            // The base of a free-floating one: its own speeds, unit columns.
            return quote! {
                #k => {
                    jac.fill(0.0);
                    for m in 0..6 {
                        jac[m * #nl + m] = 1.0;
                    }
                    #rt::scene::WrenchBody {
                        rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                        body_fixed: #body_fixed,
                    }
                }
            };
        };
        let (pl, jc) = (
            format_ident!("{}_placement", fname),
            format_ident!("{}_jacobian", fname),
        );
        let at = if floating {
            quote! {
                let mut at = *q;
                at[..7].copy_from_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
                let q = &at;
            }
        } else {
            quote!()
        };
        quote! {
            #k => {
                #at
                let j = #dyn_ty::#jc(q);
                for (row, d) in j.iter().zip(jac.chunks_exact_mut(#nl)) {
                    #rt::scene::copy_into(d, row);
                }
                #rt::scene::WrenchBody { rotation: #dyn_ty::#pl(q).1, body_fixed: #body_fixed }
            }
        }
    });
    let args = as_arrays(&[("q", sh.nq)], &quote!(return #nan;));
    if scene.wrenches.is_empty() {
        return quote! {
            fn wrench_body(&mut self, _k: #usize, _q: &[#f64], jac: &mut [#f64]) -> #rt::scene::WrenchBody #nan
        };
    }
    quote! {
        fn wrench_body(&mut self, k: #usize, q: &[#f64], jac: &mut [#f64]) -> #rt::scene::WrenchBody {
            #args
            if jac.len() != 6 * #nl {
                return #nan;
            }
            match k {
                #(#arms)*
                _ => #nan,
            }
        }
    }
}

/// `Name::step_jacobians` (inside `impl Name`) for the scene's step scheme: RK4 (RK4 and
/// dopri5 scenes) or the implicit midpoint rule.
pub fn step_jacobians(
    rt: &TokenStream,
    scene: &Scene,
    state_ty: &Ident,
    model_ty: &Ident,
    (n, dim, floating): (usize, usize, bool),
) -> TokenStream {
    let ode = quote!(#rt::ode);
    // The Jacobians' rows and columns: the tangent space's on a free-floating base.
    let tangent = if floating { dim - 1 } else { dim };
    let (nl, dl, tl) = (
        Literal::usize_unsuffixed(n),
        Literal::usize_unsuffixed(dim),
        Literal::usize_unsuffixed(tangent),
    );
    let f64 = paths::primitive("f64");
    let result = paths::result_type(
        &quote!((#state_ty, [[#f64; #tl]; #tl], [[#f64; #nl]; #tl])),
        &quote!(#ode::Stop),
    );
    let done = paths::ok(quote! {(
        #state_ty::from_array(&x),
        ::core::array::from_fn(|i| ::core::array::from_fn(|j| a[i * #tl + j])),
        ::core::array::from_fn(|i| ::core::array::from_fn(|j| b[i * #nl + j])),
    )});
    let midpoint = scene.simulation.integrator == Integrator::Midpoint;
    let (call, scratch, scheme) = if floating && midpoint {
        (
            quote!(#ode::floating_midpoint_step_jacobians),
            quote!(#ode::ArrayScratch::<{ #ode::linearize::floating_midpoint_scratch_len(#dl, #nl) }, #dl>::new()),
            "implicit midpoint",
        )
    } else if floating {
        (
            quote!(#ode::floating_rk4_step_jacobians),
            quote!(#ode::ArrayScratch::<{ #ode::linearize::floating_rk4_scratch_len(#dl, #nl) }>::new()),
            "RK4",
        )
    } else if midpoint {
        (
            quote!(#ode::midpoint_step_jacobians),
            quote!(#ode::ArrayScratch::<{ #ode::linearize::midpoint_scratch_len(#dl, #nl) }, #dl>::new()),
            "implicit midpoint",
        )
    } else {
        (
            quote!(#ode::rk4_step_jacobians),
            quote!(#ode::ArrayScratch::<{ #ode::linearize::rk4_scratch_len(#dl, #nl) }>::new()),
            "RK4",
        )
    };
    let tangent_doc = if floating {
        ", the base's pose in the tangent space of Pinocchio's `integrate` (its 7 numbers as 6 \
         directions `[δp; δθ]` in base coordinates: `A` and `B` have `DIM − 1` rows, `A` as many \
         columns; `kanegen::runtime::ode::floating_rk4_step_jacobians` and \
         `floating_midpoint_step_jacobians`)"
    } else {
        ""
    };
    let doc = format!(
        " One {scheme} step of size `h` from `(t, state)` (what [`Self::step`] takes) with the \
         joint torques `u` added to the scene's drive, and its Jacobians `(A, B)`: \
         `A[i][j] = ∂x⁺_i/∂x_j`, `B[i][j] = ∂x⁺_i/∂u_j` over the flat state \
         ([`{state_ty}::to_array`]){tangent_doc}. Exact for the scheme: the chain rule through its stages \
         (`kanegen::runtime::ode::linearize`) from the generated derivatives of forward and \
         inverse dynamics and the drive's own. With `u = 0` the new state is `step`'s, bit for bit."
    );
    quote! {
        #[doc = #doc]
        ///
        /// # Errors
        /// A `kanegen::ode::Stop` when the new state is not finite (or the midpoint iterations
        /// do not converge).
        #[allow(clippy::type_complexity)]
        pub fn step_jacobians(
            t: #f64,
            state: &#state_ty,
            u: &[#f64; #nl],
            h: #f64,
        ) -> #result {
            let mut x = state.to_array();
            let mut work = [0.0f64; #rt::scene::linearize::jacobian_work_len(&Self::EFFECTS)];
            let mut model = #model_ty(0);
            let mut sys = #rt::scene::SceneControl {
                dynamics: &mut model,
                effects: &Self::EFFECTS,
                work: &mut work,
            };
            let (mut a, mut b) = ([0.0f64; #tl * #tl], [0.0f64; #tl * #nl]);
            #call(&mut sys, t, h, &mut x, u, &mut a, &mut b, &mut #scratch)?;
            #done
        }
    }
}
