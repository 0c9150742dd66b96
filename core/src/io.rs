//! Model readers (URDF, TOML) — STUB being written.
