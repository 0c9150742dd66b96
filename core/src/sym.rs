//! The counting symbolic scalar — STUB being written.
