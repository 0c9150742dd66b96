//! Code generation from traced `Sym` graphs (issue 4).
