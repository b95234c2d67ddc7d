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


def _element(EI: float, m: float, rI: float, h: float, rot: bool) -> tuple[FloatArray, FloatArray, FloatArray]:
    k = EI / h**3 * np.array(
        [[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
         [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]]
    )
    mt = m * h / 420 * np.array(
        [[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
         [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]]
    )
    mr = rI / (30 * h) * np.array(
        [[36, 3 * h, -36, 3 * h], [3 * h, 4 * h * h, -3 * h, -h * h],
         [-36, -3 * h, 36, -3 * h], [3 * h, -h * h, -3 * h, 4 * h * h]]
    )
    return k, mt, mr if rot else 0.0 * mr


def assemble(d: Driveline, elements_per_segment: int = 40) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Global ``K, M, G`` with end conditions applied, and the node positions."""
    n_el = elements_per_segment * len(d.segments)
    n_dof = 2 * (n_el + 1)
    K = np.zeros((n_dof, n_dof))
    M = np.zeros_like(K)
    G = np.zeros_like(K)
    e = 0
    z = [0.0]
    station_node = [0]
    for seg in d.segments:
        h = seg.length / elements_per_segment
        rI = seg.density * seg.second_moment
        k, mt, mr = _element(seg.bending_stiffness, seg.mass_per_length, rI, h, seg.rotary_inertia)
        g = 2.0 * mr if seg.gyroscopic else 0.0 * mr
        if not seg.rotary_inertia and seg.gyroscopic:
            g = 2.0 * _element(1.0, 0.0, rI, h, True)[2]
        for _ in range(elements_per_segment):
            sl = slice(2 * e, 2 * e + 4)
            K[sl, sl] += k
            M[sl, sl] += mt + mr
            G[sl, sl] += g
            e += 1
            z.append(z[-1] + h)
        station_node.append(e)
    for m in d.masses:
        i = 2 * station_node[m.node]
        M[i, i] += m.mass
        M[i + 1, i + 1] += m.diametral_inertia
        G[i + 1, i + 1] += m.polar_inertia
    for b in d.bearings:
        if not b.is_isotropic:
            raise ValueError("the finite-element check covers isotropic bearings only")
        i = 2 * station_node[b.node]
        K[i, i] += b.kxx
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
