"""Work model of one CriticalSpeeds analysis: a cost estimate per stage from the driveline, the orders
and ``omega_max``, evaluated before any stage starts (both cores; the C port reads these constants
from the generated header).

Every root search of the transfer-matrix method (seed Sec. 8) scans lines of the scaled determinant
(seed Eq. 31) on grids of ``POINTS_PER_ROOT (1 + freedoms)`` points per pi of the bare-shaft phase
``kappa sqrt(w)`` (``Driveline._grid``), each evaluation passing every station. A stage's search is
bounded by the search limit, so its evaluations are at most

    lines * (POINTS_PER_ROOT (1 + freedoms) * senses * kappa sqrt(ratio * limit) / pi + 8)

doubled where the search range widens fourfold until it finds its roots. The finite-element stages
cost as their matrices: the dense eigenproblem of the plausibility check as its order cubed, the
damped modes and the unbalance response as their banded orders. Each stage's units times its rate
(native seconds per unit on the project's two-core machine) is its estimate; the sum is refused
above ``MAX_ANALYSIS_SECONDS``. The estimates are upper bounds: a search that finds its roots early
stops early.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from .budget import seconds_units
from .campbell import MAX_KNOTS
from .driveline import POINTS_PER_ROOT, SEARCH_LIMIT, Driveline
from .fem import elements_by_length
from .unbalance_outputs import DAMPING_POINTS, FE_ELEMENTS, TABLE_ELEMENTS

#: CPU seconds the estimate of one analysis may reach. The native analysis takes at most about this
#: (three times as long in wall time on the two busy cores of the project's machine, still within
#: its budget of 5 s), the Python one about as long (its budget: 30 s).
MAX_ANALYSIS_SECONDS = 1.5
#: Native CPU seconds per unit of each stage, fitted to the worst layouts (fmu_harness/checks/analysis_work.py)
#: on the project's machine; the search rate to a layout whose Campbell table takes the full grid at
#: every speed (30 segments with 62 masses and 62 bearings: 4.5 s estimated, 4.5 s measured).
RATE_SEARCH = 1.35e-9  # per determinant evaluation and station
RATE_DENSE = 1.0e-9  # per cube of the order of the dense eigenproblem
RATE_BANDED = 1.0e-4  # per unknown of a banded finite-element model, per solve

STAGES = ("critical speeds", "order resonances", "Campbell table", "FE check", "damped modes", "unbalance response")
#: What the refusal suggests, after the estimates.
ADVICE = "(fewer stations or segments, fewer or lower orders)"

#: The texts the C port of :func:`estimate` reads (``CriticalSpeedsModel.native_constants``); its
#: numbers come from the shared constants header (``fmu_harness.packaging.native_constants``).
NATIVE_CONSTANTS = {"WORK_ADVICE": ADVICE, "WORK_STAGE_COUNT": len(STAGES),
                    **{f"WORK_STAGE_{i}": name for i, name in enumerate(STAGES)}}


@dataclass(frozen=True)
class Work:
    """Estimated seconds of each stage (:data:`STAGES`), in their order."""

    seconds: tuple[float, ...]

    @property
    def total(self) -> float:
        return math.fsum(self.seconds)

    def units(self, stage: str) -> int:
        """The budget units of ``stage`` at its estimate (:func:`.budget.seconds_units`): a finite-element
        stage's charge."""
        return seconds_units(self.seconds[STAGES.index(stage)])

    def refusal(self) -> str | None:
        """Why the analysis is refused, or None: its estimate with each stage's, above the limit."""
        if self.total <= MAX_ANALYSIS_SECONDS:
            return None
        stages = ", ".join(f"{name} {seconds:.3g} s" for name, seconds in zip(STAGES, self.seconds))
        return (f"the analysis would take about {self.total:.3g} s ({stages}), more than the "
                f"{MAX_ANALYSIS_SECONDS:g} s accepted {ADVICE}")


def _grid(points_per_pi: float, phase: float) -> float:
    """Points of one search line up to ``phase`` (the bare-shaft phase at its end)."""
    return points_per_pi * phase / math.pi + 8.0


def estimate(driveline: Driveline, orders: Sequence[int], omega_max: float, campbell_points: int,
             check_elements: int) -> Work:
    """The estimate of every stage of the analysis of ``driveline`` for ``orders`` up to ``omega_max``, with
    the Campbell table's ``campbell_points`` speeds (each on the full grid when the count check fails, and
    up to MAX_KNOTS more where the table is refined) and ``check_elements`` per segment in the FE check."""
    stations = driveline._chain.stations
    senses = 1 if driveline.is_isotropic else 2
    per_pi = POINTS_PER_ROOT * (1 + driveline.freedoms) * senses
    kappa = driveline._kappa
    to_limit = _grid(per_pi, kappa * math.sqrt(SEARCH_LIMIT))
    critical = 2.0 * to_limit
    resonances = math.fsum(2.0 * _grid(per_pi, kappa * math.sqrt(2.0 * k * omega_max))
                           + 2.0 * _grid(per_pi, kappa * math.sqrt(k * SEARCH_LIMIT)) for k in {1, *orders})
    campbell = 2.0 * 2.0 * (campbell_points + MAX_KNOTS) * to_limit
    planes = 1 if all(b.kxx == b.k_yy for b in driveline.bearings) else 2
    check = planes * (2.0 * (check_elements * len(driveline.segments) + 1 + len(driveline.joints))) ** 3
    damped = DAMPING_POINTS * 4.0 * (sum(elements_by_length(driveline, TABLE_ELEMENTS)) + 1)
    response = 4.0 * (sum(elements_by_length(driveline, FE_ELEMENTS)) + 1)
    search = RATE_SEARCH * stations
    return Work((search * critical, search * resonances, search * campbell, RATE_DENSE * check,
                 RATE_BANDED * damped, RATE_BANDED * response))
