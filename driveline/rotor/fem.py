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
    """Global ``K, M, G`` with end conditions applied, and the node positions.

    Every element contributes its own ``fe_matrices``: a segment over its
    ``elements_per_segment`` beam elements, a point element on the two dofs
    ``[U, psi]`` of its node.
    """
    n_el = elements_per_segment * len(d.segments)
    n_dof = 2 * (n_el + 1)
    K = np.zeros((n_dof, n_dof))
    M = np.zeros_like(K)
    G = np.zeros_like(K)
    z = [0.0]
    station_node = [0]
    for seg in d.segments:
        first = 2 * station_node[-1]
        block = slice(first, first + 2 * (elements_per_segment + 1))
        for glob, loc in zip((K, M, G), seg.fe_matrices(elements_per_segment)):
            glob[block, block] += loc
        h = seg.length / elements_per_segment
        for _ in range(elements_per_segment):
            z.append(z[-1] + h)
        station_node.append(station_node[-1] + elements_per_segment)
    for element in d.point_elements:
        i = 2 * station_node[element.node]
        for glob, loc in zip((K, M, G), element.fe_matrices()):
            glob[i:i + 2, i:i + 2] += loc
    e = station_node[-1]
    fixed: list[int] = []
    for end, node in ((d.left, 0), (d.right, e)):
        if end is EndCondition.PINNED:
            fixed.append(2 * node)
        elif end is EndCondition.CLAMPED:
            fixed.extend([2 * node, 2 * node + 1])
    keep = np.setdiff1d(np.arange(n_dof), fixed)
    ix = np.ix_(keep, keep)
    return K[ix], M[ix], G[ix], np.array(z)


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
