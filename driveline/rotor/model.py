"""Time stepping of the critical-speed monitor: analysis when the structure changes, lookups per step.

The driveline is analysed once per distinct set of structural parameters (at
initialisation, and again when a tunable parameter changes): critical speeds, order
resonances up to twice ``omega_max``, and a Campbell table of the first two forward
and backward whirl frequencies, interpolated per step with cubic splines.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from ..model import SteppedModel
from .driveline import SEARCH_LIMIT, Driveline, OrderResonance
from .loader import example_path, load_driveline, one_piece_shaft
from .spec import SPEC

CAMPBELL_POINTS = 41  # spline knots over [0, omega_max]; measured interpolation error <= 1e-12 relative
WHIRL_MODES = 2
SHAFT_PARAMETERS = ("L_shaft", "D_outer", "D_inner", "E", "density", "m_joint", "Jp_joint", "Jd_joint", "k_bearing")


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
    """'1,2,3,6' -> (1, 2, 3, 6); raises ValueError naming the bad entry."""
    orders = []
    for entry in text.split(","):
        if not entry.strip().isdigit() or int(entry) < 1:
            raise ValueError(f"parameter orders = {text!r}: {entry.strip()!r} is not a positive integer")
        orders.append(int(entry))
    return tuple(orders)


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
    derived_state = ("_analysis", "_analysed_for")

    def reset_internal_state(self) -> None:
        self._analysis: Analysis | None = None
        self._analysed_for: tuple | None = None

    def _structure(self) -> tuple:
        return (self.layout, self.orders, self.omega_max, *(getattr(self, n) for n in SHAFT_PARAMETERS))

    def extra_parameter_errors(self) -> list[str]:
        """Build and analyse the driveline (only when the structure changed): its errors are the checks."""
        key = self._structure()
        if key == self._analysed_for:
            return []
        try:
            orders = parse_orders(self.orders)
            driveline = build_driveline(self.layout, {n: getattr(self, n) for n in SHAFT_PARAMETERS})
            self._analysis = analyse(driveline, orders, self.omega_max)
            self._resonance_speeds = self._analysis.resonance_speeds
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
