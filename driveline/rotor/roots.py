"""Bracketing root search on vectorised scalar functions (seed Sec. 8, Fig. 3, reworked).

The seed scans ``f`` with a step of 1/100-1/1000 of the interval and refines a
sign change by repeatedly dividing the step by ten. Here every stage runs on all
functions of a batch (e.g. the determinant at 41 spin speeds) and on all their
brackets at once, one vectorised call per stage:

1. ``f`` is evaluated on every grid in one call;
2. all sign changes are refined together by a vectorised Chandrupatla iteration
   (inverse quadratic interpolation where it is safe, bisection otherwise) to the
   root tolerance; a bracket whose converged point has a larger ``|f|`` than both
   its ends is a pole, not a root, and is rejected (the scaled determinant has no
   poles; the guard is for any other ``f`` passed in);
3. a pair of roots closer than the grid step shows no sign change, only a dip of
   ``|f|``: every grid point where ``|f|`` has a local minimum without a sign change
   and at most ``DIP_RATIO`` of its larger neighbour is re-scanned on a finer
   sub-grid, all dips of one level together, recursively; a dip that persists
   down to the root tolerance is reported as a double root.

Where ``f`` also returns its rounding level (the scaled determinant does), the
search does not chase round-off: a dip whose bottom lies within ``ROUNDING``
times its rounding level of zero is as deep as ``f`` resolves, a double root, not
re-scanned; any other dip no deeper than ``ROUNDING`` times the rounding levels of
its three points is ripple and is dropped. At most ``MAX_DIPS`` dips of one
function are re-scanned; a function with more is refused (ArithmeticError).

Where ``f`` can also be evaluated ``again`` another way that is exact in exact
arithmetic (the determinant with every segment cut into one more piece), the
three points of every dip are evaluated again and their rounding levels raised
to at least the difference: a sample of the round-off ``f`` accumulates before
its last step, which its own rounding level does not see (issue 45: a layout
whose determinant is noise of 5e10 where that level says 1.5e-4, and whose dips
then depended on each core's round-off).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]
#: ``f(x, k)``: the ``k[i]``-th function of a batch at ``x[i]``, or that and its rounding level there.
BatchFunc = Callable[[FloatArray, IntArray], FloatArray | tuple[FloatArray, FloatArray]]
#: ``again(x, k)``: the ``k[i]``-th function at ``x[i]`` evaluated another way, equal in exact arithmetic.
AgainFunc = Callable[[FloatArray, IntArray], FloatArray]

SUBGRID = 24
#: Sub-grid levels: each divides the dip's width by SUBGRID / 2 (16 levels span 1e17).
MAX_DEPTH = 16
#: A dip is examined when |f| there is below this fraction of its larger neighbour
#: (an isolated hidden pair gives at most 1/9; neighbouring roots raise that).
DIP_RATIO = 0.9
#: A dip within this multiple of the rounding levels is round-off (a ripple measured at about one level).
ROUNDING = 8.0
#: Dips re-scanned at most on one function (all levels): a hidden pair costs one or two per level.
MAX_DIPS = 512
#: Iteration cap of the bracket refinement (it halves a bracket at least every third step).
MAX_ITERATIONS = 200
#: Default absolute and relative tolerance of a root.
XTOL = 1e-12
RTOL = 4.0 * float(np.finfo(float).eps)


@dataclass(frozen=True)
class BatchReport:
    """Roots of every function of a batch (ascending, double roots twice) and search diagnostics."""

    roots: list[FloatArray]
    evaluations: int
    rejected_poles: int
    dips_examined: int
    double_roots: int


def find_roots_batch(
    f: BatchFunc, grids: Sequence[FloatArray], xtol: float = XTOL, rtol: float = RTOL, again: AgainFunc | None = None
) -> BatchReport:
    """Roots of the functions ``f(., k)`` inside ``[grids[k][0], grids[k][-1]]``, all searched together.

    Each grid must be strictly increasing and resolve its function's oscillation. A
    root is located to ``xtol + rtol |x|`` or better (the interpolation converges
    superlinearly, so usually to round-off).
    """
    xs = [np.asarray(g, dtype=float) for g in grids]
    for x in xs:
        if x.ndim != 1 or x.size < 3 or np.any(np.diff(x) <= 0):
            raise ValueError("grid must be a strictly increasing 1-D array of at least 3 points")
    st = _Search(f, xtol, rtol, again)
    x = np.concatenate(xs)
    line = np.repeat(np.arange(len(xs)), [g.size for g in xs])
    seq, (fx, rx) = line.copy(), st.eval(x, line)
    st.rescans = np.zeros(len(xs), dtype=np.intp)
    depth = 0
    while x.size:
        x, fx, rx, line, seq = _scan(st, x, fx, rx, line, seq, depth)
        depth += 1
    _refine(st)
    found = np.concatenate(st.roots)
    where = np.concatenate(st.lines)
    roots = [np.sort(found[where == k]) for k in range(len(xs))]
    return BatchReport(roots, st.evaluations, st.poles, st.dips, st.doubles)


class _Search:
    """Evaluation counter, collected brackets and roots of one batch search."""

    def __init__(self, f: BatchFunc, xtol: float, rtol: float, again: AgainFunc | None = None) -> None:
        self.f, self.xtol, self.rtol, self.again = f, xtol, rtol, again
        self.evaluations = self.poles = self.dips = self.doubles = 0
        self.roots: list[FloatArray] = [np.empty(0)]
        self.lines: list[IntArray] = [np.empty(0, dtype=np.intp)]
        self.brackets: list[tuple[FloatArray, ...]] = []
        self.rescans = np.zeros(0, dtype=np.intp)

    def eval(self, x: FloatArray, line: IntArray) -> tuple[FloatArray, FloatArray]:
        """``f`` at ``x`` on ``line`` and its rounding level (0 where ``f`` gives none)."""
        self.evaluations += x.size
        if not x.size:
            return np.empty(0), np.empty(0)
        values = self.f(x, line)
        if isinstance(values, tuple):
            return np.asarray(values[0], dtype=float), np.asarray(values[1], dtype=float)
        return np.asarray(values, dtype=float), np.zeros(x.size)

    def rounding(self, x: FloatArray, fx: FloatArray, rx: FloatArray, line: IntArray) -> FloatArray:
        """The rounding levels ``rx`` of ``f`` (``fx``) at ``x`` raised to the difference from an evaluation
        ``again`` (unchanged without one)."""
        if self.again is None or not x.size:
            return rx
        self.evaluations += x.size
        return np.maximum(rx, np.abs(fx - np.asarray(self.again(x, line), dtype=float)))

    def found(self, x: FloatArray, line: IntArray) -> None:
        self.roots.append(x)
        self.lines.append(line)


def _scan(st: _Search, x: FloatArray, fx: FloatArray, rx: FloatArray, line: IntArray, seq: IntArray, depth: int):
    """Record the zeros and sign changes of the sampled sequences ``seq`` (``x`` ascending in each, ``f``
    ``fx`` with rounding levels ``rx``); return the sub-grids of their dips, sampled, for the next level."""
    s = np.sign(fx)
    af = np.abs(fx)
    zero = s == 0.0
    st.found(x[zero], line[zero])
    linked = seq[:-1] == seq[1:]
    change = np.flatnonzero(linked & (s[:-1] * s[1:] < 0))
    st.brackets.append((x[change], x[change + 1], fx[change], fx[change + 1], line[change]))
    # dips: local minima of |f| with the same sign on both neighbours
    inner = linked[:-1] & linked[1:]
    same = (s[:-2] == s[1:-1]) & (s[1:-1] == s[2:]) & ~zero[1:-1]
    dip = inner & same & (af[1:-1] < af[:-2]) & (af[1:-1] <= af[2:])
    # A hidden pair r1 ~ r2 makes f ~ c (x - r1)(x - r2): the nearest grid point then
    # has at most 1/9 of its larger neighbour's |f|. Shallow dips (round-off ripple
    # on a flat stretch) are not examined.
    dip &= af[1:-1] <= DIP_RATIO * np.maximum(af[:-2], af[2:])
    # the propagation's round-off at the dips' points, which the rounding levels of f do not see
    at = np.unique(np.flatnonzero(dip)[:, None] + np.arange(3)[None, :])
    rx = rx.copy()
    rx[at] = st.rounding(x[at], fx[at], rx[at], line[at])
    # a dip whose bottom f does not resolve from zero is kept (a double root, below); one whose depth
    # the rounding of its points explains is ripple
    unresolved = af[1:-1] <= ROUNDING * rx[1:-1]
    dip &= unresolved | (np.maximum(af[:-2], af[2:]) - af[1:-1] > ROUNDING * (rx[:-2] + rx[1:-1] + rx[2:]))
    i = np.flatnonzero(dip) + 1
    st.dips += i.size
    lo, hi, mid = x[i - 1], x[i + 1], x[i]
    # a dip that persists down to the root tolerance, or to f's rounding, is a double root
    double = (hi - lo <= 2.0 * (st.xtol + st.rtol * np.abs(mid))) | (depth >= MAX_DEPTH) | unresolved[i - 1]
    st.doubles += int(np.count_nonzero(double))
    st.found(np.repeat(mid[double], 2), np.repeat(line[i][double], 2))
    i, lo, hi = i[~double], lo[~double], hi[~double]
    st.rescans += np.bincount(line[i], minlength=st.rescans.size)
    if np.any(st.rescans > MAX_DIPS):
        raise ArithmeticError(f"the root search met more than {MAX_DIPS} dips on one line: "
                              "rounding hides the roots there")
    t = np.linspace(0.0, 1.0, SUBGRID + 1)
    sub = lo[:, None] + (hi - lo)[:, None] * t[None, 1:-1]
    sub_line = np.repeat(line[i], SUBGRID - 1)
    fsub, rsub = (part.reshape(sub.shape) for part in st.eval(sub.ravel(), sub_line))
    xs = np.concatenate([lo[:, None], sub, hi[:, None]], axis=1)
    fs = np.concatenate([fx[i - 1][:, None], fsub, fx[i + 1][:, None]], axis=1)
    rs = np.concatenate([rx[i - 1][:, None], rsub, rx[i + 1][:, None]], axis=1)
    width = SUBGRID + 1
    return xs.ravel(), fs.ravel(), rs.ravel(), np.repeat(line[i], width), np.repeat(np.arange(i.size), width)


def _refine(st: _Search) -> None:
    """Refine every collected bracket together (Chandrupatla's method, vectorised).

    Each step puts the new point at a fraction ``t`` of the bracket from its newest
    end: inverse quadratic interpolation through the last three points when the
    function is monotone enough there (Chandrupatla's test), else ``t = 1/2``; ``t``
    is kept at least the tolerance away from either end. A bracket is done when
    narrower than twice the tolerance or on an exact zero; its root is the end with
    the smaller ``|f|``. A converged point with ``|f|`` above both initial ends is a pole.
    """
    a, b, fa, fb, line = (np.concatenate(parts) for parts in zip(*st.brackets))
    f_ends = np.maximum(np.abs(fa), np.abs(fb))
    c, fc = b.copy(), fb.copy()
    t = np.full(a.size, 0.5)
    root = np.empty(a.size)
    f_root = np.empty(a.size)
    active = np.arange(a.size)
    for _ in range(MAX_ITERATIONS):
        if not active.size:
            break
        xt = a + t * (b - a)
        ft = st.eval(xt, line[active])[0]
        keep = np.sign(ft) == np.sign(fa)  # the new point replaces a; else b becomes a
        c, fc = np.where(keep, a, b), np.where(keep, fa, fb)
        b, fb = np.where(keep, b, a), np.where(keep, fb, fa)
        a, fa = xt, ft
        best_a = np.abs(fa) < np.abs(fb)
        xm, fm = np.where(best_a, a, b), np.where(best_a, fa, fb)
        with np.errstate(divide="ignore"):
            tlim = (st.xtol + st.rtol * np.abs(xm)) / np.abs(b - a)
        done = (fm == 0.0) | (tlim > 0.5)
        root[active[done]], f_root[active[done]] = xm[done], fm[done]
        go = ~done
        a, b, c, fa, fb, fc, tlim = a[go], b[go], c[go], fa[go], fb[go], fc[go], tlim[go]
        active = active[go]
        with np.errstate(divide="ignore", invalid="ignore"):
            xi = (a - b) / (c - b)
            phi = (fa - fb) / (fc - fb)
            quadratic = (phi * phi < xi) & ((1.0 - phi) ** 2 < 1.0 - xi)
            t = np.where(quadratic, fa / (fb - fa) * fc / (fb - fc)
                         + (c - a) / (b - a) * fa / (fc - fa) * fb / (fc - fb), 0.5)
        t = np.clip(np.where(np.isfinite(t), t, 0.5), tlim, 1.0 - tlim)
    else:
        raise ArithmeticError("root refinement did not converge")
    pole = np.abs(f_root) > f_ends  # |f| grew towards the 'root': a pole
    st.poles += int(np.count_nonzero(pole))
    st.found(root[~pole], line[~pole])
