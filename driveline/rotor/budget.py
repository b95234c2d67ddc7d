"""The work budget of one CriticalSpeeds analysis: a bound that holds by construction (both cores; the C
port is ``budget.c``).

Every stage draws from one budget before it works, in units of bounded cost: one step of the
propagation of the scaled determinant (seed Eqs. 28-31) of an isotropic chain, a node, a point
element or a piece of a segment (``transfer.MAX_PIECE_PHASE``: at most a phase of 2 per piece, so a
piece costs the same at any frequency); an anisotropic chain's step (8x4 basis instead of 4x2)
costs ``ANISOTROPIC_STEP``. A determinant evaluation or mode shape pays its steps, each point its
own pieces. The finite-element stages are paid whole before they start, at their estimate
(:mod:`.work`: a dense eigen-solve as its order cubed, the damped modes and the response as their
banded orders) converted at ``SECONDS_PER_UNIT``. A charge the budget cannot pay raises
:class:`BudgetSpent` naming the stage, before the work is done; the C port charges the same units,
one evaluation at a time, so the same input stops in the same stage.

The budget is active in a context (:func:`spending`), so the searches deep inside (:mod:`.roots`,
:mod:`.campbell`) charge it without passing it along; outside one nothing is charged.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from .unit_rates import NATIVE_SECONDS_PER_UNIT, PYTHON_SECONDS_PER_UNIT

#: Units of one step of an anisotropic chain (measured 6 to 8 times an isotropic step, both cores).
ANISOTROPIC_STEP = 8
#: Native CPU seconds the finite-element stages' estimates (:mod:`.work`) convert to one unit at: the
#: rate their fits assumed (2026-11-27), not a measured one (:mod:`.unit_rates` holds those).
SECONDS_PER_UNIT = 75e-9
#: The budget in units.
UNITS = 33_333_333
#: Native and Python CPU seconds of the whole budget at the measured rates: within the limits of 5 s
#: and 30 s (tests/core/test_budget_rates.py).
SECONDS = UNITS * NATIVE_SECONDS_PER_UNIT
PYTHON_SECONDS = UNITS * PYTHON_SECONDS_PER_UNIT


class BudgetSpent(ValueError):
    """The analysis would exceed its work budget: refused, naming the stage."""


class Budget:
    """Units left to one analysis, and the stage now drawing from them."""

    def __init__(self, units: int = UNITS) -> None:
        self.left = units
        self.stage = ""

    def charge(self, units: int) -> None:
        """Pay ``units`` of the current stage; :class:`BudgetSpent` (nothing paid) when they exceed what is left."""
        if units > self.left:
            self.left = -1
            raise BudgetSpent(refusal(self.stage))
        self.left -= units


def refusal(stage: str, seconds: float = SECONDS) -> str:
    """The refusal of an analysis whose budget ``stage`` exhausted, the budget taking about ``seconds``."""
    return (f"the analysis would exceed its work budget (about {seconds:.1f} s) in the {stage} "
            "(fewer stations or segments, fewer or lower orders, or a smaller omega_in_max)")


_ACTIVE: ContextVar[Budget | None] = ContextVar("budget", default=None)


@contextmanager
def spending(budget: Budget, stage: str) -> Iterator[Budget]:
    """``budget`` pays the work of ``stage`` inside the ``with`` block."""
    budget.stage = stage
    token = _ACTIVE.set(budget)
    try:
        yield budget
    finally:
        _ACTIVE.reset(token)


def charge(units: int) -> None:
    """Pay ``units`` from the active budget (none active: nothing to pay)."""
    budget = _ACTIVE.get()
    if budget is not None:
        budget.charge(units)


def seconds_units(seconds: float) -> int:
    """Units of a stage estimated at ``seconds`` (rounded up)."""
    return math.ceil(seconds / SECONDS_PER_UNIT)
