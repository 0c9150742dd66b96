//! A named frame's placement and geometric Jacobian (RBDA §4.4 and §4.5 in base coordinates) as
//! loops over the support path of its body, so that no expression grows with the model.
//!
//! Body `i`'s placement is the composition along its support path `κ(i)` (the joints from the
//! base to it, [`Tables::ancestor`]): `E_0i = E_i E_0λ(i)`, `p_0i = p_0λ(i) + E_0λ(i)ᵀ r_i`
//! (RBDA §2.8). A frame fixed to body `i` at `t_f` with orientation `R_fi` in its frame is at
//! `x_f = p_0i + E_0iᵀ t_f` with orientation `R_f = E_0iᵀ R_fi` (base axes). The Jacobian
//! column of a joint `j ∈ κ(i)` is its motion subspace in base coordinates, `ᴼS_j = [ω_j; v_j]`
//! (the velocity of the point at the base origin, [`Transform::apply_tr_motion`]), moved to the
//! frame's origin and written `[v_j + ω_j × x_f; ω_j]` (rows `[v; ω]`, Pinocchio's
//! `LOCAL_WORLD_ALIGNED`); the other columns are zero.

use super::spatial::{compose, cross, rot_tr, transforms, Transform};
use super::tables::Tables;
use crate::scalar::Scalar;

/// A frame fixed to a body: the body (`None`: the base) and the frame's origin and orientation
/// in the body's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame<S> {
    /// The body it is fixed to.
    pub body: Option<usize>,
    /// Its origin `t_f` in the body frame.
    pub translation: [S; 3],
    /// Its orientation `R_fi` in the body frame (frame axes to body axes).
    pub rotation: [[S; 3]; 3],
}

/// Whether joint `j` is on the support path of body `i` (`j ≤ i` on a chain).
#[inline(always)]
pub(crate) fn supports<S>(t: &Tables<'_, S>, i: usize, j: usize) -> bool {
    match t.ancestor {
        Some(anc) => anc.get(i * t.parent.len() + j).copied().unwrap_or(false),
        None => j <= i,
    }
}

/// The placements `x0[j] = (E_0j, p_0j)` of the bodies on the support path of body `i`, from
/// their joint transforms `x` (other entries left as they are).
#[inline(always)]
pub fn support_placements<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    i: usize,
    x: &[Transform<S>],
    x0: &mut [Transform<S>],
) {
    for j in 0..x.len().min(x0.len()).min(i + 1) {
        if !supports(t, i, j) {
            continue;
        }
        let parent = t.parent.get(j).copied().flatten();
        x0[j] = match parent.and_then(|l| x0.get(l)) {
            Some(p) => compose(&x[j], p),
            None => x[j],
        };
    }
}

/// The frame's origin `x_f = p_0i + E_0iᵀ t_f` in base coordinates, from the placements `x0` of
/// [`support_placements`].
#[inline(always)]
pub fn origin<S: Scalar + Copy>(frame: &Frame<S>, x0: &[Transform<S>]) -> [S; 3] {
    let Some(b) = frame.body.and_then(|i| x0.get(i)) else {
        return frame.translation;
    };
    let d = rot_tr(&b.e, &frame.translation);
    [b.r[0] + d[0], b.r[1] + d[1], b.r[2] + d[2]]
}

/// The frame's origin and orientation `R_f = E_0iᵀ R_fi` in base coordinates, from the
/// placements `x0` of [`support_placements`].
#[inline(always)]
pub fn pose<S: Scalar + Copy>(frame: &Frame<S>, x0: &[Transform<S>]) -> ([S; 3], [[S; 3]; 3]) {
    let Some(b) = frame.body.and_then(|i| x0.get(i)) else {
        return (frame.translation, frame.rotation);
    };
    let cols: [[S; 3]; 3] =
        core::array::from_fn(|c| rot_tr(&b.e, &core::array::from_fn(|r| frame.rotation[r][c])));
    let rotation = core::array::from_fn(|r| core::array::from_fn(|c| cols[c][r]));
    (origin(frame, x0), rotation)
}

/// The Jacobian's columns `[v; ω]` at the frame origin `xf`, one 6-vector per joint into
/// `cols` (zero off the support path), from the placements `x0` of [`support_placements`].
#[inline(always)]
pub fn jacobian_columns<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    frame: &Frame<S>,
    x0: &[Transform<S>],
    xf: &[S; 3],
    cols: &mut [[S; 6]],
) {
    for (j, col) in cols.iter_mut().enumerate() {
        *col = [S::zero(); 6];
        let on_path = frame.body.is_some_and(|i| supports(t, i, j));
        let (true, Some(s), Some(x)) = (on_path, t.s.get(j), x0.get(j)) else {
            continue;
        };
        let so = x.apply_tr_motion(s);
        let w = [so[0], so[1], so[2]];
        let wx = cross(&w, xf);
        *col = [
            so[3] + wx[0],
            so[4] + wx[1],
            so[5] + wx[2],
            w[0],
            w[1],
            w[2],
        ];
    }
}

/// The joint transforms and placements of the support path of `frame`'s body at the joint
/// positions `q`, on the stack of `N` joints.
#[inline(always)]
pub(crate) fn placements<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    frame: &Frame<S>,
    q: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> [Transform<S>; N] {
    let zero = S::zero();
    let id = Transform {
        e: [[zero; 3]; 3],
        r: [zero; 3],
    };
    let (mut x, mut x0) = ([id; N], [id; N]);
    if let Some(i) = frame.body {
        let upto = (i + 1).min(N).min(q.len());
        transforms(t, &q[..upto], sincos, &mut x[..upto]);
        support_placements(t, i, &x, &mut x0);
    }
    x0
}

/// The frame's placement `(x_f, R_f)` in the base frame at `q`.
#[inline]
pub fn frame_placement<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    frame: &Frame<S>,
    q: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> ([S; 3], [[S; 3]; 3]) {
    pose(frame, &placements::<S, N>(t, frame, q, sincos))
}

/// The frame's geometric Jacobian at `q`: rows `[v; ω]` of its origin in base axes, one column
/// per joint.
#[inline]
pub fn frame_jacobian<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    frame: &Frame<S>,
    q: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; N]; 6] {
    let x0 = placements::<S, N>(t, frame, q, sincos);
    let xf = origin(frame, &x0);
    let mut cols = [[S::zero(); 6]; N];
    jacobian_columns(t, frame, &x0, &xf, &mut cols);
    core::array::from_fn(|r| core::array::from_fn(|j| cols[j][r]))
}
