"""Time stepping of the critical-speed monitor: analysis when the structure changes, lookups per step.

The driveline is analysed once per distinct set of structural parameters (at
initialisation, and again when a tunable parameter changes): critical speeds, order
resonances up to twice ``omega_max``, and a Campbell table of the first two forward
and backward whirl frequencies, interpolated per step with cubic splines.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.linalg import eigh

from ..model import SteppedModel
from . import fem
from .driveline import SEARCH_LIMIT, Driveline, OrderResonance
from .elements import Bearing, Unbalance
from .loader import example_path, load_driveline, one_piece_shaft
from .spec import SPEC
from .unbalance_outputs import UnbalanceOutputs

#: Orders watched at most, and the highest order (joints excite low orders: 1, 2, 3, 6).
MAX_ORDERS = 16
MAX_ORDER = 100
#: Work limit of one analysis in units of :func:`searched_modes`: the default shaft needs 28 (0.6 s),
#: a 10 m tube 197 (2 s); 250 keeps one analysis below about 5 s on one core.
MAX_SEARCHED_MODES = 250.0
#: Finite-element plausibility check of every analysis (:func:`implausibility`).
FE_ELEMENTS = 4
PLAUSIBLE_DEVIATION = 0.02
CAMPBELL_POINTS = 41  # spline knots over [0, omega_max]; measured interpolation error <= 1e-12 relative
WHIRL_MODES = 2
SHAFT_PARAMETERS = ("L_shaft", "D_outer", "D_inner", "E", "density", "m_joint", "Jp_joint", "Jd_joint", "k_bearing",
                    "c_bearing", "shear")
UNBALANCE_PARAMETERS = ("unbalance", "unbalance_position", "response_position")


@dataclass(frozen=True)
class Analysis:
    """Everything a step needs, for one set of structural parameters."""

    critical_speeds: tuple[float, float, float]  # missing ones (beyond the search limit) = the limit
    critical_speed_count: int
    whirl: CubicSpline  # |omega| -> (forward_1, forward_2, backward_1, backward_2)
    resonances: tuple[OrderResonance, ...]

    @property
    def resonance_speeds(self) -> np.ndarray:
        return np.array([r.spin for r in self.resonances])


def parse_orders(text: str) -> tuple[int, ...]:
    """'1,2,3,6' -> (1, 2, 3, 6); raises ValueError naming the bad entry or the exceeded limit."""
    entries = text.split(",", MAX_ORDERS)
    if len(entries) > MAX_ORDERS:
        raise ValueError(f"parameter orders lists more than {MAX_ORDERS} orders")
    orders = []
    for entry in entries:
        digits = entry.strip()
        if not (digits.isascii() and digits.isdigit() and len(digits) <= 3 and 1 <= int(digits) <= MAX_ORDER):
            raise ValueError(f"parameter orders: {digits[:20]!r} is not an integer from 1 to {MAX_ORDER}")
        orders.append(int(digits))
    return tuple(orders)


def searched_modes(driveline: Driveline, orders: tuple[int, ...], omega_max: float) -> float:
    """Bare-shaft bending modes below the frequencies the order-resonance searches scan (order k
    up to ``2 k omega_max``), times the stations each determinant evaluation passes: the cost
    of :func:`analyse` in units of about one root bracket. The shaft has a mode every pi of
    ``kappa sqrt(w)``, ``kappa = sum L (m'/EI)^(1/4)``."""
    kappa = math.fsum(s.length * (s.mass_per_length / s.bending_stiffness) ** 0.25 for s in driveline.segments)
    scanned = math.fsum(math.sqrt(2.0 * k * omega_max) for k in {1, *orders})
    return kappa * scanned / math.pi * (len(driveline.segments) + 1)


def implausibility(driveline: Driveline, analysis: Analysis) -> str | None:
    """Why ``analysis`` cannot be right, or None: its first two whirl frequencies at standstill
    must each match a natural frequency of the independent finite-element model (:mod:`.fem`,
    FE_ELEMENTS cubic elements per segment, within PLAUSIBLE_DEVIATION; a bearing with
    kxx != kyy is checked in both planes). Catches roots that rounding invents when stiffness
    or mass terms differ by more than double precision resolves."""
    planes = {tuple(b.kxx for b in driveline.bearings), tuple(b.k_yy for b in driveline.bearings)}
    natural = []
    for stiffnesses in planes:
        bearings = [Bearing(b.node, k) for b, k in zip(driveline.bearings, stiffnesses)]
        plane = replace(driveline, bearings=bearings)
        stiffness, mass, _, _ = fem.assemble(plane, FE_ELEMENTS)
        natural.extend(np.sqrt(np.abs(eigh(stiffness, mass, eigvals_only=True))))
    natural = np.array(natural)
    for whirl in analysis.whirl(0.0)[:WHIRL_MODES]:
        if whirl >= SEARCH_LIMIT:  # beyond the search (a short, stiff shaft): nothing to check
            continue
        nearest = natural[np.argmin(np.abs(natural - whirl))]
        if not abs(nearest - whirl) <= PLAUSIBLE_DEVIATION * whirl:
            return (f"the whirl frequency {whirl:.6g} rad/s at standstill has no counterpart in the "
                    f"finite-element check (nearest {nearest:.6g} rad/s): the parameters are beyond "
                    "what double precision resolves")
    return None


def build_driveline(layout: str, shaft: dict[str, float]) -> Driveline:
    """The one-piece tube of ``shaft``, or the described layout (file or shipped name)."""
    if not layout:
        return one_piece_shaft(**shaft)
    return load_driveline(Path(layout) if layout.lower().endswith(".toml") else example_path(layout))


def analyse(driveline: Driveline, orders: tuple[int, ...], omega_max: float) -> Analysis:
    """Critical speeds, Campbell table and order resonances; what lies beyond the search limit
    (a short, stiff shaft) reads as the limit, and the critical speeds found are counted."""
    found = driveline.critical_speeds(3)
    critical = tuple(float(w) for w in found) + (SEARCH_LIMIT,) * (3 - found.size)
    spins = np.linspace(0.0, omega_max, CAMPBELL_POINTS)
    campbell = driveline.campbell(spins, WHIRL_MODES)
    table = np.hstack([campbell.forward, campbell.backward])
    table = np.where(np.isfinite(table), table, SEARCH_LIMIT)  # a mode beyond the limit reads as the limit
    resonances = driveline.order_resonances(orders, ("forward", "backward"), None, 2.0 * omega_max)
    if not resonances:
        resonances = driveline.order_resonances(orders, ("forward",), 1)
    if not resonances:
        raise ValueError(f"no order resonance of the orders {orders} below the search limit {SEARCH_LIMIT:g} rad/s")
    return Analysis(critical, found.size, CubicSpline(spins, table), tuple(resonances))


class CriticalSpeedsModel(SteppedModel):
    """The ``CriticalSpeeds`` co-simulation model."""

    spec = SPEC
    derived_state = ("_analysis", "_analysed_for", "_resonance_speeds", "_unbalance")

    def reset_internal_state(self) -> None:
        self._analysis: Analysis | None = None
        self._analysed_for: tuple | None = None
        self._unbalance: UnbalanceOutputs | None = None

    def _structure(self) -> tuple:
        return (self.layout, self.orders, self.omega_max,
                *(getattr(self, n) for n in SHAFT_PARAMETERS + UNBALANCE_PARAMETERS))

    def extra_parameter_errors(self) -> list[str]:
        """Build and analyse the driveline (only when the structure changed): its errors are the checks."""
        key = self._structure()
        if key == self._analysed_for:
            return []
        try:
            orders = parse_orders(self.orders)
            driveline = build_driveline(self.layout, {n: getattr(self, n) for n in SHAFT_PARAMETERS})
            work = searched_modes(driveline, orders, self.omega_max)
            if not work <= MAX_SEARCHED_MODES:
                raise ValueError(f"the analysis would scan {work:.3g} shaft modes, more than the "
                                 f"{MAX_SEARCHED_MODES:.0f} accepted (shorter or stiffer shaft, fewer or "
                                 "lower orders, or a smaller omega_max)")
            analysis = analyse(driveline, orders, self.omega_max)
            reason = implausibility(driveline, analysis)
            if reason is not None:
                raise ValueError(reason)
            unbalances = driveline.unbalances if self.layout else (
                Unbalance(self.unbalance_position * driveline.length, self.unbalance),)
            self._unbalance = UnbalanceOutputs.build(driveline, unbalances, self.response_position, self.omega_max)
            self._analysis = analysis
            self._resonance_speeds = analysis.resonance_speeds
        except (ValueError, ArithmeticError) as error:  # e.g. a diameter of 1e300 overflows
            return [f"driveline: {error} (a structural parameter is too large or small to analyse)"
                    if isinstance(error, ArithmeticError) else f"driveline: {error}"]
        self._analysed_for = key
        return []

    def start(self, start_time: float) -> None:
        self.evaluate()

    def advance(self, current_time: float, step_size: float) -> None:
        self.evaluate()

    def evaluate(self) -> None:
        analysis = self._analysis
        speed = abs(self.omega)
        self.omega_crit_1, self.omega_crit_2, self.omega_crit_3 = analysis.critical_speeds
        self.critical_speed_count = analysis.critical_speed_count
        whirl = analysis.whirl(speed)
        self.whirl_forward_1, self.whirl_forward_2 = float(whirl[0]), float(whirl[1])
        self.whirl_backward_1, self.whirl_backward_2 = float(whirl[2]), float(whirl[3])
        self.speed_ratio = speed / self.omega_crit_1
        margins = (speed - self._resonance_speeds) / self._resonance_speeds
        closest = int(np.argmin(np.abs(margins)))
        resonance = analysis.resonances[closest]
        self.resonance_order = resonance.order
        self.resonance_whirl = 1 if resonance.whirl == "forward" else -1
        self.resonance_speed = resonance.spin
        self.resonance_margin = float(margins[closest])
        self.resonance_count = int(np.count_nonzero(np.abs(margins) < self.band))
        self.resonance_warning = self.resonance_count > 0
        self.unbalance_response, self.bearing_force_max, self.damping_ratio = self._unbalance.evaluate(speed)
