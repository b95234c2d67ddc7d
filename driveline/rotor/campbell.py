"""Campbell data by branch: whirl frequencies followed over the spin speed, interpolated through crossings.

Sorted per speed ("first", "second" whirl frequency), two branches of one whirl sense
that cross (e.g. the two rigid-body modes of a symmetric tube on soft bearings in
backward whirl) give the sorted curves a kink, and a spline through them errs by the
kink's size. Here every branch is followed from one speed to the next, splined alone,
and the branches are sorted only when the table is evaluated.

The roots at all speeds come from one batch search (:mod:`.roots`) on grids with
``POINTS_PER_ROOT`` points per bare-shaft root. The driveline's own grid, which also
allows one root per degree of freedom of every point element anywhere in the range,
is searched at the first speed only: the whirl frequencies of the undamped rotor are
real and move continuously with the speed, and a scan misses roots only in pairs, so
the count at the first speed must match and the count of each whirl sense below the
search limit may change by at most one (a root crossing the limit) from one speed to
the next; otherwise every speed is searched on the full grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline

from .driveline import SEARCH_LIMIT, Driveline

FloatArray = NDArray[np.float64]

#: Relative step of the central differences giving a root's slope ``dw/dOmega``.
SLOPE_STEP = 1e-6
#: Relative error of the interpolated branches aimed at, rounds of added speeds, most speeds.
SPLINE_RTOL = 1e-12
REFINEMENTS = 4
MAX_KNOTS = 400


@dataclass(frozen=True)
class WhirlBranches:
    """Whirl frequencies [rad/s] at ``spins`` (m,): ``forward`` (m, bf) and ``backward`` (m, bb), one
    column per branch, continuous in the speed; the branches that are among the first ``n_modes``
    at some speed (NaN where a branch lies beyond the search)."""

    spins: FloatArray
    forward: FloatArray
    backward: FloatArray


def whirl_branches(driveline: Driveline, spins: ArrayLike, n_modes: int) -> WhirlBranches:
    """Branches of the first ``n_modes`` forward and backward whirl frequencies over increasing ``spins``.

    Where a branch's cubic spline errs by more than ``SPLINE_RTOL`` at the middle between
    two speeds (estimated by a Newton step on the determinant there), that middle is
    added to the speeds, up to ``REFINEMENTS`` times. Anisotropic drivelines (whose whirl
    sense is read from mode shapes) give the sorted Campbell table, one column per rank.
    """
    sp = np.asarray(spins, dtype=float)
    if sp.ndim != 1 or sp.size < 2 or not np.all(np.isfinite(sp)) or sp[0] < 0.0 or np.any(np.diff(sp) <= 0.0):
        raise ValueError("spins must be at least two increasing finite speeds >= 0 rad/s")
    if not driveline.is_isotropic:
        table = driveline.campbell(sp, n_modes)
        return WhirlBranches(sp, table.forward, table.backward)
    x_hi = min(((n_modes + 2) * math.pi / driveline._kappa) ** 2, SEARCH_LIMIT)
    while True:
        knots = sp
        found = _roots_over_speeds(driveline, knots, x_hi, None)
        for round_ in range(REFINEMENTS + 1):
            branches = [_follow(driveline, knots, sign, roots, n_modes) for sign, roots in zip((1.0, -1.0), found)]
            if round_ == REFINEMENTS or knots.size > MAX_KNOTS:
                break
            coarse = np.flatnonzero(_spline_error(driveline, knots, branches) > SPLINE_RTOL)
            if not coarse.size:
                break
            middles = 0.5 * (knots[coarse] + knots[coarse + 1])
            added = _roots_over_speeds(driveline, middles, x_hi, (found, coarse))
            knots = np.insert(knots, coarse + 1, middles)
            found = [_insert(old, coarse + 1, new) for old, new in zip(found, added)]
        enough = min(r.size for roots in found for r in roots) >= n_modes
        if x_hi >= SEARCH_LIMIT or (enough and not any(np.isnan(b).any() for b in branches)):
            return WhirlBranches(knots, *branches)
        x_hi = min(4.0 * x_hi, SEARCH_LIMIT)


def _insert(roots: list[FloatArray], at: NDArray[np.intp], new: list[FloatArray]) -> list[FloatArray]:
    out = list(roots)
    for position, r in sorted(zip(at, new), key=lambda item: -item[0]):
        out.insert(position, r)
    return out


def _roots_over_speeds(
    driveline: Driveline, spins: FloatArray, x_hi: float, between: tuple[list[list[FloatArray]], NDArray[np.intp]] | None
) -> list[list[FloatArray]]:
    """Forward and backward whirl frequencies up to ``x_hi`` at every speed (see the module docstring).

    The coarse counts are checked against the full grid at the first speed, or, for speeds
    ``between`` known ones (their roots, and the index of the speed below each new one),
    against those neighbours.
    """
    lines = np.array([(sign, 0.0, spin) for spin in spins for sign in (1.0, -1.0)])
    found = driveline._line_roots(lines, None, x_hi, SEARCH_LIMIT, coarse=True)
    counts = np.array([r.size for r in found]).reshape(-1, 2)
    if between is None:
        first = driveline._line_roots(lines[:2], None, x_hi, SEARCH_LIMIT)
        reference = [(np.array([first[0].size, first[1].size]), 0)]
    else:
        known, below = between
        sizes = np.array([[r.size for r in sense] for sense in known]).T
        reference = [(sizes[below], 1), (sizes[below + 1], 1)]
    steps = [np.abs(counts[:1] - ref[:1] if between is None else counts - ref) > allowed for ref, allowed in reference]
    if np.any(np.abs(np.diff(counts, axis=0)) > 1) or any(np.any(step) for step in steps):
        found = driveline._line_roots(lines, None, x_hi, SEARCH_LIMIT)
    return [found[0::2], found[1::2]]


def _spline_error(driveline: Driveline, knots: FloatArray, branches: list[FloatArray]) -> FloatArray:
    """Relative error of the branches' cubic splines at the middle of every knot interval (largest of
    all branches), estimated by one Newton step ``f / f_w`` on the determinant there."""
    middles = 0.5 * (knots[:-1] + knots[1:])
    error = np.zeros(middles.size)
    for sign, table in zip((1.0, -1.0), branches):
        w = CubicSpline(knots, table)(middles)
        spin = np.broadcast_to(middles[:, None], w.shape)
        h = SLOPE_STEP * w
        f = driveline.determinant(sign * np.stack([w, w + h, w - h]), np.stack([spin] * 3))
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.abs(f[0] * 2.0 * h / (f[1] - f[2])) / w
        error = np.fmax(error, np.nanmax(np.where(np.isfinite(step), step, np.nan), axis=1, initial=0.0))
    return error


def _follow(driveline: Driveline, spins: FloatArray, sign: float, roots: list[FloatArray], n_modes: int) -> FloatArray:
    """Columns of the branches through ``roots`` (ascending per speed) of the whirl sense ``sign``.

    From speed ``i`` to ``i + 1`` every root moves on by its slope ``dw/dOmega = -f_Omega / f_w``
    (central differences); the predicted positions, in their order, take the roots found
    at ``i + 1`` in theirs, so branches that cross between two speeds keep their identity.
    A root crossing the search limit ends or starts a branch. Only branches among the
    first ``n_modes`` at some speed are returned.
    """
    w = np.concatenate(roots)
    spin = np.repeat(spins, [r.size for r in roots])
    h = SLOPE_STEP * w
    f = driveline.determinant(sign * np.concatenate([w + h, w - h, w, w]),
                              np.concatenate([spin, spin, spin + h, spin - h])).reshape(4, -1)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = -(f[2] - f[3]) / (f[0] - f[1])
    slope = np.split(np.where(np.isfinite(slope), slope, 0.0), np.cumsum([r.size for r in roots])[:-1])
    branch = [np.arange(roots[0].size)]
    count = roots[0].size
    for i in range(spins.size - 1):
        predicted = roots[i] + slope[i] * (spins[i + 1] - spins[i])
        kept = min(roots[i].size, roots[i + 1].size)
        ids = np.concatenate([branch[i][np.argsort(predicted, kind="stable")[:kept]],
                              np.arange(count, count + roots[i + 1].size - kept)])
        count += roots[i + 1].size - kept
        branch.append(ids)
    table = np.full((spins.size, count), np.nan)
    for i, (ids, r) in enumerate(zip(branch, roots)):
        table[i, ids] = r
    used = np.unique(np.concatenate([ids[:n_modes] for ids in branch]))
    return table[:, used]


class WhirlTable:
    """The first ``n_modes`` forward and backward whirl frequencies at any speed of the branches' range.

    Each branch is a cubic spline over the speed (a missing value reads as ``missing``);
    a call sorts the branches of each sense at the speed asked and returns
    ``(forward_1..n, backward_1..n)``, ``missing`` where a sense has fewer branches.
    """

    def __init__(self, branches: WhirlBranches, n_modes: int, missing: float) -> None:
        columns = np.hstack([branches.forward, branches.backward])
        self._spline = CubicSpline(branches.spins, np.where(np.isnan(columns), missing, columns))
        self._forward = branches.forward.shape[1]
        self._n = n_modes
        self._missing = missing

    def __call__(self, speed: float) -> FloatArray:
        values = self._spline(speed)
        out = []
        for part in (values[: self._forward], values[self._forward:]):
            first = np.sort(part)[: self._n]
            out.append(np.pad(first, (0, self._n - first.size), constant_values=self._missing))
        return np.concatenate(out)
