//! The model's numbers that the compact kernels loop over, and the kernels' scratch.

use super::spatial::Transform;
use crate::scalar::Scalar;

/// A model's numbers as the compact kernels read them (one joint and its body per entry,
/// `λ(j) < j`), in the model's body frames (RBDA §4.4). Every slice has one entry per joint
/// (`N`); a generated type holds one as a `const` of `'static` slices, the tracer builds one
/// from `Vec`s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tables<'a, S> {
    /// Each joint's parent body `λ(j) < j` (`None`: the base).
    pub parent: &'a [Option<usize>],
    /// Whether joint `j` is revolute (else prismatic).
    pub revolute: &'a [bool],
    /// `E_j = A_j + cos q_j B_j + sin q_j C_j` ([module docs](super)): `A_j`.
    pub a: &'a [[[S; 3]; 3]],
    /// `B_j` ([module docs](super)).
    pub b: &'a [[[S; 3]; 3]],
    /// `C_j` ([module docs](super)).
    pub c: &'a [[[S; 3]; 3]],
    /// Joint origin `l_j` in the parent body frame.
    pub l: &'a [[S; 3]],
    /// `Υ_j u_j` of a prismatic joint (zero for a revolute one): `r_j = l_j + q_j Υ_j u_j`.
    pub slide: &'a [[S; 3]],
    /// Motion subspace `S_j` (`[u; 0]` revolute, `[0; u]` prismatic; RBDA Table 4.1).
    pub s: &'a [[S; 6]],
    /// Spatial inertia of body `j` about its origin, `[m, h (3), Ī_xx, Ī_xy, Ī_xz, Ī_yy, Ī_yz,
    /// Ī_zz]` (RBDA eq. (2.63)).
    pub inertia: &'a [[S; 10]],
    /// On a tree, whether joint `j` is joint `i` or one of its ancestors (entry `i N + j`, rows
    /// first); `None` on a chain, where every `j ≤ i` is.
    pub ancestor: Option<&'a [bool]>,
    /// The base's spatial acceleration `a₀ = [0; −g]` (RBDA §5.3; zero without gravity).
    pub a0: [S; 6],
}

/// Each body's joint transform, then its placement, motion subspace and spatial inertia in base
/// coordinates: the kernels' per-body scratch (one entry per joint), filled by
/// [`transforms`](super::spatial::transforms) and [`world`](super::spatial::world).
#[derive(Debug)]
pub struct Bodies<'a, S> {
    /// `Xup_i = XJ(q_i) Xtree_i` as `(E_i, r_i)`.
    pub x: &'a mut [Transform<S>],
    /// `(E_0i, p_0i)`: `E_0i` rotates base to body `i` coordinates, `p_0i` is its origin.
    pub x0: &'a mut [Transform<S>],
    /// `ᴼX_i S_i`.
    pub s0: &'a mut [[S; 6]],
    /// `ᴼX_i* I_i ⁱX_O` (about the base origin, RBDA eq. (2.66)); the CRBA sums composite
    /// inertias in it.
    pub i0: &'a mut [[S; 10]],
}

/// Storage of `N` joints for [`Bodies`], on the stack: what the const-`N` entry points (and so
/// generated code) hand to the kernels.
#[derive(Clone, Copy, Debug)]
pub struct BodyStore<S, const N: usize> {
    x: [Transform<S>; N],
    x0: [Transform<S>; N],
    s0: [[S; 6]; N],
    i0: [[S; 10]; N],
}

impl<S: Scalar + Copy, const N: usize> BodyStore<S, N> {
    /// Zeroed storage.
    #[inline(always)]
    #[must_use]
    pub fn new() -> Self {
        let zero = S::zero();
        let x = Transform {
            e: [[zero; 3]; 3],
            r: [zero; 3],
        };
        BodyStore {
            x: [x; N],
            x0: [x; N],
            s0: [[zero; 6]; N],
            i0: [[zero; 10]; N],
        }
    }

    /// The storage as the kernels' scratch.
    #[inline(always)]
    pub fn bodies(&mut self) -> Bodies<'_, S> {
        Bodies {
            x: &mut self.x,
            x0: &mut self.x0,
            s0: &mut self.s0,
            i0: &mut self.i0,
        }
    }
}

impl<S: Scalar + Copy, const N: usize> Default for BodyStore<S, N> {
    #[inline(always)]
    fn default() -> Self {
        Self::new()
    }
}

/// The numbers of a model's `f64` [`Tables`] of `N` joints in another scalar `S` (a
/// [`Lane`](crate::lanes::Lane) of several states), on the stack: what a generated compact
/// `NAME_lanes` runs its kernel on. Each number is `S::constant` of the table's.
#[derive(Clone, Copy, Debug)]
pub struct TablesStore<S, const N: usize> {
    a: [[[S; 3]; 3]; N],
    b: [[[S; 3]; 3]; N],
    c: [[[S; 3]; 3]; N],
    l: [[S; 3]; N],
    slide: [[S; 3]; N],
    s: [[S; 6]; N],
    inertia: [[S; 10]; N],
    a0: [S; 6],
}

impl<S: Scalar + Copy, const N: usize> TablesStore<S, N> {
    /// The numbers of `t` (at least `N` joints) in `S`.
    #[inline(always)]
    #[must_use]
    pub fn new(t: &Tables<'_, f64>) -> Self {
        let x = |v: &f64| S::constant(*v);
        let m = |j: usize, m: &[[[f64; 3]; 3]]| {
            m.get(j)
                .map_or([[S::zero(); 3]; 3], |m| m.map(|r| r.each_ref().map(x)))
        };
        let v = |j: usize, v: &[[f64; 3]]| v.get(j).map_or([S::zero(); 3], |v| v.each_ref().map(x));
        TablesStore {
            a: core::array::from_fn(|j| m(j, t.a)),
            b: core::array::from_fn(|j| m(j, t.b)),
            c: core::array::from_fn(|j| m(j, t.c)),
            l: core::array::from_fn(|j| v(j, t.l)),
            slide: core::array::from_fn(|j| v(j, t.slide)),
            s: core::array::from_fn(|j| t.s.get(j).map_or([S::zero(); 6], |v| v.each_ref().map(x))),
            inertia: core::array::from_fn(|j| {
                t.inertia
                    .get(j)
                    .map_or([S::zero(); 10], |v| v.each_ref().map(x))
            }),
            a0: t.a0.each_ref().map(x),
        }
    }

    /// The tables in `S`, with the structure (parents, joint kinds, ancestors) of `t`.
    #[inline(always)]
    #[must_use]
    pub fn tables<'a>(&'a self, t: &Tables<'a, f64>) -> Tables<'a, S> {
        crate::tables_with_numbers!(t.parent, t.revolute, t.ancestor; self)
    }
}

/// A [`Tables`] of the structure `parent`, `revolute`, `ancestor` (slices) and the numbers held
/// in the fields `a`, `b`, `c`, `l`, `slide`, `s`, `inertia` (arrays or `Vec`s) and `a0` of
/// `numbers`: how [`TablesStore`] and the run-time path's tables in another scalar
/// (`kanegen_dynamics::kernels::TablesIn`) lend theirs to the kernels.
#[macro_export]
macro_rules! tables_with_numbers {
    ($parent:expr, $revolute:expr, $ancestor:expr; $numbers:expr) => {
        $crate::compact::Tables {
            parent: $parent,
            revolute: $revolute,
            a: &$numbers.a,
            b: &$numbers.b,
            c: &$numbers.c,
            l: &$numbers.l,
            slide: &$numbers.slide,
            s: &$numbers.s,
            inertia: &$numbers.inertia,
            ancestor: $ancestor,
            a0: $numbers.a0,
        }
    };
}
