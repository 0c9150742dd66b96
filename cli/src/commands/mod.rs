//! The CLI's commands, as library functions the tests call directly.

pub mod accuracy;
pub mod bench;
pub mod count;
pub mod count_events;
pub mod eval;
pub mod generate;
pub mod info;
pub mod linearize;
pub mod simulate;
pub mod simulate_text;
pub mod sweep;
pub mod table1;
