//! The parallel-axis shift of a rigid body's rotational inertia (Steiner's theorem; RBDA
//! eq. (2.63), spatial_v2 `mcI`), generic over the scalar: the one the run-time algorithms
//! (`kanegen-dynamics`: a body's inertia about its joint frame, spatial inertias from a centre
//! of mass) trace and run.
//!
//! ```
//! use kanegen_runtime::inertia::parallel_axis;
//! let i = parallel_axis(&2.0, &[0.0, 0.0, 3.0], &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
//! // 2·3² about the x and y axes, nothing about z.
//! assert_eq!(i, [[19.0, 0.0, 0.0], [0.0, 19.0, 0.0], [0.0, 0.0, 1.0]]);
//! ```

use crate::scalar::Scalar;

/// `Ī = I_c + m c̃ c̃ᵀ` (`= I_c + m (|c|² 1 − c cᵀ)`): the inertia `I_c` of a body of mass `m`
/// about its centre of mass, shifted to the point from which the centre of mass is at `c` (same
/// axes). In the operations, and their order, of the matrix product `c̃ c̃ᵀ` (each entry a
/// three-term sum of products accumulated from zero), scaled by `m` and added to `I_c`, so a
/// tracer counts what it always did.
pub fn parallel_axis<S: Scalar>(m: &S, c: &[S; 3], inertia_com: &[[S; 3]; 3]) -> [[S; 3]; 3] {
    let [x, y, z] = c.clone();
    let zero = S::zero;
    // c̃, the cross-product matrix of c.
    let skew = [
        [zero(), -z.clone(), y.clone()],
        [z, zero(), -x.clone()],
        [-y, x, zero()],
    ];
    // (c̃ c̃ᵀ)_rs = row r of c̃ · row s of c̃.
    let dot = |r: usize, s: usize| {
        zero()
            + skew[r][0].clone() * skew[s][0].clone()
            + skew[r][1].clone() * skew[s][1].clone()
            + skew[r][2].clone() * skew[s][2].clone()
    };
    let product: [[S; 3]; 3] = core::array::from_fn(|r| core::array::from_fn(|s| dot(r, s)));
    let shift: [[S; 3]; 3] =
        core::array::from_fn(|r| core::array::from_fn(|s| m.clone() * product[r][s].clone()));
    core::array::from_fn(|r| {
        core::array::from_fn(|s| inertia_com[r][s].clone() + shift[r][s].clone())
    })
}
