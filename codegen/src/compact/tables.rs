//! The numbers of a model that the compact form's tables hold (`kanegen_runtime::compact::Tables`).

use crate::options::Options;
use kanegen_model::{JointKind, Model};

/// A 3×3 matrix, rows first.
pub type M3 = [[f64; 3]; 3];

fn transpose(m: &M3) -> M3 {
    core::array::from_fn(|i| core::array::from_fn(|j| m[j][i]))
}

fn mul(a: &M3, b: &M3) -> M3 {
    core::array::from_fn(|i| core::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// The numbers of `kanegen_runtime::compact::Tables` for a model, one entry per joint (its
/// fields, in `Vec`s; the module docs of `kanegen_runtime::compact` derive `A`, `B`, `C`).
#[derive(Clone, Debug)]
pub struct Numbers {
    /// `λ(j)`.
    pub parent: Vec<Option<usize>>,
    /// Revolute (else prismatic).
    pub revolute: Vec<bool>,
    /// `A_j`.
    pub a: Vec<M3>,
    /// `B_j`.
    pub b: Vec<M3>,
    /// `C_j`.
    pub c: Vec<M3>,
    /// `l_j`.
    pub l: Vec<[f64; 3]>,
    /// `Υ_j u_j` of a prismatic joint.
    pub slide: Vec<[f64; 3]>,
    /// `S_j`.
    pub s: Vec<[f64; 6]>,
    /// The spatial inertias, `[m, h, Ī upper triangle]`.
    pub inertia: Vec<[f64; 10]>,
    /// `ancestor[i][j]` on a tree (`None`: a chain).
    pub ancestor: Option<Vec<Vec<bool>>>,
    /// `a₀ = [0; −g]`.
    pub a0: [f64; 6],
}

/// `(A, B, C, slide, S)` of one joint (the module docs of `kanegen_runtime::compact`).
fn joint_numbers(jp: &kanegen_dynamics::JointParams<f64>) -> (M3, M3, M3, [f64; 3], [f64; 6]) {
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

/// The compact tables of `model` under `opts`: the joints' placements and axes of
/// [`kanegen_dynamics::Params`], the inertias regrouped when [`Options::regroup`] is on (the
/// payload body neither gives nor receives), gravity as `a₀`.
#[must_use]
pub fn numbers(model: &Model, opts: &Options) -> Numbers {
    let n = model.dof();
    let keep: &[usize] = if opts.runtime_payload { &[n - 1] } else { &[] };
    let p = if opts.regroup {
        kanegen_dynamics::regroup::regrouped::<f64>(model, None, keep).params
    } else {
        kanegen_dynamics::Params::<f64>::new(model)
    };
    let mut t = Numbers {
        parent: vec![],
        revolute: vec![],
        a: vec![],
        b: vec![],
        c: vec![],
        l: vec![],
        slide: vec![],
        s: vec![],
        inertia: vec![],
        ancestor: None,
        a0: [0.0; 6],
    };
    for jp in &p.joints {
        let (a, b, c, slide, s) = joint_numbers(jp);
        t.a.push(a);
        t.b.push(b);
        t.c.push(c);
        t.slide.push(slide);
        t.s.push(s);
        t.l.push(jp.l.0);
        let (i, ib) = (&jp.inertia, jp.inertia.ibar.0);
        t.inertia.push([
            i.m, i.h.0[0], i.h.0[1], i.h.0[2], ib[0][0], ib[0][1], ib[0][2], ib[1][1], ib[1][2],
            ib[2][2],
        ]);
        t.parent.push(jp.parent);
        t.revolute.push(jp.kind == JointKind::Revolute);
    }
    // On a tree, row `i` of `H` keeps the entries of `i`'s ancestors (RBDA §6.2: the others
    // are zero); a chain's every `j < i` is one.
    if !model.is_chain() {
        t.ancestor = Some(
            (0..n)
                .map(|i| {
                    let mut anc = vec![false; n];
                    let mut j = Some(i);
                    while let Some(k) = j {
                        anc[k] = true;
                        j = t.parent[k];
                    }
                    anc
                })
                .collect(),
        );
    }
    if let Some(g) = opts.gravity {
        t.a0 = [0.0, 0.0, 0.0, -g[0], -g[1], -g[2]];
    }
    t
}
