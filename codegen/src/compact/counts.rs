//! The operation counts of a compact type's functions: the runtime kernels
//! (`kanegen_runtime::compact`) run on the tracer [`Sym`], with every number of the tables, the
//! payload and the arguments a symbolic *input* (so no constant folding hides a multiplication
//! that the loops really do), counted under [`Convention::Paper`]: every operation the kernel
//! executes, which is what the compiled loops execute (their tables are read from memory).

use crate::compact::tables::Numbers;
use kanegen_runtime::compact::{self as k, Tables};
use kanegen_runtime::Scalar;
use kanegen_trace::sym::{Convention, Counts, Sym, Tracer};
use kanegen_trace::Function;

/// The most joints whose kernels the generator traces: the kernels are generic over the number
/// of joints, and each size traced instantiates them on `Sym` once more in this crate (compile
/// time). Above, a compact type reports the unrolled form's counts, and its header says so.
pub const MAX_N: usize = 64;

/// Calls `$f::<N>(args)` for `N = $n` among the listed sizes (`None` for another).
macro_rules! at_size {
    ($n:expr, $f:ident($a:expr, $b:expr, $c:expr), [$($k:literal)*]) => {
        match $n {
            $($k => Some($f::<$k>($a, $b, $c)),)*
            _ => None,
        }
    };
}

/// The traced counts of the kernel that the compact body of `f` calls on a model with tables
/// `t` (`payload`: the last body's inertia built from a runtime payload per call), or `None`
/// for a function without a compact body or a model of more than [`MAX_N`] joints.
#[must_use]
pub fn counts(t: &Numbers, f: Function, payload: bool) -> Option<Counts> {
    at_size!(t.parent.len(), trace_kernel(t, f, payload), [1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32 33 34 35 36 37 38 39 40 41 42 43 44 45 46 47 48 49 50 51 52 53 54 55 56 57 58 59 60 61 62 63 64])?
}

/// [`counts`] for `N` joints.
fn trace_kernel<const N: usize>(t: &Numbers, f: Function, payload: bool) -> Option<Counts> {
    let tr = Tracer::new();
    let x = || tr.input("x");
    let v3 = || -> [Sym; 3] { core::array::from_fn(|_| x()) };
    let m3 = || -> [[Sym; 3]; 3] { core::array::from_fn(|_| v3()) };
    let joints = || -> [Sym; N] { core::array::from_fn(|_| x()) };
    let tables: Tables<Sym, N> = Tables {
        parent: core::array::from_fn(|j| t.parent.get(j).copied().flatten()),
        revolute: core::array::from_fn(|j| t.revolute.get(j).copied().unwrap_or(true)),
        a: core::array::from_fn(|_| m3()),
        b: core::array::from_fn(|_| m3()),
        c: core::array::from_fn(|_| m3()),
        l: core::array::from_fn(|_| v3()),
        slide: core::array::from_fn(|_| v3()),
        s: core::array::from_fn(|_| core::array::from_fn(|_| x())),
        inertia: core::array::from_fn(|_| core::array::from_fn(|_| x())),
        ancestor: t.ancestor.as_ref().map(|rows| {
            core::array::from_fn(|i| {
                core::array::from_fn(|j| rows.get(i).and_then(|r| r.get(j)) == Some(&true))
            })
        }),
        a0: core::array::from_fn(|_| x()),
    };
    let inertia = if payload {
        k::with_payload(&tables.inertia, x(), &v3(), &m3())
    } else {
        tables.inertia
    };
    let (tb, i, sc) = (&tables, &inertia, |a: Sym| a.sin_cos());
    let out: Vec<Sym> = match f {
        Function::MassMatrix => k::mass_matrix(tb, i, &joints(), sc).concat(),
        Function::NonlinearEffects => {
            k::nonlinear_effects(tb, i, &joints(), &joints(), sc).to_vec()
        }
        Function::Gravity => k::gravity(tb, i, &joints(), sc).to_vec(),
        Function::InverseDynamics => {
            k::inverse_dynamics(tb, i, &joints(), &joints(), &joints(), sc).to_vec()
        }
        Function::MassMatrixAndNonlinearEffects => {
            let (m, c) = k::mass_matrix_and_nonlinear_effects(tb, i, &joints(), &joints(), sc);
            [m.concat(), c.to_vec()].concat()
        }
        Function::ForwardDynamics => {
            k::forward_dynamics(tb, i, &joints(), &joints(), &joints(), sc).to_vec()
        }
        Function::ForwardDynamicsWithWrenches => {
            let f_ext = core::array::from_fn(|_| core::array::from_fn(|_| x()));
            k::forward_dynamics_with_wrenches(tb, i, &joints(), &joints(), &joints(), &f_ext, sc)
                .to_vec()
        }
        _ => return None,
    };
    Some(tr.finish(&out).counts(Convention::Paper))
}
