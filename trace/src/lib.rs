//! # kanegen-trace
//!
//! The third stage of kanegen's pipeline: the counting symbolic scalar [`Sym`], the one entry
//! point [`trace`] that records a function of a model's dynamics as an expression graph, and what
//! is read off such graphs: operation counts under three conventions ([`Convention`]), the
//! `kanegen count` report ([`count`]), and, with the feature `table1`, the paper's Table 1
//! (`table1`) and the exact polynomial fitter it uses (`poly`). The code generator emits the
//! same graphs.
//!
//! ```
//! use kanegen_dynamics::Methods;
//! use kanegen_trace::{trace, Convention, Function, Spec, Subject};
//! // The paper's mass matrix for 3 general bodies, from its inertial-frame inputs (Table 1's start).
//! let t = trace(Subject::InertialFrame { n: 3 }, Function::MassMatrix, Methods::RECURRENT,
//!     &Spec::default()).unwrap();
//! let c = t.trace.counts(Convention::Paper);
//! assert!(c.mul > 0 && c.add > 0);
//! ```
#![warn(missing_docs)]

pub mod count;
mod coupled;
mod entry;
mod function;
#[cfg(feature = "table1")]
pub mod poly;
mod spec;
pub mod sym;
#[cfg(feature = "table1")]
pub mod table1;

pub use entry::{trace, TraceError, Traced};
pub use function::{Arg, Function, Input, PayloadField};
pub use spec::{Base, Effect, Spec, Subject, Wrench, WrenchValue};
pub use sym::{Convention, Counts, Node, Sym, Trace, Tracer};
