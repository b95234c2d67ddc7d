"""A driveline assembled from elements: whirl frequencies, Campbell data, critical speeds.

All frequencies and speeds are in rad/s. ``spin`` is the shaft speed ``Omega``,
``w`` a whirl frequency. Forward whirl turns with the spin, backward against it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import transfer
from .elements import Bearing, ConcentratedMass, EndCondition, PointElement, ShaftSegment, Unbalance
from .roots import IntArray, find_roots_batch

FloatArray = NDArray[np.float64]
Whirl = Literal["forward", "backward"]

#: Grid points per expected root: the bare shaft has one root per pi of the phase
#: kappa*sqrt(w), and every degree of freedom of a point mass may add one more.
POINTS_PER_ROOT = 16
#: Default upper limit of any search [rad/s] (about 955 000 rpm).
SEARCH_LIMIT = 1.0e5
#: Grid offset of the scan, an irrational fraction of a step: pinned-beam roots sit at theta = k pi.
GRID_OFFSET = 0.6180339887498949
#: Points of the logarithmic lead-in below the scan's first point (the last of them is that point).
LEAD_POINTS = 9
#: How far below the scan's first point the lead-in starts (a ratio of squared frequencies).
LEAD_RATIO = 1e-4
#: Points per segment of the mode shape whose forward fraction tells a whirl's direction.
DIRECTION_POINTS = 4


@dataclass(frozen=True)
class WhirlFrequencies:
    """Natural whirl frequencies at one spin speed [rad/s], ascending."""

    spin: float
    forward: FloatArray
    backward: FloatArray

    @property
    def all(self) -> FloatArray:
        return np.sort(np.concatenate([self.forward, self.backward]))


@dataclass(frozen=True)
class CampbellDiagram:
    """Whirl frequencies over spin speeds: arrays (n_speeds, n_modes), NaN where absent."""

    spins: FloatArray
    forward: FloatArray
    backward: FloatArray


#: Forward share of ``sum |U|^2`` from which unbalance counts as exciting a synchronous mode.
EXCITED_SHARE = 0.01


@dataclass(frozen=True)
class CriticalSpeed:
    """A critical speed [rad/s] and the share of its mode's forward circular component in
    ``sum |U|^2`` (1 forward whirl; anisotropic supports give nearly planar modes near 0.5)."""

    spin: float
    forward_share: float

    @property
    def whirl(self) -> Whirl:
        """The dominant whirl sense of the mode."""
        return "forward" if self.forward_share >= 0.5 else "backward"


@dataclass(frozen=True)
class OrderResonance:
    """Spin speed at which ``order * spin`` equals a whirl frequency of the given sense."""

    order: int
    whirl: Whirl
    spin: float

    @property
    def frequency(self) -> float:
        """Excitation (= whirl) frequency ``order * spin`` [rad/s]."""
        return self.order * self.spin

    def margin(self, spin: float) -> float:
        """Relative separation ``(self.spin - spin) / spin`` (positive: resonance above)."""
        return (self.spin - spin) / spin


def _speed(name: str, value: float, positive: bool = False) -> float:
    v = float(value)
    if not math.isfinite(v) or v < 0.0 or (positive and v == 0.0):
        bound = "> 0" if positive else ">= 0"
        raise ValueError(f"{name} must be a finite speed {bound} rad/s, got {value!r}")
    return v


def _as_tuple(items: Iterable, kind: type, name: str) -> tuple:
    out = tuple(items)
    for i, it in enumerate(out):
        if not isinstance(it, kind):
            raise ValueError(f"{name}[{i}] must be a {kind.__name__}, got {type(it).__name__}")
    return out


@dataclass(frozen=True)
class Driveline:
    """Segments in axial order with point elements at the nodes between them.

    Node ``0`` is the left end, node ``k`` the joint after segment ``k-1``, node
    ``len(segments)`` the right end (as ROSS numbers its nodes). ``left`` and
    ``right`` are the end conditions; bearings are point elements and may sit at
    any node, including the ends (then use ``free`` ends, as the seed's Fig. 2).
    ``joints`` holds further point elements (:class:`Hinge`, ...), applied at their
    node after its masses and bearings; a hinge must sit at an inner node. ``unbalances``
    excite the forced response (:mod:`driveline.rotor.damped`) and leave the whirl alone.
    """

    segments: Sequence[ShaftSegment]
    masses: Sequence[ConcentratedMass] = ()
    bearings: Sequence[Bearing] = ()
    left: EndCondition | str = EndCondition.FREE
    right: EndCondition | str = EndCondition.FREE
    name: str = ""
    joints: Sequence[PointElement] = ()
    unbalances: Sequence[Unbalance] = ()
    _chain: transfer.Chain = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        segs = _as_tuple(self.segments, ShaftSegment, "segments")
        if not segs:
            raise ValueError("segments: a driveline needs at least one shaft segment")
        masses = _as_tuple(self.masses, ConcentratedMass, "masses")
        bearings = _as_tuple(self.bearings, Bearing, "bearings")
        joints = _as_tuple(self.joints, PointElement, "joints")
        n_nodes = len(segs) + 1
        for kind, items in (("masses", masses), ("bearings", bearings), ("joints", joints)):
            for i, it in enumerate(items):
                if it.node >= n_nodes:
                    raise ValueError(
                        f"{kind}[{i}].node = {it.node} is out of range: nodes are 0..{n_nodes - 1}"
                    )
                if it.splits_slope and it.node in (0, n_nodes - 1):
                    raise ValueError(
                        f"{kind}[{i}].node = {it.node}: a {type(it).__name__.lower()} must sit at an inner "
                        f"node (1..{n_nodes - 2}), not at an end"
                    )
        ends = []
        for label, value in (("left", self.left), ("right", self.right)):
            try:
                ends.append(EndCondition(value))
            except ValueError:
                allowed = ", ".join(e.value for e in EndCondition)
                raise ValueError(f"{label} end condition {value!r} is not one of: {allowed}") from None
        object.__setattr__(self, "segments", segs)
        object.__setattr__(self, "masses", masses)
        object.__setattr__(self, "bearings", bearings)
        object.__setattr__(self, "joints", joints)
        unbalances = _as_tuple(self.unbalances, Unbalance, "unbalances")
        length = math.fsum(s.length for s in segs)
        for i, it in enumerate(unbalances):
            if it.position > length:
                raise ValueError(f"unbalances[{i}].position = {it.position!r} m lies beyond the right end ({length!r} m)")
        object.__setattr__(self, "unbalances", unbalances)
        object.__setattr__(self, "left", ends[0])
        object.__setattr__(self, "right", ends[1])
        object.__setattr__(self, "_chain", transfer.Chain.build(segs, self.point_elements, ends[0], ends[1]))

    @property
    def point_elements(self) -> tuple[PointElement, ...]:
        """Every point element, in the order applied at a node: masses, bearings, joints."""
        return (*self.masses, *self.bearings, *self.joints)

    @property
    def length(self) -> float:
        """Overall length [m]."""
        return math.fsum(s.length for s in self.segments)

    @property
    def is_isotropic(self) -> bool:
        """True when every element acts on each whirl component alone (4x4 formulation)."""
        return self._chain.isotropic

    @property
    def _kappa(self) -> float:
        """Phase constant: the bare shaft has a mode every pi of ``kappa * sqrt(w)``."""
        return float(sum(s.length * (s.mass_per_length / s.bending_stiffness) ** 0.25 for s in self.segments))

    @property
    def freedoms(self) -> int:
        """Degrees of freedom the point elements add at their nodes, each of which can add a root
        anywhere in a search range (the search grids are that much finer)."""
        return sum(len(frozenset().union(*(el.freedoms for el in node))) for node in self._chain.points)

    # -- determinant -----------------------------------------------------------
    def determinant(self, w: ArrayLike, spin: ArrayLike = 0.0) -> FloatArray:
        """Scaled frequency determinant ``f(w, spin)`` (seed Eq. 31), vectorised.

        Isotropic: signed ``w`` (forward > 0, backward < 0). Anisotropic: ``w > 0``.
        """
        return transfer.determinant(self._chain, w, spin)

    def mode_shape(self, w: float, spin: float = 0.0, points_per_segment: int = 8) -> transfer.ModeShape:
        """Deflection shape at a natural frequency ``w`` (see :func:`transfer.mode_shape`)."""
        return transfer.mode_shape(self._chain, w, spin, points_per_segment)

    # -- grids and searches ----------------------------------------------------
    def _grid(self, x_max: float, ratio: float, coarse: bool = False) -> FloatArray:
        """Search grid on ``(0, x_max]`` for the frequency ``ratio * x``.

        Uniform in the bare-shaft phase ``theta = kappa sqrt(|ratio| x)``. The shaft
        alone has one root per pi of ``theta``; each translational or rotational
        degree of freedom of a concentrated mass can add one root anywhere, and the
        8x8 (anisotropic) determinant holds both whirl senses. The grid has
        ``POINTS_PER_ROOT`` points per expected root on that count (``coarse``: per
        bare-shaft root only), plus a logarithmic lead-in for heavy masses on soft
        bearings near zero.
        """
        extra = 0 if coarse else self.freedoms
        per_pi = POINTS_PER_ROOT * (1 + extra) * (1 if self.is_isotropic else 2)
        kappa = self._kappa * math.sqrt(abs(ratio))
        theta_max = kappa * math.sqrt(x_max)
        n = max(math.ceil(theta_max / math.pi * per_pi), 8)
        theta = (np.arange(n) + GRID_OFFSET) * (theta_max / n)
        theta = np.append(theta, theta_max)  # the scan must reach x_max itself
        x = (theta / kappa) ** 2
        lead = np.geomspace(x[0] * LEAD_RATIO, x[0], LEAD_POINTS)[:-1]
        return np.concatenate([lead, x])

    def _line_roots(
        self, lines: FloatArray, n: int | None, x_max: float | None, limit: float, coarse: ArrayLike = False
    ) -> list[FloatArray]:
        """Roots ``x > 0`` of ``f(w, spin)`` along every line ``(w, spin) = (w_k x, s_k x + o_k)``, one
        batch search: all up to ``x_max`` (on ``coarse`` grids where asked, per line), or the first
        ``n`` below ``limit``.

        ``lines`` is (m, 3) with rows ``(w_k, s_k, o_k)``; each line's grid follows its ``|w_k|``.
        A line short of ``n`` roots is searched again over a 4x wider range, until ``limit``.
        """
        lines = np.asarray(lines, dtype=float)
        ratios = np.abs(lines[:, 0])
        if x_max is not None:
            kinds = list(zip(ratios, np.broadcast_to(coarse, ratios.shape)))
            grid = {kind: self._grid(x_max, *kind) for kind in set(kinds)}
            return self._batch(lines, [grid[kind] for kind in kinds])
        if n is None or isinstance(n, bool) or not float(n).is_integer() or n < 1:
            raise ValueError(f"n must be a positive integer (or give an upper limit), got {n!r}")
        limit = _speed("limit", limit, positive=True)
        x_hi = np.minimum(((n + 2) * math.pi / (self._kappa * np.sqrt(ratios))) ** 2, limit)
        out: list[FloatArray] = [np.empty(0)] * len(lines)
        todo = np.arange(len(lines))
        while todo.size:
            found = self._batch(lines[todo], [self._grid(x_hi[j], ratios[j]) for j in todo])
            short = []
            for j, roots in zip(todo, found):
                out[j] = roots[:n]
                if roots.size < n and x_hi[j] < limit:
                    short.append(j)
            todo = np.array(short, dtype=np.intp)
            x_hi[todo] = np.minimum(4.0 * x_hi[todo], limit)
        return out

    def _batch(self, lines: FloatArray, grids: list[FloatArray]) -> list[FloatArray]:
        """Roots of the determinant along ``lines`` (rows ``(w_k, s_k, o_k)``) on their ``grids``, one batch."""
        w_k, s_k, o_k = lines.T
        def f(x: FloatArray, k: IntArray, extra_pieces: int = 0) -> tuple[FloatArray, FloatArray]:
            return transfer.determinant_and_rounding(self._chain, w_k[k] * x, s_k[k] * x + o_k[k], extra_pieces)

        return find_roots_batch(f, grids, again=lambda x, k: f(x, k, 1)[0]).roots

    @staticmethod
    def _take(roots: FloatArray, n: int | None) -> FloatArray:
        return roots if n is None else roots[:n]

    def _roots_by_whirl(
        self,
        cases: ArrayLike,
        whirls: tuple[Whirl, ...],
        n: int | None,
        x_max: float | None,
        limit: float,
    ) -> list[dict[Whirl, FloatArray]]:
        """Roots ``x`` of ``f(+-w, spin) = 0`` on every case ``(w, spin) = (r x, s x + o)``, per whirl sense.

        ``cases`` is (m, 3) with rows ``(r > 0, s, o)``, all searched in one batch.
        Isotropic: forward at ``+w``, backward at ``-w``, each a line of its own.
        Anisotropic: the ``2 n`` lowest roots at ``w > 0``, each classified by its
        mode shape (forward when the forward component carries more than half of
        ``sum |U|^2``). At standstill (``s = o = 0``) the modes are planar: both
        senses get the same roots, searched once.
        """
        cases = np.atleast_2d(np.asarray(cases, dtype=float))
        standstill = (cases[:, 1] == 0.0) & (cases[:, 2] == 0.0)
        senses = (1.0, -1.0) if self.is_isotropic else (1.0,)
        lines, owner = [], []
        for c, case in enumerate(cases):
            for sign in senses[: 1 if standstill[c] else None]:
                lines.append((sign * case[0], case[1], case[2]))
                owner.append((c, sign))
        nn = n if n is None or self.is_isotropic else 2 * n
        found = dict(zip(owner, self._line_roots(np.array(lines), nn, x_max, limit)))
        out = []
        for c, (r, s, o) in enumerate(cases):
            if standstill[c]:
                roots = self._take(found[c, 1.0], n)
                out.append({wh: roots for wh in whirls})
            elif self.is_isotropic:
                out.append({wh: self._take(found[c, 1.0 if wh == "forward" else -1.0], n) for wh in whirls})
            else:
                roots = found[c, 1.0]
                kinds = np.array(["forward" if self.mode_shape(r * x, s * x + o, DIRECTION_POINTS).forward_fraction >= 0.5
                                  else "backward" for x in roots], dtype=object)
                out.append({wh: self._take(roots[kinds == wh], n) for wh in whirls})
        return out

    # -- results -----------------------------------------------------------------
    def whirl_frequencies(
        self, spin: float = 0.0, n: int | None = 4, w_max: float | None = None, limit: float = SEARCH_LIMIT
    ) -> WhirlFrequencies:
        """Natural whirl frequencies at spin speed ``spin`` [rad/s].

        Either the first ``n`` of each sense (default 4) or all up to ``w_max``.
        At ``spin = 0`` both lists hold the same (planar) modes. With anisotropic
        bearings a mode is forward when its forward circular component carries
        more than half of ``sum |U|^2``; the ``2 n`` lowest modes are split, so a
        list may hold fewer than ``n``.
        """
        spin = _speed("spin", spin)
        if w_max is not None:
            w_max = _speed("w_max", w_max, positive=True)
            n = None
        found = self._roots_by_whirl([(1.0, 0.0, spin)], ("forward", "backward"), n, w_max, limit)[0]
        return WhirlFrequencies(spin, found["forward"], found["backward"])

    def campbell(self, spins: ArrayLike, n_modes: int = 4) -> CampbellDiagram:
        """Campbell diagram data: first ``n_modes`` forward and backward frequencies per speed, one batch search."""
        sp = np.atleast_1d(np.asarray(spins, dtype=float))
        for v in sp:
            _speed("spins", v)
        fwd = np.full((sp.size, n_modes), np.nan)
        bwd = np.full((sp.size, n_modes), np.nan)
        cases = np.column_stack([np.ones(sp.size), np.zeros(sp.size), sp])
        for i, r in enumerate(self._roots_by_whirl(cases, ("forward", "backward"), n_modes, None, SEARCH_LIMIT)):
            fwd[i, : r["forward"].size] = r["forward"]
            bwd[i, : r["backward"].size] = r["backward"]
        return CampbellDiagram(sp, fwd, bwd)

    def order_resonances(
        self,
        orders: Iterable[int] = (1,),
        whirl: Iterable[Whirl] = ("forward",),
        n: int | None = 3,
        spin_max: float | None = None,
        limit: float = SEARCH_LIMIT,
    ) -> list[OrderResonance]:
        """Spin speeds where ``order * spin`` equals a whirl frequency, sorted by speed.

        Solved directly as roots of ``f(+-order*spin, spin)`` in ``spin``: order 1
        forward gives the critical speeds; orders 2 (Cardan joints), 3 and 6
        (tripod joints) the order resonances. Either the first ``n`` per order and
        sense, or all up to ``spin_max``.
        """
        if spin_max is not None:
            spin_max = _speed("spin_max", spin_max, positive=True)
        whirls = tuple(whirl)
        for wh in whirls:
            if wh not in ("forward", "backward"):
                raise ValueError(f"whirl must be 'forward' or 'backward', got {wh!r}")
        ks = []
        for k in orders:
            if isinstance(k, bool) or int(k) != k or k < 1:
                raise ValueError(f"order must be a positive integer, got {k!r}")
            ks.append(int(k))
        if not ks:
            return []
        cases = [(k, 1.0, 0.0) for k in ks]
        found = self._roots_by_whirl(cases, whirls, n, spin_max, limit)
        out = [OrderResonance(k, wh, float(x)) for k, roots in zip(ks, found) for wh in whirls for x in roots[wh]]
        return sorted(out, key=lambda r: (r.spin, r.order))

    def critical_speeds(
        self, n: int | None = 3, whirl: Whirl = "forward", spin_max: float | None = None, limit: float = SEARCH_LIMIT
    ) -> FloatArray:
        """Critical speeds [rad/s]: spin speeds with a synchronous whirl frequency.

        ``whirl="forward"`` (default): the speeds unbalance excites, :meth:`unbalance_critical_speeds`
        (isotropic supports: the roots of ``f(Omega, Omega) = 0``). ``"backward"`` solves
        ``f(-Omega, Omega) = 0`` (anisotropic: the synchronous roots classified backward). First ``n``
        or all up to ``spin_max``. Fewer than ``n`` are returned if no more exist below ``limit``
        (a Rayleigh shaft has finitely many forward critical speeds).
        """
        if whirl == "forward":
            return np.array([c.spin for c in self.unbalance_critical_speeds(n, spin_max, limit)])
        res = self.order_resonances((1,), (whirl,), n, spin_max, limit)
        return np.array([r.spin for r in res])

    def unbalance_critical_speeds(
        self, n: int | None = 3, spin_max: float | None = None, limit: float = SEARCH_LIMIT
    ) -> list[CriticalSpeed]:
        """The synchronous roots (whirl = spin) whose mode unbalance excites, ascending.

        Unbalance is a forward rotating force: it excites a mode through the mode's forward
        circular component. Isotropic supports: the forward roots (backward modes have none).
        Anisotropic supports: every synchronous root whose forward share of ``sum |U|^2`` is at
        least :data:`EXCITED_SHARE`, among the ``2 (n + 1)`` lowest (fewer than ``n`` are returned
        when nearly pure backward modes crowd them out).
        """
        if self.is_isotropic:
            return [CriticalSpeed(r.spin, 1.0) for r in self.order_resonances((1,), ("forward",), n, spin_max, limit)]
        found = self.order_resonances((1,), ("forward", "backward"), None if n is None else n + 1, spin_max, limit)
        shares = [(r.spin, self.mode_shape(r.spin, r.spin, DIRECTION_POINTS).forward_fraction) for r in found]
        excited = [CriticalSpeed(spin, share) for spin, share in sorted(shares) if share >= EXCITED_SHARE]
        return excited if n is None else excited[:n]

    def nearest_order_resonance(
        self,
        spin: float,
        orders: Iterable[int] = (1, 2),
        whirl: Iterable[Whirl] = ("forward", "backward"),
        limit: float = SEARCH_LIMIT,
    ) -> OrderResonance | None:
        """The order resonance whose spin speed is closest to ``spin`` (``None`` if none below ``limit``)."""
        spin = _speed("spin", spin, positive=True)
        orders = tuple(orders)
        whirl = tuple(whirl)
        span = min(2.0 * spin, limit)
        # Within (0, 2 spin] any resonance is nearer than all beyond 2 spin.
        cands = self.order_resonances(orders, whirl, None, span, limit)
        if not cands:
            cands = self.order_resonances(orders, whirl, 1, None, limit)
        if not cands:
            return None
        return min(cands, key=lambda r: abs(r.spin - spin))
