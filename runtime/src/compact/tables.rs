//! The model's numbers that the compact kernels loop over.

/// A model's numbers as the compact kernels read them (one joint and its body per entry,
/// `λ(j) < j`), in the model's body frames (RBDA §4.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tables<S, const N: usize> {
    /// Each joint's parent body `λ(j) < j` (`None`: the base).
    pub parent: [Option<usize>; N],
    /// Whether joint `j` is revolute (else prismatic).
    pub revolute: [bool; N],
    /// `E_j = A_j + cos q_j B_j + sin q_j C_j` ([module docs](super)): `A_j`.
    pub a: [[[S; 3]; 3]; N],
    /// `B_j` ([module docs](super)).
    pub b: [[[S; 3]; 3]; N],
    /// `C_j` ([module docs](super)).
    pub c: [[[S; 3]; 3]; N],
    /// Joint origin `l_j` in the parent body frame.
    pub l: [[S; 3]; N],
    /// `Υ_j u_j` of a prismatic joint (zero for a revolute one): `r_j = l_j + q_j Υ_j u_j`.
    pub slide: [[S; 3]; N],
    /// Motion subspace `S_j` (`[u; 0]` revolute, `[0; u]` prismatic; RBDA Table 4.1).
    pub s: [[S; 6]; N],
    /// Spatial inertia of body `j` about its origin, `[m, h (3), Ī_xx, Ī_xy, Ī_xz, Ī_yy, Ī_yz,
    /// Ī_zz]` (RBDA eq. (2.63)).
    pub inertia: [[S; 10]; N],
    /// On a tree, whether joint `j` is joint `i` or one of its ancestors (`[i][j]`); `None`
    /// on a chain, where every `j ≤ i` is.
    pub ancestor: Option<[[bool; N]; N]>,
    /// The base's spatial acceleration `a₀ = [0; −g]` (RBDA §5.3; zero without gravity).
    pub a0: [S; 6],
}
