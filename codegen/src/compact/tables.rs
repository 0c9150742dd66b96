//! The numbers of a model that the compact form's tables hold (`kanegen_runtime::compact::Tables`):
//! [`kanegen_dynamics::kernels::KernelTables`] of the model's parameters under the options.

use crate::options::Options;
pub use kanegen_dynamics::kernels::{KernelTables, M3};
use kanegen_model::Model;

/// The compact tables of `model` under `opts`: the joints' placements and axes of
/// [`kanegen_dynamics::Params`], the inertias regrouped when [`Options::regroup`] is on (the
/// payload body neither gives nor receives), gravity as `a₀`; on a free-floating base, the
/// model's own inertias, the base's and gravity in [`KernelTables::base`].
#[must_use]
pub fn numbers(model: &Model, opts: &Options) -> KernelTables {
    let floating = model.base_kind() == kanegen_model::BaseKind::FreeFloating;
    if let Some(inertial) = model.base_inertial().filter(|_| floating) {
        // Free-floating: the model's own numbers (regrouping would move inertia onto the
        // base, and the kernels execute the same operations whatever the numbers).
        let base = kanegen_dynamics::FloatingBase::<f64>::from_inertial(inertial);
        let p = kanegen_dynamics::Params::<f64>::new(model);
        return KernelTables::floating(&p, &base, opts.gravity);
    }
    let n = model.dof();
    let keep: &[usize] = if opts.runtime_payload { &[n - 1] } else { &[] };
    let p = if opts.regroup {
        kanegen_dynamics::regroup::regrouped::<f64>(model, None, keep).params
    } else {
        kanegen_dynamics::Params::<f64>::new(model)
    };
    KernelTables::new(&p, opts.gravity)
}
