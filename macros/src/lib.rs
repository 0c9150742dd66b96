//! Proc-macros of kanegen (issue 4).
