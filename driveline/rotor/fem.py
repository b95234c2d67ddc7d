"""Independent finite-element check of the transfer-matrix results, and the damped model.

Cubic Hermite Rayleigh-beam elements (Timoshenko elements for segments with ``shear``) in the
same complex whirl coordinate, giving the symmetric quadratic eigenproblem
``(K + w Omega G - w^2 M) q = 0`` with ``G = 2 Mr + Jp`` (rotary-inertia matrix ``Mr``;
``Ip = 2 I`` for a shaft section). Its real eigenvalues ``w`` are the signed whirl frequencies:
positive forward, negative backward. It shares no code with the transfer-matrix path and serves
as the reference for root counts; eigenvalue errors fall as ``h**4`` (``h**2`` with shear).
:func:`assemble_damped` adds the bearings' damping and anisotropy for :mod:`.damped`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .driveline import Driveline
from .elements import Bearing, EndCondition

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Mesh:
    """Degrees of freedom of the beam model, numbered before the end conditions remove ``fixed``.

    ``blocks`` holds every element's dofs and ``K, M, G``; ``elements`` the dofs
    ``[U1, psi1, U2, psi2]`` of each beam element, starting at ``z[e]``; ``node_u`` the
    translation dof of each driveline node.
    """

    n_dof: int
    blocks: list[tuple[list[int], tuple[FloatArray, FloatArray, FloatArray]]]
    fixed: list[int]
    z: FloatArray
    elements: NDArray[np.int_]
    node_u: NDArray[np.int_]

    def matrices(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Global ``K, M, G`` over all dofs (end conditions not applied)."""
        K = np.zeros((self.n_dof, self.n_dof))
        M = np.zeros_like(K)
        G = np.zeros_like(K)
        for dofs, matrices in self.blocks:
            block = np.ix_(dofs, dofs)
            for glob, loc in zip((K, M, G), matrices):
                glob[block] += loc
        return K, M, G

    @property
    def kept(self) -> NDArray[np.int_]:
        """The dofs left by the end conditions, ascending."""
        return np.setdiff1d(np.arange(self.n_dof), self.fixed)


#: What a segment's share of elements may exceed a whole number by and still round down to it (a
#: segment of exactly half the length, summed in floating point, keeps ``most``).
SHARE_SLACK = 1e-9


def elements_by_length(d: Driveline, most: int) -> list[int]:
    """Beam elements per segment: ``most`` on a segment of half the driveline's length or longer,
    proportionally fewer (at least one) on a shorter one, so that many short segments cost no more
    than a two-span shaft."""
    half = 0.5 * math.fsum(s.length for s in d.segments)
    return [min(most, max(1, math.ceil(most * s.length / half - SHARE_SLACK))) for s in d.segments]


def mesh(d: Driveline, elements_per_segment: int | Sequence[int] = 40, undamped: bool = True) -> Mesh:
    """Number the dofs and collect the element matrices.

    Every element contributes its own ``fe_matrices``: a segment over its
    ``elements_per_segment`` beam elements (one count for all, or one per segment), a point element on the dofs ``[U, psi]``
    of its node; an element that splits the slope (a hinge) adds a dof ``psi_out``,
    from which the next segment starts. End conditions act on the slope outside
    the end node's point elements (as in the transfer path). With ``undamped`` false the
    bearings are left out (the damped assembly adds their components).
    """
    counts = ([elements_per_segment] * len(d.segments) if isinstance(elements_per_segment, int)
              else list(elements_per_segment))
    at_node: list[list] = [[] for _ in range(len(d.segments) + 1)]
    for element in d.point_elements:
        if undamped or not isinstance(element, Bearing):
            at_node[element.node].append(element)
    blocks: list[tuple[list[int], tuple]] = []
    z = [0.0]
    u, psi, n_dof = 0, 1, 2
    fixed: list[int] = []
    elements: list[list[int]] = []
    node_u: list[int] = []
    for node, point_elements in enumerate(at_node):
        node_u.append(u)
        if node == 0:
            fixed += _fixed_dofs(d.left, u, psi)
        for element in point_elements:
            dofs = [u, psi]
            if element.splits_slope:
                psi, n_dof = n_dof, n_dof + 1
                dofs.append(psi)
            blocks.append((dofs, element.fe_matrices()))
        if node == len(d.segments):
            fixed += _fixed_dofs(d.right, u, psi)
            break
        seg, count = d.segments[node], counts[node]
        dofs = [u, psi, *range(n_dof, n_dof + 2 * count)]
        n_dof += 2 * count
        u, psi = dofs[-2], dofs[-1]
        blocks.append((dofs, seg.fe_matrices(count)))
        h = seg.length / count
        for e in range(count):
            elements.append(dofs[2 * e: 2 * e + 4])
            z.append(z[-1] + h)
    return Mesh(n_dof, blocks, fixed, np.array(z), np.array(elements), np.array(node_u))


def assemble(d: Driveline, elements_per_segment: int = 40) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Global ``K, M, G`` with end conditions applied, and the axial positions of the beam nodes (see :func:`mesh`)."""
    m = mesh(d, elements_per_segment)
    ix = np.ix_(m.kept, m.kept)
    K, M, G = m.matrices()
    return K[ix], M[ix], G[ix], m.z


@dataclass(frozen=True)
class DampedMatrices:
    """The damped model in the complex whirl coordinate ``u`` (end conditions applied)::

        M u'' + (C - i Omega G) u' + C_b conj(u') + K u + K_b conj(u) = f

    ``K``, ``C`` hold the bearings' components on ``u`` (``k_a``, ``c_a``), ``K_b``, ``C_b``
    those on ``conj(u)`` (``k_b``, ``c_b``: anisotropy, zero for axisymmetric bearings).
    ``index[g]`` is the row of global dof ``g`` (-1 where an end condition fixes it).
    """

    K: NDArray[np.complex128]
    M: FloatArray
    G: FloatArray
    C: NDArray[np.complex128]
    K_b: NDArray[np.complex128]
    C_b: NDArray[np.complex128]
    mesh: Mesh
    index: NDArray[np.int_]


def assemble_damped(d: Driveline, elements_per_segment: int | Sequence[int] = 40) -> DampedMatrices:
    """:class:`DampedMatrices` of ``d``: the undamped elements as in :func:`assemble`, and every
    bearing's stiffness and damping components on its node's translation dof."""
    m = mesh(d, elements_per_segment, undamped=False)
    kept = m.kept
    index = np.full(m.n_dof, -1)
    index[kept] = np.arange(kept.size)
    K, M, G = (matrix[np.ix_(kept, kept)] for matrix in m.matrices())
    K = K.astype(complex)
    n = kept.size
    C, K_b, C_b = (np.zeros((n, n), dtype=complex) for _ in range(3))
    for bearing in d.bearings:
        row = index[m.node_u[bearing.node]]
        if row < 0:  # on a pinned or clamped end: the support holds it already
            continue
        (ka, kb), (ca, cb) = bearing.stiffness_components, bearing.damping_components
        K[row, row] += ka
        K_b[row, row] += kb
        C[row, row] += ca
        C_b[row, row] += cb
    return DampedMatrices(K, M, G, C, K_b, C_b, m, index)


def _fixed_dofs(end: EndCondition, u: int, psi: int) -> list[int]:
    return {EndCondition.FREE: [], EndCondition.PINNED: [u], EndCondition.CLAMPED: [u, psi]}[end]


def whirl_frequencies(d: Driveline, spin: float = 0.0, elements_per_segment: int = 40) -> FloatArray:
    """All signed whirl frequencies of the FE model at ``spin`` (ascending) [rad/s]."""
    K, M, G, _ = assemble(d, elements_per_segment)
    n = K.shape[0]
    Minv = np.linalg.inv(M)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = Minv @ K
    A[n:, n:] = spin * (Minv @ G)
    lam = np.linalg.eigvals(A)
    # w^2 M q - w Omega G q - K q = 0 is linearised as w [q; w q] = A [q; w q].
    if np.max(np.abs(lam.imag)) > 1e-6 * max(1.0, np.max(np.abs(lam.real))):
        raise RuntimeError("FE eigenvalues are not real: the model is not conservative")
    return np.sort(lam.real)
