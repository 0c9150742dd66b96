//! A model's numbers as the runtime kernels read them ([`kanegen_runtime::compact`]), built from
//! its [`Params`], and the kernels' scratch in `Vec`s: the model and the data (Pinocchio's split)
//! of the run-time path and of the compact form's tables, which `kanegen-codegen` writes out as
//! `const`s from the same [`KernelTables`].

use crate::base::{FloatingBase, FloatingState, BASE_BODY};
use crate::linalg::Vec3;
use crate::loads::{ExternalWrench, LoadFrame, Loads};
use crate::params::{JointParams, Params};
use kanegen_model::JointKind;
use kanegen_runtime::compact::aba::{aba_floating_on_world, aba_on_world};
use kanegen_runtime::compact::floating::Base;
use kanegen_runtime::compact::spatial::{rot, transforms, world};
use kanegen_runtime::compact::{
    Articulated, Bodies, FloatingRoot, Frame, Rates, Tables, Transform,
};

/// A 3×3 matrix, rows first.
pub type M3 = [[f64; 3]; 3];

fn transpose(m: &M3) -> M3 {
    core::array::from_fn(|i| core::array::from_fn(|j| m[j][i]))
}

fn mul(a: &M3, b: &M3) -> M3 {
    core::array::from_fn(|i| core::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// The numbers of [`Tables`] for a model, one entry per joint (its fields, in `Vec`s; the module
/// docs of [`kanegen_runtime::compact`] derive `A`, `B`, `C`).
#[derive(Clone, Debug)]
pub struct KernelTables {
    /// `λ(j)`.
    pub parent: Vec<Option<usize>>,
    /// Revolute (else prismatic).
    pub revolute: Vec<bool>,
    /// The numbers: `A`, `B`, `C`, `l`, the slides, `S`, the inertias and `a₀`.
    pub numbers: TablesIn<f64>,
    /// On a tree, whether joint `j` is joint `i` or one of its ancestors, entry `i N + j` (rows
    /// first); `None` on a chain.
    pub ancestor: Option<Vec<bool>>,
    /// The model's named frames, in its order.
    pub frames: Vec<Frame<f64>>,
    /// A free-floating base's inertia and gravity (`None`: a fixed base, gravity in `a0`).
    pub base: Option<Base<f64>>,
}

/// `(A, B, C, slide, S)` of one joint (the module docs of [`kanegen_runtime::compact`]).
fn joint_numbers(jp: &JointParams<f64>) -> (M3, M3, M3, [f64; 3], [f64; 6]) {
    let u = jp.axis.0;
    let ups = jp.upsilon.0;
    let uu: M3 = core::array::from_fn(|i| core::array::from_fn(|j| u[i] * u[j]));
    let one_minus: M3 =
        core::array::from_fn(|i| core::array::from_fn(|j| f64::from(u8::from(i == j)) - uu[i][j]));
    let skew: M3 = [[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]];
    match jp.kind {
        JointKind::Revolute => (
            transpose(&mul(&ups, &uu)),
            transpose(&mul(&ups, &one_minus)),
            transpose(&mul(&ups, &skew)),
            [0.0; 3],
            [u[0], u[1], u[2], 0.0, 0.0, 0.0],
        ),
        JointKind::Prismatic => (
            transpose(&ups),
            [[0.0; 3]; 3],
            [[0.0; 3]; 3],
            core::array::from_fn(|i| (0..3).map(|k| ups[i][k] * u[k]).sum()),
            [0.0, 0.0, 0.0, u[0], u[1], u[2]],
        ),
    }
}

/// A spatial inertia as the kernels hold it: `[m, h (3), Ī upper triangle (6)]`.
#[must_use]
pub fn inertia_row(i: &crate::spatial::RbInertia<f64>) -> [f64; 10] {
    let ib = i.ibar.0;
    [
        i.m, i.h.0[0], i.h.0[1], i.h.0[2], ib[0][0], ib[0][1], ib[0][2], ib[1][1], ib[1][2],
        ib[2][2],
    ]
}

impl KernelTables {
    /// The tables of `p` (its joints' placements, axes and inertias as they are), with gravity
    /// `g` in the base frame as `a₀` (`None`: none).
    #[must_use]
    pub fn new(p: &Params<f64>, gravity: Option<[f64; 3]>) -> Self {
        let n = p.joints.len();
        let mut t = KernelTables {
            parent: Vec::with_capacity(n),
            revolute: Vec::with_capacity(n),
            numbers: TablesIn {
                a: Vec::with_capacity(n),
                b: Vec::with_capacity(n),
                c: Vec::with_capacity(n),
                l: Vec::with_capacity(n),
                slide: Vec::with_capacity(n),
                s: Vec::with_capacity(n),
                inertia: Vec::with_capacity(n),
                a0: [0.0; 6],
            },
            ancestor: None,
            frames: p
                .frames
                .iter()
                .map(|f| Frame {
                    body: f.parent,
                    translation: f.translation.0,
                    rotation: f.rotation.0,
                })
                .collect(),
            base: None,
        };
        for jp in &p.joints {
            let (a, b, c, slide, s) = joint_numbers(jp);
            let x = &mut t.numbers;
            x.a.push(a);
            x.b.push(b);
            x.c.push(c);
            x.slide.push(slide);
            x.s.push(s);
            x.l.push(jp.l.0);
            x.inertia.push(inertia_row(&jp.inertia));
            t.parent.push(jp.parent);
            t.revolute.push(jp.kind == JointKind::Revolute);
        }
        let chain = (0..n).all(|j| t.parent[j] == j.checked_sub(1));
        if !chain {
            t.ancestor = Some(ancestors(&t.parent));
        }
        if let Some(g) = gravity {
            t.numbers.a0 = [0.0, 0.0, 0.0, -g[0], -g[1], -g[2]];
        }
        t
    }

    /// The tables of `p` on the free-floating base `base` under gravity `g` (inertial frame):
    /// `a₀` zero, the base's inertia and gravity in [`KernelTables::base`].
    #[must_use]
    pub fn floating(p: &Params<f64>, base: &FloatingBase<f64>, gravity: Option<[f64; 3]>) -> Self {
        let mut t = KernelTables::new(p, None);
        t.base = Some(Base {
            inertia: inertia_row(&base.inertia),
            gravity,
        });
        t
    }

    /// The number of joints.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.parent.len()
    }

    /// The tables as the kernels take them.
    #[must_use]
    pub fn tables(&self) -> Tables<'_, f64> {
        self.numbers.tables(self)
    }
}

/// On a tree, row `i` of `H` keeps the entries of `i`'s ancestors (RBDA §6.2: the others are
/// zero): entry `i N + j` says whether `j` is `i` or an ancestor of it.
fn ancestors(parent: &[Option<usize>]) -> Vec<bool> {
    let n = parent.len();
    let mut anc = vec![false; n * n];
    for i in 0..n {
        let mut j = Some(i);
        while let Some(k) = j {
            anc[i * n + k] = true;
            j = parent[k];
        }
    }
    anc
}

/// The numbers of [`KernelTables`] in another scalar `S` (several states' lanes side by side, a
/// counting scalar), in `Vec`s; the tables' structure (parents, joint kinds, ancestors) stays
/// theirs ([`TablesIn::tables`]).
#[derive(Clone, Debug)]
pub struct TablesIn<S> {
    /// `A_j`.
    pub a: Vec<[[S; 3]; 3]>,
    /// `B_j`.
    pub b: Vec<[[S; 3]; 3]>,
    /// `C_j`.
    pub c: Vec<[[S; 3]; 3]>,
    /// `l_j`.
    pub l: Vec<[S; 3]>,
    /// `Υ_j u_j` of a prismatic joint.
    pub slide: Vec<[S; 3]>,
    /// `S_j`.
    pub s: Vec<[S; 6]>,
    /// The spatial inertias, `[m, h, Ī upper triangle]`.
    pub inertia: Vec<[S; 10]>,
    /// `a₀ = [0; −g]`.
    pub a0: [S; 6],
}

impl<S: kanegen_runtime::Scalar + Copy> TablesIn<S> {
    /// The numbers of `t`, each mapped by `s`.
    pub fn new(t: &KernelTables, s: impl Fn(f64) -> S) -> Self {
        let (t, m3) = (&t.numbers, |m: &M3| m.map(|r| r.map(&s)));
        TablesIn {
            a: t.a.iter().map(m3).collect(),
            b: t.b.iter().map(m3).collect(),
            c: t.c.iter().map(m3).collect(),
            l: t.l.iter().map(|v| v.map(&s)).collect(),
            slide: t.slide.iter().map(|v| v.map(&s)).collect(),
            s: t.s.iter().map(|v| v.map(&s)).collect(),
            inertia: t.inertia.iter().map(|v| v.map(&s)).collect(),
            a0: t.a0.map(&s),
        }
    }

    /// The tables as the kernels take them, with the structure of `t` (the tables these numbers
    /// came from).
    #[must_use]
    pub fn tables<'a>(&'a self, t: &'a KernelTables) -> Tables<'a, S> {
        kanegen_runtime::tables_with_numbers!(&t.parent, &t.revolute, t.ancestor.as_deref(); self)
    }
}

/// The kernels' per-body scratch for `N` joints in `Vec`s: [`Bodies`] and [`Articulated`], made
/// once and overwritten by every call (the data of Pinocchio's model/data split).
#[derive(Clone, Debug)]
pub struct KernelData {
    bodies: BodyVecs<f64>,
    articulated: ArticulatedVecs<f64>,
    f_ext: Vec<[f64; 6]>,
    zero_tau: Vec<f64>,
}

/// The storage of [`Bodies`] for `n` joints in `Vec`s, on any scalar (the tracer's too).
#[derive(Clone, Debug)]
pub struct BodyVecs<S> {
    x: Vec<Transform<S>>,
    x0: Vec<Transform<S>>,
    s0: Vec<[S; 6]>,
    i0: Vec<[S; 10]>,
}

impl<S: kanegen_runtime::Scalar + Copy> BodyVecs<S> {
    /// Zeroed storage for `n` joints.
    #[must_use]
    pub fn new(n: usize) -> Self {
        let zero = S::zero();
        let id = Transform {
            e: [[zero; 3]; 3],
            r: [zero; 3],
        };
        BodyVecs {
            x: vec![id; n],
            x0: vec![id; n],
            s0: vec![[zero; 6]; n],
            i0: vec![[zero; 10]; n],
        }
    }

    /// The storage as the kernels' scratch.
    pub fn bodies(&mut self) -> Bodies<'_, S> {
        Bodies {
            x: &mut self.x,
            x0: &mut self.x0,
            s0: &mut self.s0,
            i0: &mut self.i0,
        }
    }
}

impl KernelData {
    /// Scratch for `n` joints.
    #[must_use]
    pub fn new(n: usize) -> Self {
        KernelData {
            bodies: BodyVecs::new(n),
            articulated: ArticulatedVecs::new(n),
            f_ext: vec![[0.0; 6]; n],
            zero_tau: vec![0.0; n],
        }
    }

    /// The scratch as the kernels take it: the bodies, the articulated-body quantities, and a
    /// per-body wrench buffer.
    pub fn split(&mut self) -> (Bodies<'_, f64>, Articulated<'_, f64>, &mut [[f64; 6]]) {
        let b = self.bodies.bodies();
        (b, self.articulated.articulated(), &mut self.f_ext)
    }
}

/// The storage of [`Articulated`] for `n` joints in `Vec`s, on any scalar (the tracer's too).
#[derive(Clone, Debug)]
pub struct ArticulatedVecs<S> {
    six: [Vec<[S; 6]>; 5],
    ia: Vec<[S; 21]>,
    du: [Vec<S>; 2],
}

impl<S: kanegen_runtime::Scalar + Copy> ArticulatedVecs<S> {
    /// Zeroed storage for `n` joints.
    #[must_use]
    pub fn new(n: usize) -> Self {
        let zero = S::zero();
        ArticulatedVecs {
            six: core::array::from_fn(|_| vec![[zero; 6]; n]),
            ia: vec![[zero; 21]; n],
            du: [vec![zero; n], vec![zero; n]],
        }
    }

    /// The storage as the articulated-body kernel's scratch.
    pub fn articulated(&mut self) -> Articulated<'_, S> {
        let [v, c, pa, ui, a] = &mut self.six;
        let [d, u] = &mut self.du;
        Articulated {
            v,
            c,
            ia: &mut self.ia,
            pa,
            ui,
            d,
            u,
            a,
        }
    }
}

/// Forward dynamics on the run-time path: the articulated-body kernel
/// ([`kanegen_runtime::compact::aba`]) on the tables `t` with the scratch `data`, into `out`.
/// On a fixed base (`floating = None`) `out = q̈`; on a free-floating one `out = ν̇ =
/// [v̇_b; ω̇_b; q̈]` as [`crate::algorithms::aba::floating`] writes it, `q`, `qd` the joints'
/// (the tables then hold no gravity: it comes from `loads`). Loads as the algorithms of this crate
/// take them (drives, gravity, wrenches in a body's or the base's frame; `tau = None`: zero);
/// `armature` as [`crate::algorithms::aba::forward_dynamics_in`]'s. Allocates nothing.
#[allow(clippy::too_many_arguments)]
pub fn forward_dynamics(
    t: &KernelTables,
    data: &mut KernelData,
    floating: Option<(&FloatingBase<f64>, &FloatingState<f64>)>,
    q: &[f64],
    qd: &[f64],
    loads: &Loads<f64>,
    armature: Option<&[f64]>,
    out: &mut [f64],
) {
    let tables = t.tables();
    let zero_tau = &data.zero_tau;
    let mut b = data.bodies.bodies();
    let mut ab = data.articulated.articulated();
    let f_ext = &mut data.f_ext;
    transforms(&tables, q, f64::sin_cos, b.x);
    world(&tables, tables.inertia, &mut b);
    // R₀ᵀ of a free-floating base: inertial-frame vectors into base coordinates.
    let r0t = floating.map(|(_, st)| st.rotation.transpose().0);
    let external = &loads.external;
    if !external.is_empty() {
        body_wrenches(external, r0t.as_ref(), b.x0, f_ext);
    }
    let rates = Rates {
        qd,
        tau: loads.tau.as_deref().unwrap_or(zero_tau),
        f_ext: (!external.is_empty()).then_some(&*f_ext),
        armature,
    };
    match (floating, r0t) {
        (Some((base, st)), Some(r0t)) => {
            let (w, v) = (&st.omega_b.0, &st.v_b.0);
            let root = FloatingRoot {
                inertia: inertia_row(&base.inertia),
                v: [w[0], w[1], w[2], v[0], v[1], v[2]],
                f_ext: base_wrench(external, &r0t),
                gravity: loads.gravity.as_ref().map(|g| rot(&r0t, &g.0)),
            };
            aba_floating_on_world(&tables, rates, &root, &b, &mut ab, out);
        }
        _ => aba_on_world(&tables, rates, &b, &mut ab, out),
    }
}

/// A wrench `[force; moment]` in the frame whose rotation from the loads' frame is `e` (`None`:
/// the loads are in that frame already).
fn wrench_in(w: &ExternalWrench<f64>, e: Option<&[[f64; 3]; 3]>) -> [f64; 6] {
    let turn = |v: &Vec3<f64>| match e {
        Some(e) => rot(e, &v.0),
        None => v.0,
    };
    let (f, m) = (turn(&w.force), turn(&w.moment));
    [f[0], f[1], f[2], m[0], m[1], m[2]]
}

/// Each body's external wrenches summed in its own frame into `f_ext` (`[force; moment]` at its
/// origin): body-frame wrenches as they are, base-frame (inertial-frame) ones rotated by `E_0j`
/// (`E_0j R₀ᵀ` on a free-floating base, `r0t` = `R₀ᵀ`).
fn body_wrenches(
    external: &[ExternalWrench<f64>],
    r0t: Option<&[[f64; 3]; 3]>,
    x0: &[Transform<f64>],
    f_ext: &mut [[f64; 6]],
) {
    f_ext.fill([0.0; 6]);
    for w in external {
        let (Some(f), Some(x)) = (f_ext.get_mut(w.body), x0.get(w.body)) else {
            continue;
        };
        let local = match (w.frame, r0t) {
            (LoadFrame::Body, _) => wrench_in(w, None),
            (LoadFrame::Base, None) => wrench_in(w, Some(&x.e)),
            (LoadFrame::Base, Some(r)) => {
                let e = core::array::from_fn(|i| {
                    core::array::from_fn(|j| (0..3).map(|k| x.e[i][k] * r[k][j]).sum())
                });
                wrench_in(w, Some(&e))
            }
        };
        for (a, b) in f.iter_mut().zip(local) {
            *a += b;
        }
    }
}

/// The external wrench on a free-floating base body, `[force; moment]` in its frame (`r0t` =
/// `R₀ᵀ` takes inertial-frame ones there), `None` when none acts on it.
fn base_wrench(external: &[ExternalWrench<f64>], r0t: &[[f64; 3]; 3]) -> Option<[f64; 6]> {
    let mut on_base = external.iter().filter(|w| w.body == BASE_BODY).peekable();
    on_base.peek()?;
    let mut sum = [0.0; 6];
    for w in on_base {
        let e = (w.frame == LoadFrame::Base).then_some(r0t);
        for (a, b) in sum.iter_mut().zip(wrench_in(w, e)) {
            *a += b;
        }
    }
    Some(sum)
}
