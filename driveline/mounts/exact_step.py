"""Exact time stepping of ``M q'' + C q' + K q = f(t)`` with f held or linear over a step.

State ``s = (q, q')`` (the Maxwell branches' forces after them: :func:`state_matrices`),
``s' = A s + B f`` with ``A = [[0, I], [-M^-1 K, -M^-1 C]]`` and
``B = [[0], [M^-1]]``. With ``f(t0 + tau) = f0 + f1 tau`` over a step h (f1 = 0: zero-order
hold; f1 the inputs' derivatives: first-order hold) the exact solution is

    s(h) = Phi s(0) + Gamma0 f0 + Gamma1 f1,   Phi = e^(A h),
    Gamma0 = int_0^h e^(A (h - tau)) B dtau,   Gamma1 = int_0^h e^(A (h - tau)) B tau dtau,

the blocks of one exponential of the augmented matrix (Van Loan 1978)

    exp([[A, B, 0], [0, 0, I], [0, 0, 0]] h) = [[Phi, Gamma0, Gamma1], [0, I, I h], [0, 0, I]],

computed once per step size. Its cost is bounded by the squarings of the scaling and squaring
method (Higham 2005, Pade degree 13): ``ceil(log2(|Z h|_1 / THETA_13))`` for the augmented
matrix Z, at most :data:`MAX_SQUARINGS`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from .forces import BranchMap
from .rigid_body import RigidBody

#: The 1-norm up to which the degree-13 Pade approximant needs no scaling (Higham 2005, Table 2.3).
THETA_13 = 5.371920351148152
#: Squarings of one exponential at most: |Z h|_1 up to THETA_13 2^40 (a step some 10^12 times
#: longer than the period of the highest mode: no simulation asks that).
MAX_SQUARINGS = 40


def state_matrices(body: RigidBody, branches: BranchMap | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``A`` (n x n) and ``B`` (n x 6) of the first-order system, ``n = 12`` plus the Maxwell
    branches' forces z (:class:`.forces.BranchMap`): ``q'' = M^-1 (f - K q - C q' - R^T z)``,
    ``z' = diag(g) R q' - z / tau``."""
    count = 0 if branches is None else len(branches)
    n = 12 + count
    inverse_mass = np.linalg.inv(body.mass)
    a = np.zeros((n, n))
    a[:6, 6:12] = np.eye(6)
    a[6:12, :6] = -inverse_mass @ body.stiffness
    a[6:12, 6:12] = -inverse_mass @ body.damping
    if count:
        a[6:12, 12:] = -inverse_mass @ branches.rows.T
        a[12:, 6:12] = branches.gains[:, None] * branches.rows
        a[12:, 12:] = -np.diag(1.0 / branches.times)
    b = np.zeros((n, 6))
    b[6:12, :] = inverse_mass
    return a, b


def augmented(a: np.ndarray, b: np.ndarray, h: float) -> np.ndarray:
    """``Z h`` ((n + 12) x (n + 12)) whose exponential holds Phi, Gamma0 and Gamma1."""
    n = len(a)
    z = np.zeros((n + 12, n + 12))
    z[:n, :n] = a * h
    z[:n, n:n + 6] = b * h
    z[n:n + 6, n + 6:] = np.eye(6) * h
    return z


def squarings(z: np.ndarray) -> int | None:
    """Squarings the scaling and squaring method takes for ``exp(z)``; None where ``z``'s norm is not finite
    (a step so long that the matrix overflows), which no count of squarings scales."""
    norm = float(np.max(np.sum(np.abs(z), axis=0)))
    if not math.isfinite(norm):
        return None
    return max(0, math.ceil(math.log2(norm / THETA_13))) if norm > THETA_13 else 0


def work_error(a: np.ndarray, b: np.ndarray, h: float) -> str | None:
    """Why a step of ``h`` is refused (its exponential needs more than MAX_SQUARINGS squarings), or None."""
    with np.errstate(over="ignore"):
        needed = squarings(augmented(a, b, h))
    if needed is None:
        return f"a step of {h!r} s overflows the matrix exponential's norm: take shorter steps"
    if needed <= MAX_SQUARINGS:
        return None
    return (f"a step of {h!r} s would take {needed} squarings of the matrix exponential, more than the "
            f"{MAX_SQUARINGS} accepted: take shorter steps")


@dataclass(frozen=True)
class Propagator:
    """``Phi``, ``Gamma0`` and ``Gamma1`` for one step size ``h``."""

    h: float
    phi: np.ndarray
    gamma0: np.ndarray
    gamma1: np.ndarray

    @classmethod
    def build(cls, a: np.ndarray, b: np.ndarray, h: float) -> Propagator:
        n = len(a)
        e = expm(augmented(a, b, h))
        return cls(h, e[:n, :n], e[:n, n:n + 6], e[:n, n + 6:])

    def step(self, state: np.ndarray, f0: np.ndarray, f1: np.ndarray) -> np.ndarray:
        """The state after the step from ``state`` under ``f0 + f1 tau``."""
        return self.phi @ state + self.gamma0 @ f0 + self.gamma1 @ f1
