"""A step of the powertrain on progressive mounts: the implicit midpoint rule with the discrete gradient.

The state ``s = (q, q', z)`` (q from the weight's equilibrium ``Q_g``, so the body's displacement from
the unloaded mounts is ``Q = Q_g + q``; z the Maxwell branches' forces). Over a step h under the load
``f0 + f1 tau`` (its mean ``f_m = f0 + f1 h / 2``), with ``dq = q1 - q0``,

    M (q1' - q0') / h = f_m + W - E(Q0, Q1) - C dq / h - R^T (z0 + z1) / 2,
    dq / h = (q0' + q1') / 2,                                                        (I1)
    (z1 - z0) / h = g (R dq / h) - (z0 + z1) / (2 tau),

W the weight, ``E(Q0, Q1)`` the discrete gradient of the mounts' elastic energy V (its product with dq
is ``V(Q1) - V(Q0)`` exactly, :func:`.forces.mean_elastic_load`). Multiplied by dq the equations give
the energy balance of the step exactly (up to rounding and Newton's tolerance):

    kinetic + V - W.Q + sum z^2 / (2 g)  grows by  f_m . dq - dq^T C dq / h - h sum ((z0 + z1) / 2)^2 / (g tau),

so the scheme is unconditionally stable (it dissipates what the model dissipates, adds nothing) and of
second order. q1' and z1 are linear in dq; the six equations left in dq are solved by Newton's method
with their exact Jacobian ``2 M / h^2 + dE/dQ1 + C / h + R^T diag(g / (2 + h / tau)) R``. What depends on h
and the parameters alone is built once a step size (:class:`StepMatrices`); Newton starts from ``dq = h q0'``
and keeps the Jacobian's factors for the next iteration while each correction is at most
:data:`.forces.NEWTON_CONTRACTION` of the one before (the simplified Newton method: a step's second
iteration, which only confirms the first's root to the tolerance, needs no new Jacobian).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.linalg import LinAlgWarning, lu_factor, lu_solve

from .forces import MAX_NEWTON, NEWTON_CONTRACTION, NEWTON_STEP, BranchMap, mean_elastic_load
from .layout import Layout


#: Why a step whose matrices are beyond the range of numbers (a step of about 1e-150 s or less) is refused.
TOO_SHORT = "the step is too short for the implicit step (2 M / h^2 is beyond the range of numbers)"


@dataclass(frozen=True)
class StepParts:
    """What a step changed, for the energy balance: dq, mean load, mean branch forces."""

    dq: np.ndarray
    mean_load: np.ndarray
    mean_branch: np.ndarray


@dataclass(frozen=True)
class StepMatrices:
    """What the steps of one size ``h`` take of h and the parameters alone: the branches' forces after a
    step ``z1 = keep z0 + gain (R dq)`` (``keep = (1 - s) / (1 + s)``, ``gain = g / (1 + s)``,
    ``s = h / (2 tau)``), ``resistance`` ``C / h + R^T diag(gain / 2) R`` (the viscous and branch forces'
    part in dq) and ``jacobian`` ``2 M / h^2 + resistance``, the Jacobian's part without the mounts'
    characteristics."""

    h: float
    keep: np.ndarray
    gain: np.ndarray
    resistance: np.ndarray
    jacobian: np.ndarray

    @classmethod
    def of(cls, mass: np.ndarray, damping: np.ndarray, branches: BranchMap, h: float) -> StepMatrices:
        """The matrices of steps of ``h`` (for a step too short, below about 1e-150 s, 2 M / h^2 is beyond the
        range of numbers: the step refuses it, :data:`TOO_SHORT`)."""
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            shrink = 0.5 * h / branches.times
            gain = branches.gains / (1.0 + shrink)
            resistance = damping / h + branches.rows.T @ ((0.5 * gain)[:, None] * branches.rows)
            return cls(h, (1.0 - shrink) / (1.0 + shrink), gain, resistance, 2.0 * mass / (h * h) + resistance)


def implicit_step(layout: Layout, mass: np.ndarray, damping: np.ndarray, branches: BranchMap,
                  weight: np.ndarray, weight_sag: np.ndarray, state: np.ndarray, f0: np.ndarray,
                  f1: np.ndarray, h: float, matrices: StepMatrices | None = None) -> tuple[np.ndarray, StepParts]:
    """The state after a step of ``h`` from ``state`` under ``f0 + f1 tau`` (equations (I1)), with the
    :class:`StepMatrices` of h when given; ArithmeticError when Newton does not converge or the motion
    leaves the range of numbers (numpy's overflow warnings are silenced here: the non-finite residual is
    the refusal's reason)."""
    if matrices is None or matrices.h != h:
        matrices = StepMatrices.of(mass, damping, branches, h)
    with np.errstate(over="ignore", invalid="ignore"):
        return _solve(layout, mass, branches, weight, weight_sag, state, f0, f1, matrices)


def _factors(jacobian: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """LU factors of the Jacobian; LinAlgError for a singular one (as numpy's solve)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LinAlgWarning)
        factors = lu_factor(jacobian, check_finite=False)
    if not np.all(np.diagonal(factors[0])):
        raise np.linalg.LinAlgError("Singular matrix")
    return factors


def _solve(layout: Layout, mass: np.ndarray, branches: BranchMap, weight: np.ndarray, weight_sag: np.ndarray,
           state: np.ndarray, f0: np.ndarray, f1: np.ndarray, matrices: StepMatrices) -> tuple[np.ndarray, StepParts]:
    q0, v0, z0 = state[:6], state[6:12], state[12:]
    h = matrices.h
    if not np.all(np.isfinite(matrices.jacobian)):  # the residual's terms then overflow in an order of their sum
        raise ArithmeticError(TOO_SHORT)
    z_keep = matrices.keep * z0
    mean_load = f0 + 0.5 * h * f1
    load = mean_load + weight - branches.rows.T @ (0.5 * (z0 + z_keep))  # less the branches' forces held from z0
    big_q0 = weight_sag + q0
    dq = h * v0
    factors, previous = None, np.inf
    for _ in range(MAX_NEWTON):
        elastic, elastic_jacobian = mean_elastic_load(layout, big_q0, big_q0 + dq, with_jacobian=factors is None)
        residual = mass @ (2.0 * dq / h - 2.0 * v0) / h - load + elastic + matrices.resistance @ dq
        if not np.all(np.isfinite(residual)):
            raise ArithmeticError("the step's motion is beyond the range of numbers (a load near 1e300)")
        if factors is None:
            factors = _factors(matrices.jacobian + elastic_jacobian)
        correction = lu_solve(factors, -residual, check_finite=False)
        dq = dq + correction
        size = np.max(np.abs(correction))
        if size <= NEWTON_STEP * max(np.max(np.abs(big_q0 + dq)), 1e-300):
            z1 = z_keep + matrices.gain * (branches.rows @ dq)
            parts = StepParts(dq, mean_load, 0.5 * (z0 + z1))
            return np.concatenate([q0 + dq, 2.0 * dq / h - v0, z1]), parts
        if not size <= NEWTON_CONTRACTION * previous:  # a slow contraction: the Jacobian again
            factors = None
        previous = size
    raise ArithmeticError(f"the implicit step did not converge in {MAX_NEWTON} Newton iterations")
