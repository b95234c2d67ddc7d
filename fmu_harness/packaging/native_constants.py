"""The constants the Python core and its C port share, declared once: the names below are the Python
modules' own constants, and the native build writes their values into the generated header
``driveline_constants.h`` that every native FMU carries (next to ``model_variables.h``), as
``<PACKAGE>_<MODULE>_<NAME>`` (``driveline.rotor.roots.SUBGRID`` is ``ROTOR_ROOTS_SUBGRID``). The header
also holds the kinds of failure (:data:`ERROR_KINDS`) as the enum ``ErrorKind``: a C function that
fails returns its kind with the message, so no C code tells kinds apart by their text.

A C file defines none of these numbers itself (tests/native/test_native_constants.py checks every
``#define`` and ``static const`` of ``fmu_src/native``). Numbers only the C port has (the Arnoldi
iteration's cap and tolerance, which scipy's ARPACK holds for Python; buffer sizes) stay in C.
"""

from __future__ import annotations

import importlib
import math
import re

#: Python module -> the names of its constants that the C port uses.
SHARED = {
    "driveline.rotor.driveline": ("SEARCH_LIMIT", "EXCITED_SHARE", "POINTS_PER_ROOT", "GRID_OFFSET", "LEAD_POINTS",
                                  "DIRECTION_POINTS", "LEAD_RATIO"),
    "driveline.layout_files": ("MAX_FILE_BYTES", "MAX_NESTING"),
    "driveline.rotor.loader": ("MAX_SEGMENTS", "MAX_POINT_ELEMENTS", "NODE_SNAP"),
    "driveline.mounts.layout": ("MAX_MOUNTS", "ROTATION_TOLERANCE", "STOP_BLEND"),
    "driveline.mounts.rigid_body": ("MIN_FREQUENCY_RATIO", "FREQUENCY_TOLERANCE", "MAX_FREQUENCY_ITERATIONS"),
    "driveline.mounts.rubber": ("BAND", "RELAXATION_FREQUENCIES", "BRANCHES", "FIT_POINTS", "RATIO_WEIGHT",
                                "MAX_LOSS_ERROR", "MAX_RATIO_ERROR"),
    "driveline.mounts.forces": ("MAX_NEWTON", "NEWTON_STEP", "NEWTON_CONTRACTION"),
    "driveline.mounts.joints": ("MIN_DIRECTION",),
    "driveline.mounts.exact_step": ("THETA_13", "MAX_SQUARINGS"),
    "driveline.rotor.elements": ("_SERIES_LIMIT",),
    "driveline.rotor.transfer": ("MAX_PIECE_PHASE", "LOG_SCALE_CLIP"),
    "driveline.rotor.budget": ("ANISOTROPIC_STEP", "UNITS", "SECONDS_PER_UNIT"),
    "driveline.rotor.fem": ("SHARE_SLACK",),
    "driveline.rotor.mechanism": ("RESOLVED_HINGE_SHARE",),
    "driveline.rotor.roots": ("SUBGRID", "MAX_DEPTH", "DIP_RATIO", "MAX_ITERATIONS", "XTOL", "RTOL", "ROUNDING",
                              "MAX_DIPS"),
    "driveline.rotor.campbell": ("SLOPE_STEP", "SPLINE_RTOL", "REFINEMENTS", "MAX_KNOTS", "NOISE"),
    "driveline.rotor.damped": ("EXTRA_EIGENVALUES", "DENSE_SIZE", "SHIFT", "WHIRL_SHARE"),
    "driveline.rotor.unbalance_outputs": ("FE_ELEMENTS", "TABLE_ELEMENTS", "DAMPING_POINTS", "DAMPED_MODES"),
    "driveline.rotor.work": ("MAX_ANALYSIS_SECONDS", "RATE_SEARCH", "RATE_DENSE", "RATE_BANDED"),
    "driveline.rotor.model": ("MAX_ORDERS", "MAX_ORDER", "MAX_SEARCHED_MODES", "FE_ELEMENTS", "PLAUSIBLE_DEVIATION",
                              "CAMPBELL_POINTS", "WHIRL_MODES"),
    "driveline.tripod.spec": ("EXACT", "PLAIN_TRIPOD", "SINGLE_ROLLER"),
    "driveline.tripod.geometry": ("THIRD_TURN",),
    "driveline.tripod.closed_form": ("PAPER_PHASE",),
    "driveline.tripod.plane_solver": ("LAST_UPDATE", "MAX_ITERATIONS"),
    "driveline.tripod.reactions": ("FRICTION_TOLERANCE", "MAX_FRICTION_ITERATIONS"),
    "driveline.tripod.rollers": ("CONTACT_ITERATIONS", "CONTACT_TOLERANCE", "FRICTION_SHARE_CAP", "BRACKET_MARGIN"),
    "driveline.vehicle.dynamics": ("GRAVITY", "RATE_STEP", "MAX_SUBSTEPS", "STATE_SIZE", "JACOBI_OMEGA_STEP",
                                   "JACOBI_DAMPING_STEP", "DIVERGENCE_OMEGA_STEP"),
}

#: The kinds of failure the C port tells apart: the exceptions the Python core raises. ``ErrorKind``
#: numbers them -1, -2, ... in this order, ``ERROR_NONE`` (0) is success; a failing C function returns
#: its kind by name, never a number (tests/native/test_native_constants.py holds the CriticalSpeeds
#: port to it), so the order is no convention the C relies on.
ERROR_KINDS = (ValueError, ZeroDivisionError, OverflowError, ArithmeticError, RuntimeError)

HEADER = "driveline_constants.h"


def c_name(module: str, name: str) -> str:
    """``driveline.rotor.roots``, ``SUBGRID`` -> ``ROTOR_ROOTS_SUBGRID``."""
    package, leaf = module.split(".")[-2:]
    return f"{package}_{leaf}_{name.lstrip('_')}".upper()


Constant = int | float | tuple[float, ...]


def _finite_number(value: object) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)


def shared_constants() -> dict[str, tuple[str, Constant]]:
    """Every shared constant: C name -> (its Python name, its value: a finite int or float, or a tuple of
    them, which C reads as an array's initialiser ``{a, b}``)."""
    found = {}
    for module, names in SHARED.items():
        loaded = importlib.import_module(module)
        for name in names:
            value = getattr(loaded, name)
            if not (_finite_number(value) or (isinstance(value, tuple) and value and all(map(_finite_number, value)))):
                raise TypeError(f"{module}.{name} = {value!r}: a shared constant is a finite int or float, or a "
                                "tuple of them")
            found[c_name(module, name)] = (f"{module}.{name}", value)
    return found


def _literal(value: Constant) -> str:
    if isinstance(value, tuple):
        return "{" + ", ".join(_literal(item) for item in value) + "}"
    text = str(value) if isinstance(value, int) else repr(float(value))  # repr: the same double in C
    return f"({text})" if value < 0 else text


def error_kind_name(kind: type[Exception]) -> str:
    """``ZeroDivisionError`` -> ``ERROR_ZERO_DIVISION``."""
    return "ERROR_" + re.sub(r"(?<=[a-z])(?=[A-Z])", "_", kind.__name__.removesuffix("Error")).upper()


def _error_kinds() -> str:
    """The enum ``ErrorKind``, each kind's Python name and which kinds are ArithmeticErrors."""
    kinds = [f"{error_kind_name(kind)} = {-number}" for number, kind in enumerate(ERROR_KINDS, 1)]
    names = "".join(f"(kind) == {error_kind_name(kind)} ? \"{kind.__name__}\" : " for kind in ERROR_KINDS)
    arithmetic = " || ".join(f"(kind) == {error_kind_name(kind)}" for kind in ERROR_KINDS
                             if issubclass(kind, ArithmeticError))
    return f"""/* The kinds of failure (fmu_harness/packaging/native_constants.py ERROR_KINDS): the Python exception
 * a failure of the C port stands for; a failing function returns its kind, a negative number. */
typedef enum {{ ERROR_NONE = 0, {", ".join(kinds)} }} ErrorKind;
/* Python's name of a kind ("ValueError"); "" for ERROR_NONE */
#define ERROR_KIND_NAME(kind) ({names}"")
/* Whether a kind is one of Python's ArithmeticErrors */
#define ERROR_IS_ARITHMETIC(kind) ({arithmetic})"""


def constants_header() -> str:
    """The text of ``driveline_constants.h``."""
    lines = [f"#define {name} {_literal(value)} /* {python} */" for name, (python, value) in shared_constants().items()]
    body = "\n".join(lines) + "\n\n" + _error_kinds()
    return f"""/* The constants and kinds of failure the Python core and its C port share, generated from the Python modules by the
 * native build (fmu_harness/packaging/native_constants.py): do not edit. */
#ifndef DRIVELINE_CONSTANTS_H
#define DRIVELINE_CONSTANTS_H

{body}

#endif
"""
