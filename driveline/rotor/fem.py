"""Independent finite-element check of the transfer-matrix results.

Cubic Hermite Rayleigh-beam elements in the same complex whirl coordinate, giving
the symmetric quadratic eigenproblem ``(K + w Omega G - w^2 M) q = 0`` with
``G = 2 Mr + Jp`` (rotary-inertia matrix ``Mr``; ``Ip = 2 I`` for a shaft section).
Its real eigenvalues ``w`` are the signed whirl frequencies: positive forward,
negative backward. It shares no code with the transfer-matrix path and serves as
the reference for root counts; eigenvalue errors fall as ``h**4``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .driveline import Driveline
from .elements import EndCondition

FloatArray = NDArray[np.float64]


def assemble(d: Driveline, elements_per_segment: int = 40) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Global ``K, M, G`` with end conditions applied, and the axial positions of the beam nodes.

    Every element contributes its own ``fe_matrices``: a segment over its
    ``elements_per_segment`` beam elements, a point element on the dofs ``[U, psi]``
    of its node; an element that splits the slope (a hinge) adds a dof ``psi_out``,
    from which the next segment starts. End conditions act on the slope outside
    the end node's point elements (as in the transfer path).
    """
    at_node: list[list] = [[] for _ in range(len(d.segments) + 1)]
    for element in d.point_elements:
        at_node[element.node].append(element)
    segment_blocks: list[tuple[list[int], tuple]] = []
    point_blocks: list[tuple[list[int], tuple]] = []
    z = [0.0]
    u, psi, n_dof = 0, 1, 2
    fixed: list[int] = []
    for node, elements in enumerate(at_node):
        if node == 0:
            fixed += _fixed_dofs(d.left, u, psi)
        for element in elements:
            dofs = [u, psi]
            if element.splits_slope:
                psi, n_dof = n_dof, n_dof + 1
                dofs.append(psi)
            point_blocks.append((dofs, element.fe_matrices()))
        if node == len(d.segments):
            fixed += _fixed_dofs(d.right, u, psi)
            break
        seg = d.segments[node]
        dofs = [u, psi, *range(n_dof, n_dof + 2 * elements_per_segment)]
        n_dof += 2 * elements_per_segment
        u, psi = dofs[-2], dofs[-1]
        segment_blocks.append((dofs, seg.fe_matrices(elements_per_segment)))
        h = seg.length / elements_per_segment
        for _ in range(elements_per_segment):
            z.append(z[-1] + h)
    K = np.zeros((n_dof, n_dof))
    M = np.zeros_like(K)
    G = np.zeros_like(K)
    for dofs, matrices in segment_blocks + point_blocks:
        block = np.ix_(dofs, dofs)
        for glob, loc in zip((K, M, G), matrices):
            glob[block] += loc
    keep = np.setdiff1d(np.arange(n_dof), fixed)
    ix = np.ix_(keep, keep)
    return K[ix], M[ix], G[ix], np.array(z)


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
