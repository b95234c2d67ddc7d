"""Time stepping of the critical-speed monitor: analysis when the structure changes, lookups per step.

The driveline is analysed at initialisation and again when a tunable parameter changes,
and only in the parts the change affects: the structure (critical speeds and the
finite-element check) per set of structural parameters, the Campbell table of the first
two forward and backward whirl frequencies (each branch a cubic spline, sorted per step)
per ``omega_in_max`` as well, the order resonances up to twice ``omega_in_max`` per
``orders`` as well, and the unbalance outputs (:mod:`.unbalance_outputs`) per structure,
bearing damping, unbalance parameters and ``omega_in_max``. ``band`` only enters the per-step lookup.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from scipy.linalg import eigh

from ..model import SteppedModel
from . import fem
from .campbell import WhirlTable, whirl_branches
from .driveline import SEARCH_LIMIT, Driveline, OrderResonance
from .elements import Bearing, Unbalance
from .loader import example_path, load_driveline, one_piece_shaft
from .mechanism import MECHANISM_HINGE, MECHANISM_RIGID, mechanism_error
from .spec import SPEC
from .unbalance_outputs import UnbalanceOutputs
from .budget import Budget, spending
from .budget import refusal as budget_refusal
from .work import NATIVE_CONSTANTS, Work, estimate

#: Orders watched at most, and the highest order (joints excite low orders: 1, 2, 3, 6).
MAX_ORDERS = 16
MAX_ORDER = 100
#: Work limit of one analysis in units of :func:`searched_modes`: the default shaft needs 17 (0.04 s CPU),
#: a 10 m solid tube 146 (0.1 s); even 573 took 0.5 s, so 250 keeps one analysis well below a second.
MAX_SEARCHED_MODES = 250.0
#: Finite-element plausibility check of every analysis (:func:`implausibility`).
FE_ELEMENTS = 4
PLAUSIBLE_DEVIATION = 0.02
CAMPBELL_POINTS = 41  # spline knots over [0, omega_in_max], more where a branch bends (campbell.SPLINE_RTOL)
WHIRL_MODES = 2
SHAFT_PARAMETERS = ("L_shaft", "D_outer", "D_inner", "E", "density", "m_joint", "Jp_joint", "Jd_joint", "k_bearing",
                    "shear")
#: Parameters of the damped model only (the critical speeds and whirl frequencies are the undamped ones).
DAMPING_PARAMETERS = ("c_bearing",)
UNBALANCE_PARAMETERS = ("unbalance", "unbalance_position", "response_position")
#: The parts of the analysis and the parameters each is built for besides ``layout`` (the resonances
#: also for ``orders``): a changed parameter redoes the parts that list it, and no other.
ANALYSIS_PARTS = {
    "driveline": SHAFT_PARAMETERS + DAMPING_PARAMETERS,
    "structure": SHAFT_PARAMETERS,
    "whirl": SHAFT_PARAMETERS + ("omega_in_max",),
    "resonances": SHAFT_PARAMETERS + ("omega_in_max",),
    "unbalance": SHAFT_PARAMETERS + DAMPING_PARAMETERS + UNBALANCE_PARAMETERS + ("omega_in_max",),
}


@dataclass(frozen=True)
class Structure:
    """What depends on the structural parameters alone (not on ``orders``, ``band``, ``omega_max``)."""

    driveline: Driveline
    critical_speeds: tuple[float, float, float]  # missing ones (beyond the search limit) = the limit
    critical_speed_count: int
    natural: np.ndarray  # natural frequencies of the finite-element check [rad/s]


@dataclass(frozen=True)
class Analysis:
    """Everything a step needs, for one set of structural parameters, orders and ``omega_max``."""

    critical_speeds: tuple[float, float, float]
    critical_speed_count: int
    whirl: WhirlTable  # |omega| -> (forward_1, forward_2, backward_1, backward_2)
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


def natural_frequencies(driveline: Driveline) -> np.ndarray:
    """Natural frequencies at standstill of the independent finite-element model (:mod:`.fem`,
    FE_ELEMENTS cubic elements per segment; a bearing with kxx != kyy in both planes)."""
    planes = {tuple(b.kxx for b in driveline.bearings), tuple(b.k_yy for b in driveline.bearings)}
    natural = []
    for stiffnesses in planes:
        bearings = [Bearing(b.node, k) for b, k in zip(driveline.bearings, stiffnesses)]
        plane = replace(driveline, bearings=bearings)
        stiffness, mass, _, _ = fem.assemble(plane, FE_ELEMENTS)
        natural.extend(np.sqrt(np.abs(eigh(stiffness, mass, eigvals_only=True))))
    return np.array(natural)


def implausibility(natural: np.ndarray, whirl: WhirlTable) -> str | None:
    """Why the whirl table cannot be right, or None: its first two whirl frequencies at standstill
    must each match one of the ``natural`` frequencies of the finite-element check within
    PLAUSIBLE_DEVIATION. Catches roots that rounding invents when stiffness or mass terms
    differ by more than double precision resolves."""
    for frequency in whirl(0.0)[:WHIRL_MODES]:
        if frequency >= SEARCH_LIMIT:  # beyond the search (a short, stiff shaft): nothing to check
            continue
        nearest = natural[np.argmin(np.abs(natural - frequency))]
        if not abs(nearest - frequency) <= PLAUSIBLE_DEVIATION * frequency:
            return (f"the whirl frequency {frequency:.6g} rad/s at standstill has no counterpart in the "
                    f"finite-element check (nearest {nearest:.6g} rad/s): the parameters are beyond "
                    "what double precision resolves")
    return None


SHEAR_CONFLICT = ("shear = False conflicts with the layout, whose segments keep shear deformation: a layout's "
                  "segments decide it themselves (shear = false in each [[segments]] table), the parameter "
                  "shear applies to the one-piece tube")


def load_layout(layout: str) -> Driveline:
    """The described layout: a file (a path ending in '.toml', any case) or a shipped name."""
    return load_driveline(Path(layout) if layout.lower().endswith(".toml") else example_path(layout))


def build_driveline(layout: str, shaft: dict[str, float]) -> Driveline:
    """The one-piece tube of ``shaft``, or the described layout (file or shipped name). Refused
    (ValueError) when the supports leave it a mechanism (:mod:`.mechanism`) or when ``shaft``'s
    ``shear`` is false while a layout segment keeps shear deformation."""
    if not layout:
        driveline = one_piece_shaft(**shaft)
    else:
        driveline = load_layout(layout)
        if not shaft.get("shear", True) and any(segment.shear for segment in driveline.segments):
            raise ValueError(SHEAR_CONFLICT)
    reason = mechanism_error(driveline)
    if reason is not None:
        raise ValueError(reason)
    return driveline


def finite_element_work(driveline: Driveline) -> Work:
    """The estimate whose finite-element stages (check, damped modes, response) those stages pay: theirs
    depend on the driveline alone."""
    return estimate(driveline, (1,), 1.0, CAMPBELL_POINTS, FE_ELEMENTS)


def analyse_structure(driveline: Driveline, budget: Budget | None = None, work: Work | None = None) -> Structure:
    """Critical speeds (what lies beyond the search limit, a short, stiff shaft, reads as the
    limit; the critical speeds found are counted) and the finite-element check's frequencies,
    paid from ``budget`` (a whole one if None), the check at its estimate (``work``)."""
    budget = budget or Budget()
    with spending(budget, "critical speeds"):
        found = driveline.critical_speeds(3)
    critical = tuple(float(w) for w in found) + (SEARCH_LIMIT,) * (3 - found.size)
    with spending(budget, "FE check"):
        budget.charge((work or finite_element_work(driveline)).units("FE check"))
        natural = natural_frequencies(driveline)
    return Structure(driveline, critical, found.size, natural)


def whirl_table(structure: Structure, omega_max: float, budget: Budget | None = None) -> WhirlTable:
    """The Campbell table of the first two forward and backward whirl frequencies over
    ``[0, omega_max]`` (``CAMPBELL_POINTS`` speeds, more where a branch bends), paid from ``budget`` (a
    whole one if None);
    ValueError when the finite-element check disagrees (:func:`implausibility`)."""
    spins = np.linspace(0.0, omega_max, CAMPBELL_POINTS)
    with spending(budget or Budget(), "Campbell table"):
        branches = whirl_branches(structure.driveline, spins, WHIRL_MODES)
    table = WhirlTable(branches, WHIRL_MODES, SEARCH_LIMIT)
    reason = implausibility(structure.natural, table)
    if reason is not None:
        raise ValueError(reason)
    return table


def resonances(driveline: Driveline, orders: tuple[int, ...], omega_max: float,
               budget: Budget | None = None) -> tuple[OrderResonance, ...]:
    """Every order resonance of ``orders`` (forward and backward whirl) up to ``2 omega_max``, or the
    first forward one of each order when none lies there, paid from ``budget`` (a whole one if None)."""
    with spending(budget or Budget(), "order resonances"):
        found = driveline.order_resonances(orders, ("forward", "backward"), None, 2.0 * omega_max)
        if not found:
            found = driveline.order_resonances(orders, ("forward",), 1)
    if not found:
        raise ValueError(f"no order resonance of the orders {orders} below the search limit {SEARCH_LIMIT:g} rad/s")
    return tuple(found)


def unbalance_outputs(driveline: Driveline, unbalances: tuple[Unbalance, ...], response_position: float,
                      omega_max: float, budget: Budget, work: Work) -> UnbalanceOutputs:
    """:meth:`UnbalanceOutputs.build`, its damped modes and response paid from ``budget`` at their
    estimates ``work``."""
    with spending(budget, "damped modes"):
        budget.charge(work.units("damped modes"))
    with spending(budget, "unbalance response"):
        budget.charge(work.units("unbalance response"))
    return UnbalanceOutputs.build(driveline, unbalances, response_position, omega_max)


def analyse(driveline: Driveline, orders: tuple[int, ...], omega_max: float) -> Analysis:
    """The whole analysis of one driveline within one budget: :func:`analyse_structure`, :func:`whirl_table`,
    :func:`resonances`."""
    budget, work = Budget(), estimate(driveline, orders, omega_max, CAMPBELL_POINTS, FE_ELEMENTS)
    structure = analyse_structure(driveline, budget, work)
    return Analysis(structure.critical_speeds, structure.critical_speed_count,
                    whirl_table(structure, omega_max, budget), resonances(driveline, orders, omega_max, budget))


class CriticalSpeedsModel(SteppedModel):
    """The ``CriticalSpeeds`` co-simulation model."""

    spec = SPEC
    # the first forward whirl moves with the table's range (omega_in_max) by 1e-11 rad/s at 800 rad/s
    dependency_points = ({"omega_in": 800.0, "omega_in_max": 3000.0, "orders": "3", "band": 0.3},
                         {"layout": "two_piece_propshaft"})
    derived_state = ("_analysis", "_analysed_for", "_resonance_speeds", "_parts", "_unbalance")
    resource_files = tuple(Path(__file__).parent / "data" / f"{name}.toml"
                           for name in ("two_piece_propshaft", "two_piece_propshaft_hinged"))
    derived_parts = ANALYSIS_PARTS
    native_constants = {"MECHANISM_HINGE": MECHANISM_HINGE.format(index="%d", node="%d", least="%s"),
                        "MECHANISM_RIGID": MECHANISM_RIGID, "SHEAR_CONFLICT": SHEAR_CONFLICT,
                        "BUDGET_REFUSAL": budget_refusal("%s"), **NATIVE_CONSTANTS}

    def reset_internal_state(self) -> None:
        self._analysis: Analysis | None = None
        self._analysed_for: tuple | None = None
        self._parts: dict[str, tuple[tuple, object]] = {}
        self._unbalance: UnbalanceOutputs | None = None

    def _key(self, part: str, *more: object) -> tuple:
        """What the analysis part ``part`` is built for (:data:`ANALYSIS_PARTS`), and ``more``."""
        return (self.layout, *(getattr(self, n) for n in ANALYSIS_PARTS[part]), *more)

    def _part(self, name: str, key: tuple, compute: Callable[[], Any]) -> Any:
        """The part ``name`` of the analysis for ``key``: kept from the last analysis if its key is unchanged."""
        kept = self._parts.get(name)
        if kept is None or kept[0] != key:
            self._parts[name] = (key, compute())
        return self._parts[name][1]

    def extra_parameter_errors(self) -> list[str]:
        """Analyse what a changed parameter affects: the structure (critical speeds, finite-element
        check) only when a structural parameter changed, the Campbell table when it or ``omega_in_max``
        did, the order resonances when either or ``orders`` did, the unbalance outputs when the
        structure, the damping, the unbalance parameters or ``omega_in_max`` did. Its errors are the checks."""
        key = self._key("unbalance", self.orders)  # every parameter of the analysis
        if key == self._analysed_for:
            return []
        try:
            orders = parse_orders(self.orders)
            driveline = self._part("driveline", self._key("driveline"), lambda: build_driveline(
                self.layout, {n: getattr(self, n) for n in SHAFT_PARAMETERS + DAMPING_PARAMETERS}))
            work = searched_modes(driveline, orders, self.omega_in_max)
            if not work <= MAX_SEARCHED_MODES:
                raise ValueError(f"the analysis would scan {work:.3g} shaft modes, more than the "
                                 f"{MAX_SEARCHED_MODES:.0f} accepted (shorter or stiffer shaft, fewer or "
                                 "lower orders, or a smaller omega_in_max)")
            work = estimate(driveline, orders, self.omega_in_max, CAMPBELL_POINTS, FE_ELEMENTS)
            refusal = work.refusal()
            if refusal is not None:
                raise ValueError(refusal)
            budget = Budget()  # the parts analysed anew pay from it, the kept ones not again
            structure = self._part("structure", self._key("structure"), lambda: analyse_structure(driveline, budget,
                                                                                                   work))
            whirl = self._part("whirl", self._key("whirl"), lambda: whirl_table(structure, self.omega_in_max, budget))
            found = self._part("resonances", self._key("resonances", orders),
                               lambda: resonances(driveline, orders, self.omega_in_max, budget))
            analysis = Analysis(structure.critical_speeds, structure.critical_speed_count, whirl, found)
            unbalances = driveline.unbalances if self.layout else (
                Unbalance(self.unbalance_position * driveline.length, self.unbalance),)
            self._unbalance = self._part("unbalance", self._key("unbalance"), lambda: unbalance_outputs(
                driveline, unbalances, self.response_position, self.omega_in_max, budget, work))
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
        speed = abs(self.omega_in)
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
