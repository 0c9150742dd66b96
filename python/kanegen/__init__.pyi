"""Type stubs of kanegen (the extension module ``kanegen._kanegen``)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "PathLike[str]"]
_Array = npt.ArrayLike
_F64 = npt.NDArray[np.float64]

class KanegenError(ValueError):
    """An error of kanegen: the message the command line prints after ``Error: ``."""

class Model:
    """A robot model (URDF or kanegen TOML) and the dynamics of kanegen's run-time path on it.

    Every method takes one state (1-D arrays) or a batch (2-D arrays of shape ``(B, n)``,
    evaluated in Rust across cores) and returns ``float64`` arrays (``(B, ...)`` for a batch).
    Free-floating base: ``q = [p0 (3), quaternion x y z w (4), joints]`` (``nq = 7 + N``),
    velocities ``[v_b (3), omega_b (3), qd]`` (``nv = 6 + N``); ``tau`` is the ``N`` joint drives.
    """

    @staticmethod
    def load(
        path: _Path,
        base: Optional[str] = None,
        gravity: Optional[Sequence[float]] = None,
        allow_nonphysical: bool = False,
    ) -> "Model":
        """Reads a ``.urdf`` or ``.toml`` model as the CLI does; ``base``: ``"fixed"`` or
        ``"free-floating"``; ``gravity``: ``(x, y, z)`` in m/s² (none by default);
        ``allow_nonphysical``: the CLI's ``--allow-nonphysical``."""
    @staticmethod
    def from_urdf_string(
        text: str, base: Optional[str] = None, gravity: Optional[Sequence[float]] = None
    ) -> "Model":
        """A model from URDF text."""
    @property
    def name(self) -> str:
        """The model's name."""
    @property
    def base(self) -> str:
        """``"fixed"`` or ``"free-floating"``."""
    @property
    def gravity(self) -> Optional[Tuple[float, float, float]]:
        """Gravity ``(x, y, z)`` or ``None``."""
    @property
    def nq(self) -> int:
        """Length of ``q``: ``N``, or ``7 + N`` on a free-floating base."""
    @property
    def nv(self) -> int:
        """Length of velocities and accelerations: ``N``, or ``6 + N`` on a free-floating base."""
    @property
    def joint_names(self) -> List[str]:
        """The joints in the order of ``q`` (after the base's entries)."""
    @property
    def frame_names(self) -> List[str]:
        """The named frames."""
    def mass_matrix(self, q: _Array) -> _F64:
        """``M(q)``, ``(nv, nv)`` (CRBA; Pinocchio's ``crba``)."""
    def nonlinear_effects(self, q: _Array, v: _Array) -> _F64:
        """``c(q, v)``, ``(nv,)`` (RNEA; Pinocchio's ``nonLinearEffects``)."""
    def gravity_effects(self, q: _Array) -> _F64:
        """``g(q)``, ``(nv,)`` (Pinocchio's ``computeGeneralizedGravity``)."""
    def inverse_dynamics(self, q: _Array, v: _Array, a: _Array) -> _F64:
        """``tau = M a + c``, ``(nv,)`` (Pinocchio's ``rnea``)."""
    def forward_dynamics(self, q: _Array, v: _Array, tau: _Array) -> _F64:
        """``qdd = M⁻¹ (tau − c)``, ``(nv,)`` (Pinocchio's ``aba``)."""
    def inverse_dynamics_derivatives(
        self, q: _Array, v: _Array, a: _Array
    ) -> Tuple[_F64, _F64]:
        """``(dtau/dq, dtau/dv)`` (Pinocchio's ``computeRNEADerivatives``)."""
    def forward_dynamics_derivatives(
        self, q: _Array, v: _Array, tau: _Array
    ) -> Tuple[_F64, _F64, _F64]:
        """``(dqdd/dq, dqdd/dv, M⁻¹)`` (Pinocchio's ``computeABADerivatives``)."""
    def mass_matrix_inverse(self, q: _Array) -> _F64:
        """``M(q)⁻¹``, ``(nv, nv)`` (Pinocchio's ``computeMinverse``)."""
    def frame_placement(self, name: str, q: _Array) -> Tuple[_F64, _F64]:
        """``(position (3,), rotation (3, 3))`` of a named frame."""
    def frame_jacobian(self, name: str, q: _Array) -> _F64:
        """``(6, nv)``, rows ``[v; ω]``, Pinocchio's ``LOCAL_WORLD_ALIGNED``."""

def count(path: _Path, **options: Any) -> Dict[str, Any]:
    """What ``kanegen count PATH --json`` prints, as a dict."""

def generate(path: _Path, **options: Any) -> str:
    """The Rust source ``kanegen generate PATH`` emits."""

def simulate(path: _Path, allow_long: bool = False) -> Dict[str, Any]:
    """A scene integrated as ``kanegen simulate`` does: ``t``, ``x``, ``columns``, ``summary``."""
