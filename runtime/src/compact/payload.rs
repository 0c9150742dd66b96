//! A runtime payload's spatial inertia as the last body's row of the inertia table.

use crate::scalar::Scalar;

/// The 10-entry spatial inertia (`[m, h, Ī upper triangle]`, [`Tables::inertia`](super::Tables))
/// of a body of mass `m`, centre of mass `c` and inertia `ic` about the centre of mass:
/// `h = m c`, `Ī = I_c + m (|c|² 1 − c cᵀ)` (RBDA eq. (2.63), parallel axes).
#[inline(always)]
pub fn payload_inertia<S: Scalar + Copy>(m: S, c: &[S; 3], ic: &[[S; 3]; 3]) -> [S; 10] {
    let cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    [
        m,
        m * c[0],
        m * c[1],
        m * c[2],
        ic[0][0] + m * (cc - c[0] * c[0]),
        ic[0][1] - m * c[0] * c[1],
        ic[0][2] - m * c[0] * c[2],
        ic[1][1] + m * (cc - c[1] * c[1]),
        ic[1][2] - m * c[1] * c[2],
        ic[2][2] + m * (cc - c[2] * c[2]),
    ]
}

/// `inertia` (of `N` bodies) with its last body's row replaced by the payload's
/// ([`payload_inertia`]).
#[inline(always)]
pub fn with_payload<S: Scalar + Copy, const N: usize>(
    inertia: &[[S; 10]],
    m: S,
    c: &[S; 3],
    ic: &[[S; 3]; 3],
) -> [[S; 10]; N] {
    let mut t = [[S::zero(); 10]; N];
    for (row, given) in t.iter_mut().zip(inertia) {
        *row = *given;
    }
    if let Some(last) = t.last_mut() {
        *last = payload_inertia(m, c, ic);
    }
    t
}
