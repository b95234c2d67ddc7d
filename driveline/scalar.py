"""Scalar-or-array dispatch for the closed-form physics.

The closed forms take numpy arrays (sweeps, plots) or plain floats (one FMU step). numpy's
ufuncs cost about a microsecond each on a float, the ``math`` module a tenth of that, so
the formulas pick their library with :func:`lib`.
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import Union

import numpy as np
from numpy.typing import NDArray

Real = Union[float, NDArray[np.float64]]


def lib(*values: object) -> ModuleType:
    """``math`` when every value is a Python float or int, else ``numpy``."""
    for value in values:
        if type(value) is not float and type(value) is not int:
            return np
    return math


def arcsin(value: Real) -> Real:
    """``asin`` of a float or an array (numpy spells it ``arcsin``)."""
    return math.asin(value) if type(value) is float else np.arcsin(value)
