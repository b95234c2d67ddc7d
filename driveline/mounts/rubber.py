"""Rubber's frequency-independent damping as Maxwell branches, fitted over the band.

A rubber mount's complex stiffness along an axis, ``K*(w) = K'(w) (1 + i eta)``, has a loss factor
eta that hardly changes with frequency. A viscous damper's grows in proportion to it; a causal model
with a constant loss factor over a band is a spring in parallel with a few Maxwell branches (a
spring ``w_j k`` in series with a dashpot of relaxation time ``tau_j``):

    K*(w) / k = 1 + sum_j w_j i w tau_j / (1 + i w tau_j),                           (R1)

k the static (linear) rate. The branch force ``z_j`` is an internal state,

    z_j' = w_j k d' - z_j / tau_j,                                                   (R2)

with its energy ``z_j^2 / (2 w_j k)`` stored and ``z_j^2 / (w_j k tau_j)`` dissipated per second.
The relaxation frequencies ``1 / (2 pi tau_j)`` are fixed (:data:`RELAXATION_FREQUENCIES`, chosen once
to fit loss factors 0.05-0.3 over the band); the weights ``w_j >= 0`` of one mount come from a
non-negative least-squares fit (:func:`scipy.optimize.nnls`) of

    Im K*(w) = eta Re K*(w)  at FIT_POINTS frequencies log-spaced over BAND,
    Re K*(w_ref) = r k       at the band's geometric mean w_ref,                      (R3)

both linear in w_j: eta the layout's ``loss_factor``, r its ``dynamic_ratio`` (the dynamic-to-static
stiffness ratio at w_ref). A constant loss factor makes the storage rate grow with frequency
(roughly as ``w^(2 eta / pi)``, Kramers-Kronig), so a large eta asks for a large r: a fit that
misses eta by more than :data:`MAX_LOSS_ERROR` anywhere in the band, or r by more than
:data:`MAX_RATIO_ERROR`, is refused with the ratio that would fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import nnls

#: The band over which the loss factor is fitted [Hz].
BAND = (1.0, 50.0)
#: Relaxation frequencies of the branches [Hz] (rounded optimum of the fit over eta 0.1-0.2, r 1.3-2).
RELAXATION_FREQUENCIES = (0.02, 1.2, 9.0, 60.0)
BRANCHES = len(RELAXATION_FREQUENCIES)
#: Frequencies of the fit (log-spaced over the band).
FIT_POINTS = 80
#: Weight of the ratio's equation (R3) against one loss-factor equation.
RATIO_WEIGHT = 3.0
#: The largest relative miss of the loss factor over the band, and of the ratio, that a fit may have.
MAX_LOSS_ERROR = 0.05
MAX_RATIO_ERROR = 0.02


def relaxation_times() -> np.ndarray:
    """``tau_j = 1 / (2 pi f_j)`` [s]."""
    return 1.0 / (2.0 * math.pi * np.array(RELAXATION_FREQUENCIES))


def relative_stiffness(weights: np.ndarray, frequency: np.ndarray) -> np.ndarray:
    """``K*(w) / k`` of equation (R1) at ``frequency`` [Hz] (complex)."""
    x = 2.0 * math.pi * np.asarray(frequency, float)[..., None] * relaxation_times()
    return 1.0 + (1j * x / (1.0 + 1j * x)) @ weights


def _storage_loss(frequency: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    x = 2.0 * math.pi * np.asarray(frequency, float)[:, None] * relaxation_times()
    return x * x / (1.0 + x * x), x / (1.0 + x * x)


@dataclass(frozen=True)
class Fit:
    """Branch weights ``w_j`` and the fit's largest relative misses of eta (over the band) and r."""

    weights: np.ndarray
    loss_error: float
    ratio_error: float


def fit_branches(loss_factor: float, dynamic_ratio: float) -> Fit:
    """The weights of equation (R3) for ``loss_factor`` eta and ``dynamic_ratio`` r."""
    frequencies = np.geomspace(*BAND, FIT_POINTS)
    storage, loss = _storage_loss(frequencies)
    reference = math.sqrt(BAND[0] * BAND[1])
    storage_ref, _ = _storage_loss(np.array([reference]))
    matrix = np.vstack([(loss - loss_factor * storage) / loss_factor, RATIO_WEIGHT * storage_ref])
    rhs = np.concatenate([np.ones(FIT_POINTS), [RATIO_WEIGHT * (dynamic_ratio - 1.0)]])
    weights, _ = nnls(matrix, rhs)
    fitted = relative_stiffness(weights, frequencies)
    loss_error = float(np.max(np.abs(fitted.imag / fitted.real / loss_factor - 1.0)))
    ratio_error = float(abs(relative_stiffness(weights, np.array(reference)).real / dynamic_ratio - 1.0))
    return Fit(weights, loss_error, ratio_error)


def fit_error(where: str, fit: Fit, loss_factor: float, dynamic_ratio: float) -> str | None:
    """Why a fit is refused (naming the mount ``where``), or None."""
    if fit.loss_error <= MAX_LOSS_ERROR and fit.ratio_error <= MAX_RATIO_ERROR:
        return None
    return (f"{where}.dynamic_ratio {dynamic_ratio!r} cannot go with loss_factor {loss_factor!r}: Maxwell branches "
            f"with that dynamic-to-static ratio miss the loss factor by {100 * fit.loss_error:.3g} % over "
            f"{BAND[0]:g}-{BAND[1]:g} Hz (accepted {100 * MAX_LOSS_ERROR:g} %) and the ratio by "
            f"{100 * fit.ratio_error:.3g} % (accepted {100 * MAX_RATIO_ERROR:g} %): a constant loss factor needs "
            "a larger dynamic_ratio")
