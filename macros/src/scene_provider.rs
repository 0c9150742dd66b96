//! What `scene!` emits around the one right-hand side of `kanegen_runtime::scene`: the scene's
//! effects as a `const` ([`effects`]) and the generated dynamics types as its provider
//! ([`provider`], one-line forwards to the generated functions, one arm a model phase; the
//! scene's wrenches mapped to the generated `f_ext` rows and, for a computed-torque drive, to
//! the joints by the generated frame Jacobians).

use kanegen_codegen::kanegen_dynamics::base::BASE_BODY;
use kanegen_codegen::kanegen_dynamics::LoadFrame;
use kanegen_codegen::paths;
use kanegen_runtime::scene::{Drive, Profile, SceneEffects};
use kanegen_scene::Scene;
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use syn::Ident;

/// `f64` literal.
pub fn lit(x: f64) -> Literal {
    Literal::f64_suffixed(x)
}

/// `[f64; _]` literal.
pub fn arr(v: &[f64]) -> TokenStream {
    let v = v.iter().map(|x| lit(*x));
    quote!([#(#v),*])
}

fn rows(v: &[[f64; 3]]) -> TokenStream {
    let v = v.iter().map(|r| arr(r));
    quote!([#(#v),*])
}

/// `let (Ok(q), Ok(v), …) = (<&[f64; NQ]>::try_from(q), …) else { otherwise };`: the slice
/// arguments `args` (name, length) as arrays of their lengths, `otherwise` when one is not.
pub fn as_arrays(args: &[(&str, usize)], otherwise: &TokenStream) -> TokenStream {
    let f64 = paths::primitive("f64");
    let names: Vec<Ident> = args
        .iter()
        .map(|(name, _)| format_ident!("{name}"))
        .collect();
    let arrays = names.iter().zip(args).map(|(name, (_, len))| {
        let len = Literal::usize_unsuffixed(*len);
        quote!(<&[#f64; #len]>::try_from(#name))
    });
    let oks = names.iter().map(paths::ok);
    if args.len() == 1 {
        quote!(let #(#oks)* = #(#arrays)* else { #otherwise };)
    } else {
        quote!(let (#(#oks),*) = (#(#arrays),*) else { #otherwise };)
    }
}

/// The `SceneEffects` literal of `fx` (`rt` the runtime's path).
pub fn effects(rt: &TokenStream, fx: &SceneEffects<'_>) -> TokenStream {
    let s = quote!(#rt::scene);
    let slice = |v: &[f64]| {
        let a = arr(v);
        quote!(&#a)
    };
    let drive = match fx.drive {
        Drive::None => quote!(#s::Drive::None),
        Drive::Constant(t) => {
            let t = slice(t);
            quote!(#s::Drive::Constant(#t))
        }
        Drive::Pd { kp, kd, target } => {
            let (kp, kd, target) = (slice(kp), slice(kd), slice(target));
            quote!(#s::Drive::Pd { kp: #kp, kd: #kd, target: #target })
        }
        Drive::ComputedTorque {
            kp,
            kd,
            q0,
            target,
            duration,
        } => {
            let (kp, kd, q0, target, d) = (
                slice(kp),
                slice(kd),
                slice(q0),
                slice(target),
                lit(duration),
            );
            quote! {
                #s::Drive::ComputedTorque { kp: #kp, kd: #kd, q0: #q0, target: #target, duration: #d }
            }
        }
    };
    let wrenches = fx.wrenches.iter().map(|p| match *p {
        Profile::Constant { force, moment } => {
            let (f, m) = (arr(&force), arr(&moment));
            quote!(#s::Profile::Constant { force: #f, moment: #m })
        }
        Profile::Table {
            time,
            force,
            moment,
        } => {
            let (t, f, m) = (arr(time), rows(force), rows(moment));
            quote!(#s::Profile::Table { time: &#t, force: &#f, moment: &#m })
        }
    });
    let damping = paths::option(fx.damping.map(slice));
    let coulomb = paths::option(fx.coulomb.map(|c| {
        let (tc, vs) = (slice(c.tau_c), lit(c.v_s));
        quote!(#s::Coulomb { tau_c: #tc, v_s: #vs })
    }));
    let armature = paths::option(fx.armature.map(slice));
    let flexible = paths::option(fx.flexible.map(|f| {
        let (k, d, b) = (slice(f.stiffness), slice(f.damping), slice(f.reflected));
        quote!(#s::Flexible { stiffness: #k, damping: #d, reflected: #b })
    }));
    let (dof, floating) = (Literal::usize_unsuffixed(fx.dof), fx.floating);
    quote! {
        #s::SceneEffects {
            dof: #dof,
            floating: #floating,
            drive: #drive,
            damping: #damping,
            coulomb: #coulomb,
            wrenches: &[#(#wrenches),*],
            armature: #armature,
            flexible: #flexible,
        }
    }
}

/// The names and sizes the provider's forwards use.
pub struct Shape<'a> {
    /// The runtime's path.
    pub rt: TokenStream,
    /// The provider type (a tuple struct of the model phase).
    pub ty: &'a Ident,
    /// The dynamics type of each phase (phase 0 first, with the scene's frames).
    pub phases: &'a [Ident],
    /// Joints, positions, speeds.
    pub n: usize,
    /// Bodies (joints of the full list: with mimic joints more than `n`), the rows of `f_ext`
    /// after the base's.
    pub bodies: usize,
    /// Positions.
    pub nq: usize,
    /// Speeds.
    pub nv: usize,
    /// The frame (`scene_wrench_k`) of each wrench that has one.
    pub wrench_frames: &'a [Option<String>],
}

/// `impl SceneDynamics for <shape.ty>`: forward dynamics (with the wrenches as `f_ext`), the
/// mass matrix, and inverse dynamics (computed torque), each a forward to the generated
/// function of the provider's phase; `Err` names a wrench without the frame it needs.
pub fn provider(scene: &Scene, sh: &Shape<'_>) -> Result<TokenStream, String> {
    let Shape { rt, ty, .. } = sh;
    let nvl = Literal::usize_unsuffixed(sh.nv);
    let f64 = paths::primitive("f64");
    let forward_args = as_arrays(
        &[
            ("q", sh.nq),
            ("v", sh.nv),
            ("tau", sh.n),
            ("w", 6 * scene.wrenches.len()),
        ],
        &quote!(return acc.fill(#f64::NAN);),
    );
    let mass_args = as_arrays(&[("q", sh.nq)], &quote!(return m.fill(#f64::NAN);));
    let (acc_ok, acc_err) = (paths::ok(quote!(acc)), paths::err(quote!(_)));
    let f_ext = f_ext(scene, sh)?;
    let forward = phase_match(sh, &quote!([#f64::NAN; #nvl]), |dy| {
        if scene.wrenches.is_empty() {
            quote!(#dy::forward_dynamics(q, v, tau))
        } else {
            quote!(#dy::forward_dynamics_with_wrenches(q, v, tau, &f_ext))
        }
    });
    let mass = phase_match(
        sh,
        &quote!([[#f64::NAN; #nvl]; #nvl]),
        |dy| quote!(#dy::mass_matrix(q)),
    );
    let inverse = inverse(scene, sh)?;
    Ok(quote! {
        impl #rt::scene::SceneDynamics for #ty {
            #[inline(always)]
            fn forward(&mut self, q: &[#f64], v: &[#f64], tau: &[#f64], w: &[#f64], acc: &mut [#f64]) {
                #forward_args
                let _ = w;
                #f_ext
                let a: [#f64; #nvl] = #forward;
                match <&mut [#f64; #nvl]>::try_from(&mut *acc) {
                    #acc_ok => *acc = a,
                    #acc_err => acc.fill(#f64::NAN),
                }
            }

            fn mass_matrix(&mut self, q: &[#f64], m: &mut [#f64]) {
                #mass_args
                let mm: [[#f64; #nvl]; #nvl] = #mass;
                for (row, dst) in mm.iter().zip(m.chunks_exact_mut(#nvl)) {
                    #rt::scene::copy_into(dst, row);
                }
            }

            fn inverse(&mut self, q: &[#f64], qd: &[#f64], qdd: &[#f64], w: &[#f64], tau: &mut [#f64]) {
                #inverse
            }
        }
    })
}

/// `match self.0 { k => <call on phase k's type>, … }`, `nan` for a phase out of range.
pub fn phase_match(
    sh: &Shape<'_>,
    nan: &TokenStream,
    call: impl Fn(&Ident) -> TokenStream,
) -> TokenStream {
    let arms = sh.phases.iter().enumerate().map(|(k, dy)| {
        let (k, c) = (Literal::usize_unsuffixed(k), call(dy));
        quote!(#k => #c,)
    });
    quote!(match self.0 { #(#arms)* _ => #nan })
}

/// The rows `f_ext` (one a body, the base's first on a free-floating base) of the wrench
/// values `w`: each in its body's frame at the body origin, an inertial-frame one rotated by
/// the body's rotation (the generated placement of its frame, or the base quaternion).
fn f_ext(scene: &Scene, sh: &Shape<'_>) -> Result<TokenStream, String> {
    if scene.wrenches.is_empty() {
        return Ok(TokenStream::new());
    }
    let (rt, dyn_ty) = (&sh.rt, &sh.phases[0]);
    let floating = scene.is_floating();
    let rows_n = Literal::usize_unsuffixed(sh.bodies + usize::from(floating));
    let f64 = paths::primitive("f64");
    let mut code = Vec::new();
    for (k, w) in scene.wrenches.iter().enumerate() {
        let is_base = w.body == BASE_BODY;
        let row = Literal::usize_unsuffixed(if is_base {
            0
        } else {
            w.body + usize::from(floating)
        });
        let rot = match (&sh.wrench_frames[k], is_base, w.frame) {
            (_, _, LoadFrame::Body) => None,
            (Some(fname), _, _) => {
                let pl = format_ident!("{}_placement", fname);
                Some(quote!(#dyn_ty::#pl(q).1))
            }
            (None, true, _) => Some(quote!(#rt::ode::quat_to_matrix(&[q[3], q[4], q[5], q[6]]))),
            (None, false, _) => return Err(format!("effects.wrench[{k}]: no frame")),
        };
        let (f, m) = wrench_value(k);
        let apply = match rot {
            None => quote! {
                for i in 0..3 {
                    f_ext[#row][i] += #f[i];
                    f_ext[#row][3 + i] += #m[i];
                }
            },
            Some(r) => quote! {
                let r: [[#f64; 3]; 3] = #r;
                for i in 0..3 {
                    f_ext[#row][i] += r[0][i] * #f[0] + r[1][i] * #f[1] + r[2][i] * #f[2];
                    f_ext[#row][3 + i] += r[0][i] * #m[0] + r[1][i] * #m[1] + r[2][i] * #m[2];
                }
            },
        };
        code.push(quote!({ #apply }));
    }
    Ok(quote! {
        let mut f_ext = [[0.0f64; 6]; #rows_n];
        #(#code)*
    })
}

/// The force and moment of wrench `k` in `w` (`[f64; 6W]`).
fn wrench_value(k: usize) -> (TokenStream, TokenStream) {
    let i = |j: usize| Literal::usize_unsuffixed(6 * k + j);
    let (f0, f1, f2, m0, m1, m2) = (i(0), i(1), i(2), i(3), i(4), i(5));
    (
        quote!([w[#f0], w[#f1], w[#f2]]),
        quote!([w[#m0], w[#m1], w[#m2]]),
    )
}

/// The body of `inverse`: the generated inverse dynamics minus the wrenches mapped to the
/// joints, `τ −= J_vᵀ f + J_ωᵀ m` (force and moment in base axes at the body origin; fixed
/// base only, as the scene allows computed torque only there); NaN without a computed-torque
/// drive (never called).
fn inverse(scene: &Scene, sh: &Shape<'_>) -> Result<TokenStream, String> {
    let f64 = paths::primitive("f64");
    if !matches!(scene.drives, kanegen_scene::Drives::ComputedTorque { .. }) || scene.is_floating()
    {
        return Ok(quote! {
            let _ = (q, qd, qdd, w);
            tau.fill(#f64::NAN);
        });
    }
    let (rt, dyn_ty) = (&sh.rt, &sh.phases[0]);
    let nl = Literal::usize_unsuffixed(sh.n);
    let args = as_arrays(
        &[
            ("q", sh.n),
            ("qd", sh.n),
            ("qdd", sh.n),
            ("w", 6 * scene.wrenches.len()),
        ],
        &quote!(return tau.fill(#f64::NAN);),
    );
    let mut compensate = Vec::new();
    for (k, w) in scene.wrenches.iter().enumerate() {
        let Some(fname) = &sh.wrench_frames[k] else {
            return Err(format!("effects.wrench[{k}]: no frame"));
        };
        let (pl, jac) = (
            format_ident!("{}_placement", fname),
            format_ident!("{}_jacobian", fname),
        );
        let (f, m) = wrench_value(k);
        let to_base = if w.frame == LoadFrame::Body {
            quote! {
                let r = #dyn_ty::#pl(q).1;
                let (f, m): ([#f64; 3], [#f64; 3]) = (
                    ::core::array::from_fn(|i| r[i][0] * f[0] + r[i][1] * f[1] + r[i][2] * f[2]),
                    ::core::array::from_fn(|i| r[i][0] * m[0] + r[i][1] * m[1] + r[i][2] * m[2]),
                );
            }
        } else {
            quote!()
        };
        compensate.push(quote! {{
            let (f, m): ([#f64; 3], [#f64; 3]) = (#f, #m);
            #to_base
            let jac = #dyn_ty::#jac(q);
            for j in 0..#nl {
                t[j] -= jac[0][j] * f[0] + jac[1][j] * f[1] + jac[2][j] * f[2]
                    + jac[3][j] * m[0] + jac[4][j] * m[1] + jac[5][j] * m[2];
            }
        }});
    }
    Ok(quote! {
        #args
        let _ = w;
        #[allow(unused_mut)]
        let mut t: [#f64; #nl] = #dyn_ty::inverse_dynamics(q, qd, qdd);
        #(#compensate)*
        #rt::scene::copy_into(tau, &t);
    })
}
