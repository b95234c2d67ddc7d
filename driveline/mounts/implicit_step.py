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
with their exact Jacobian ``2 M / h^2 + dE/dQ1 + C / h + R^T diag(g / (2 + h / tau)) R``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .forces import MAX_NEWTON, NEWTON_STEP, BranchMap, mean_elastic_load
from .layout import Layout


@dataclass(frozen=True)
class StepParts:
    """What a step changed, for the energy balance: dq, mean load, mean branch forces."""

    dq: np.ndarray
    mean_load: np.ndarray
    mean_branch: np.ndarray


def implicit_step(layout: Layout, mass: np.ndarray, damping: np.ndarray, branches: BranchMap,
                  weight: np.ndarray, weight_sag: np.ndarray, state: np.ndarray, f0: np.ndarray,
                  f1: np.ndarray, h: float) -> tuple[np.ndarray, StepParts]:
    """The state after a step of ``h`` from ``state`` under ``f0 + f1 tau`` (equations (I1)); ArithmeticError
    when Newton does not converge or the motion leaves the range of numbers (numpy's overflow warnings
    are silenced here: the non-finite residual is the refusal's reason)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return _solve(layout, mass, damping, branches, weight, weight_sag, state, f0, f1, h)


def _solve(layout: Layout, mass: np.ndarray, damping: np.ndarray, branches: BranchMap, weight: np.ndarray,
           weight_sag: np.ndarray, state: np.ndarray, f0: np.ndarray, f1: np.ndarray,
           h: float) -> tuple[np.ndarray, StepParts]:
    q0, v0, z0 = state[:6], state[6:12], state[12:]
    load = f0 + 0.5 * h * f1 + weight
    shrink = 0.5 * h / branches.times
    z_keep = z0 * (1.0 - shrink) / (1.0 + shrink)
    z_gain = branches.gains / (1.0 + shrink)
    branch_jacobian = branches.rows.T @ ((0.5 * z_gain)[:, None] * branches.rows)
    big_q0 = weight_sag + q0
    dq = h * v0
    for _ in range(MAX_NEWTON):
        z1 = z_keep + z_gain * (branches.rows @ dq)
        elastic, elastic_jacobian = mean_elastic_load(layout, big_q0, big_q0 + dq)
        residual = (mass @ (2.0 * dq / h - 2.0 * v0) / h - load + elastic + damping @ dq / h
                    + branches.rows.T @ (0.5 * (z0 + z1)))
        jacobian = 2.0 * mass / (h * h) + elastic_jacobian + damping / h + branch_jacobian
        if not np.all(np.isfinite(residual)):
            raise ArithmeticError("the step's motion is beyond the range of numbers (a load near 1e300)")
        correction = np.linalg.solve(jacobian, -residual)
        dq = dq + correction
        if np.max(np.abs(correction)) <= NEWTON_STEP * max(np.max(np.abs(big_q0 + dq)), 1e-300):
            z1 = z_keep + z_gain * (branches.rows @ dq)
            parts = StepParts(dq, load - weight, 0.5 * (z0 + z1))
            return np.concatenate([q0 + dq, 2.0 * dq / h - v0, z1]), parts
    raise ArithmeticError(f"the implicit step did not converge in {MAX_NEWTON} Newton iterations")
