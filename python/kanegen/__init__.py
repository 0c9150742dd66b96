"""kanegen: robot equations of motion ``M(q) q̈ + c(q, q̇) = τ`` from URDF/TOML models.

The run-time path of kanegen (its Rust algorithms, Pinocchio's names, signs and layouts) on
numpy arrays: one state as 1-D arrays, a batch as 2-D arrays of shape ``(B, n)`` evaluated in
Rust across cores. ``count``, ``generate`` and ``simulate`` run the command line's commands in
process. Every error is a :class:`KanegenError` carrying the message the command line prints.
"""

from ._kanegen import KanegenError, Model, count, generate, simulate

__all__ = ["KanegenError", "Model", "count", "generate", "simulate"]
