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
#: An estimated spline error within this multiple of the estimate's own round-off is no error.
NOISE = 10.0


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
    added to the speeds, up to ``REFINEMENTS`` times. A branch missing at some speed (crossing
    the search bound) widens the search, up to ``SEARCH_LIMIT``; the rounds to be widened are not
    refined. At the final bound the complete branches are refined and the missing one is returned
    with its NaN, its spline error left out. Anisotropic drivelines (whose whirl
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
            branches = [_follow(knots, roots, slopes, n_modes)
                        for roots, slopes in zip(found, _slopes(driveline, knots, found))]
            enough = min(r.size for roots in found for r in roots) >= n_modes
            final = x_hi >= SEARCH_LIMIT or (enough and _complete(branches))
            if round_ == REFINEMENTS or knots.size > MAX_KNOTS or not final:
                break  # a round to be widened restarts from ``sp``: refining it is wasted
            rough = np.flatnonzero(_spline_error(driveline, knots, branches) > SPLINE_RTOL)
            if not rough.size:
                break
            middles = 0.5 * (knots[rough] + knots[rough + 1])
            counts = np.array([[r.size for r in sense] for sense in found]).T  # (speeds, senses)
            added = _roots_over_speeds(driveline, middles, x_hi, np.stack([counts[rough], counts[rough + 1]], axis=1))
            knots = np.insert(knots, rough + 1, middles)
            found = [_insert(old, rough + 1, new) for old, new in zip(found, added)]
        if final:
            return WhirlBranches(knots, *branches)
        x_hi = min(4.0 * x_hi, SEARCH_LIMIT)


def _complete(branches: list[FloatArray]) -> bool:
    """No branch missing at any speed (none crosses the search bound)."""
    return not any(np.isnan(table).any() for table in branches)


def _insert(roots: list[FloatArray], at: NDArray[np.intp], new: list[FloatArray]) -> list[FloatArray]:
    """``roots`` with ``new[k]`` inserted before index ``at[k]`` (of the original list), for every ``k``."""
    out = list(roots)
    for position, r in sorted(zip(at, new), key=lambda item: -item[0]):
        out.insert(position, r)
    return out


def _roots_over_speeds(
    driveline: Driveline, spins: FloatArray, x_hi: float, neighbours: NDArray[np.intp] | None
) -> list[list[FloatArray]]:
    """Forward and backward whirl frequencies up to ``x_hi`` at every speed (see the module docstring).

    Searched on bare-shaft grids; a new set of speeds (``neighbours`` None) is checked
    against the full grid at its first speed, speeds inserted between known ones against
    the counts (forward, backward) at the known speed below and above each,
    ``neighbours`` (k, 2, 2). A failed check searches every speed on the full grid.
    """
    lines = np.array([(sign, 0.0, spin) for spin in spins for sign in (1.0, -1.0)])
    reference = lines[:2] if neighbours is None else lines[:0]
    coarse = np.arange(len(lines) + len(reference)) < len(lines)
    found = driveline._line_roots(np.vstack([lines, reference]), None, x_hi, SEARCH_LIMIT, coarse)
    counts = np.array([r.size for r in found[: len(lines)]]).reshape(-1, 2)
    if neighbours is None:
        full_count = [r.size for r in found[len(lines):]]
        failed = np.any(counts[0] != full_count) or np.any(np.abs(np.diff(counts, axis=0)) > 1)
    else:
        failed = np.any(np.abs(counts[:, None, :] - neighbours) > 1)
    if failed:
        found = driveline._line_roots(lines, None, x_hi, SEARCH_LIMIT)
    return [found[0 : len(lines) : 2], found[1 : len(lines) : 2]]


def _slopes(driveline: Driveline, spins: FloatArray, found: list[list[FloatArray]]) -> list[list[FloatArray]]:
    """Slopes ``dw/dOmega = -f_Omega / f_w`` (central differences, one evaluation) of the forward and
    backward whirl frequencies ``found`` at ``spins``; 0 where undefined (a double root)."""
    sizes = [r.size for sense in found for r in sense]
    w = np.concatenate([r for sense in found for r in sense])
    spin = np.repeat(np.tile(spins, 2), sizes)
    sign = np.repeat([1.0, -1.0], [sum(r.size for r in sense) for sense in found])
    h = SLOPE_STEP * w
    f = driveline.determinant(np.concatenate([sign * (w + h), sign * (w - h), sign * w, sign * w]),
                              np.concatenate([spin, spin, spin + h, spin - h])).reshape(4, -1)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = -(f[2] - f[3]) / (f[0] - f[1])
    parts = np.split(np.where(np.isfinite(slope), slope, 0.0), np.cumsum(sizes)[:-1])
    return [parts[: spins.size], parts[spins.size :]]


def _spline_error(driveline: Driveline, knots: FloatArray, branches: list[FloatArray]) -> FloatArray:
    """Relative error of the branches' cubic splines at the middle of every knot interval (largest of
    all branches), estimated by one Newton step ``f / f_w`` on the determinant there. The same step
    at the interval's ends, where the splines hold the roots, is the round-off of the estimate:
    an error within ``NOISE`` times that counts as zero. A branch missing at some speed (NaN) has
    no spline and contributes no error."""
    complete = [table[:, ~np.isnan(table).any(axis=0)] for table in branches]
    if not any(table.shape[1] for table in complete):
        return np.zeros(knots.size - 1)
    at = np.concatenate([0.5 * (knots[:-1] + knots[1:]), knots])
    w = np.hstack([CubicSpline(knots, table)(at) for table in complete if table.shape[1]])
    sign = np.repeat([1.0, -1.0], [table.shape[1] for table in complete])
    spin = np.broadcast_to(at[:, None], w.shape)
    h = SLOPE_STEP * w
    f = driveline.determinant(sign * np.stack([w, w + h, w - h]), np.stack([spin] * 3))
    with np.errstate(divide="ignore", invalid="ignore"):
        step = np.abs(f[0] * 2.0 * h / (f[1] - f[2])) / w
    step = np.where(np.isfinite(step), step, 0.0)
    middle, end = step[: knots.size - 1], step[knots.size - 1:]
    noise = NOISE * np.maximum(end[:-1], end[1:])
    return np.max(np.where(middle > noise, middle, 0.0), axis=1, initial=0.0)


def _follow(spins: FloatArray, roots: list[FloatArray], slopes: list[FloatArray], n_modes: int) -> FloatArray:
    """Columns of the branches through ``roots`` (ascending per speed) of one whirl sense.

    From speed ``i`` to ``i + 1`` every root moves on by its slope; the predicted
    positions, in their order, take the roots found at ``i + 1`` in theirs, so branches
    that cross between two speeds keep their identity. A root crossing the search limit
    ends or starts a branch. Only branches among the first ``n_modes`` at some speed are
    returned.
    """
    branch = [np.arange(roots[0].size)]
    count = roots[0].size
    for i in range(spins.size - 1):
        predicted = roots[i] + slopes[i] * (spins[i + 1] - spins[i])
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

    Each branch is a cubic spline over the speed (a missing value reads as ``missing``, and
    a sense with fewer than ``n_modes`` branches gets constant ones at ``missing``); a call
    sorts the branches of each sense at the speed asked and returns ``(forward_1..n, backward_1..n)``.
    """

    def __init__(self, branches: WhirlBranches, n_modes: int, missing: float) -> None:
        senses = []
        for table in (branches.forward, branches.backward):
            short = max(n_modes - table.shape[1], 0)
            senses.append(np.hstack([table, np.full((table.shape[0], short), missing)]))
        columns = np.hstack(senses)
        self._spline = CubicSpline(branches.spins, np.where(np.isnan(columns), missing, columns))
        self._forward = senses[0].shape[1]
        self._n = n_modes

    @property
    def knots(self) -> FloatArray:
        """The speeds the splines pass through (the branches' speeds)."""
        return self._spline.x

    def __call__(self, speed: float) -> FloatArray:
        values = self._spline(speed)
        k, n = self._forward, self._n
        return np.concatenate((np.sort(values[:k])[:n], np.sort(values[k:])[:n]))
