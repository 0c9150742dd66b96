//! A scalar that only counts: every multiplication, addition or subtraction, division and
//! sine–cosine the code run on it performs (sign changes free, as under the tracer's
//! [`kanegen_trace::Convention::Paper`]), with no value and no graph. The compact derivative
//! kernels execute O(N³) operations (`M⁻¹` and two `N × N` products): traced on `Sym` at
//! N = 500 their graph would not fit in memory, counted on [`Tally`] it is a loop. The kernels
//! are branch-free in the values, so what they execute on `Tally` is what they execute on `f64`.

use kanegen_runtime::Scalar;
use kanegen_trace::Counts;
use std::cell::Cell;
use std::ops::{Add, Div, Mul, Neg, Sub};

thread_local! {
    /// `[mul, add, div, sincos]` since the last [`take`].
    static OPS: Cell<[u64; 4]> = const { Cell::new([0; 4]) };
}

#[inline]
fn bump(k: usize) {
    OPS.with(|c| {
        let mut v = c.get();
        v[k] += 1;
        c.set(v);
    });
}

/// The operations counted on this thread since the last call, as [`Counts`] (the counters reset).
#[must_use]
pub fn take() -> Counts {
    let [mul, add, div, sincos] = OPS.with(|c| c.replace([0; 4]));
    Counts {
        mul,
        add,
        div,
        sincos,
        ..Counts::default()
    }
}

/// A scalar without a value that counts the operations done on it.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tally;

macro_rules! counting {
    ($tr:ident, $f:ident, $k:expr) => {
        impl $tr for Tally {
            type Output = Tally;
            #[inline]
            fn $f(self, _: Tally) -> Tally {
                bump($k);
                Tally
            }
        }
    };
}
counting!(Add, add, 1);
counting!(Sub, sub, 1);
counting!(Mul, mul, 0);
counting!(Div, div, 2);

impl Neg for Tally {
    type Output = Tally;
    #[inline]
    fn neg(self) -> Tally {
        Tally
    }
}

impl Scalar for Tally {
    fn constant(_: f64) -> Self {
        Tally
    }
    fn sin(self) -> Self {
        bump(3);
        Tally
    }
    fn cos(self) -> Self {
        bump(3);
        Tally
    }
    fn sqrt(self) -> Self {
        Tally
    }
    fn sin_cos(self) -> (Self, Self) {
        bump(3);
        (Tally, Tally)
    }
}
