"""Jacobians of a native FMU: exact through its directional (or adjoint) derivatives, by central
differences of the same FMU (Model Exchange) and by Richardson-extrapolated central differences of the
Python core, for the tests and the benchmark of directional derivatives.

The rows are the Real outputs, then der(<state>); the columns the Real inputs and the states
(:func:`fmu_harness.packaging.native.jacobian_layout`). Column j is perturbed by ``h * scale_j`` with
``scale_j = max(1, |x_j|)``: angles in rad and speeds of 100 rad/s alike.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np

from driveline.catalog import MODELS
from driveline.model import SteppedModel, TimeSourceModel
from fmu_harness.packaging import native

#: Relative step of the central differences through the FMU: rounding eps |f| / h near 2e-10 of the
#: outputs' scale, truncation h^2 |f'''| / 6 below it (the reducer's stresses near 160 deg vary fast with
#: the angle: 7e-9 with a step of 1e-5, 8e-11 with 1e-6, measured 2026-11-27).
FMU_STEP = 1e-6
#: Relative step of the Python core's differences, halved twice and extrapolated (error O(h^6): 4e-9
#: with 1e-2, 4e-13 with 2e-3 for the reducer's stresses; rounding about 1e-12).
CORE_STEP = 2e-3
#: Models whose outputs are smooth only on a smaller scale than CORE_STEP's: PowertrainMounts' snubbers take their
#: stop rate up over a blend of 2 mm (and the default's gaps lie 2 to 10 mm out), so a step of 2 mm straddles the
#: characteristic's pieces and the extrapolation errs by up to 0.2 of a row (measured on the rubber default);
#: 1e-5 keeps the stencil on one piece at the tests' points (errors within 6.4e-11 of a row's scale, 3.5e-11 on
#: the linear layout's; 1e-6 is too small: its rounding reaches 5.8e-10).
CORE_STEPS = {"PowertrainMounts": 1e-5}


def core_step(name: str) -> float:
    """The relative step of the Python core's differences for model ``name``."""
    return CORE_STEPS.get(name, CORE_STEP)


#: Rows whose differences carry more rounding than the tests' tolerances (1e-7 against the FMU's, 1e-10 against
#: the core's): (FMU, core) bounds. TripodCoupling's exact reactions: ``a_plunger_sum`` sums three plunger
#: accelerations built from terms of |Omega|^2 l, about 3e4 m/s^2, to about 0.04 m/s^2: the differences'
#: rounding, eps 3e4 / h over the row's scale of 0.5, is 1e-5 with the FMU's step 1e-6 (measured 1.9e-5) and
#: 3e-8 with the core's 5e-4 (measured 7.0e-8); ``Rz_out``, the axial part of three arm forces of some 1e3 N:
#: the core's rounding measured 2.6e-10; ``Rx_in``, ``Ry_in``, the input bearing's radial force, sum the three
#: groove forces that carry the plungers' inertia, m |Omega|^2 l of some 6e3 N each, to tens of N: the core's
#: extrapolated rounding, 6.6 eps 6e3 / 2e-3 over the row's scale of about 40, is 1e-10 (measured 1.1e-10 in the
#: column psi_dot, whose scale is 1 rad/s against omega_in's 209).
ROUNDING_ROWS = {"TripodCoupling": {"a_plunger_sum": (1e-4, 5e-7), "Rz_out": (1e-7, 1e-9), "Rx_in": (1e-7, 5e-10),
                                   "Ry_in": (1e-7, 5e-10)}}


def row_bounds(name: str, fmu_tolerance: float, core_tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Each row's bound against the FMU's and the core's differences: the tolerances but for ROUNDING_ROWS."""
    rows, _ = layout(name)
    special = ROUNDING_ROWS.get(name, {})
    return (np.array([special.get(row, (fmu_tolerance, core_tolerance))[0] for row in rows]),
            np.array([special.get(row, (fmu_tolerance, core_tolerance))[1] for row in rows]))


def layout(name: str) -> tuple[list[str], list[str]]:
    rows, columns = native.jacobian_layout(MODELS[name].spec)
    return rows + [state.derivative_name for state in MODELS[name].spec.states], columns


def references(name: str, fmi: str) -> tuple[list[int], list[int]]:
    """The value references of the rows and of the columns."""
    return native.jacobian_references(MODELS[name].spec, fmi)


def exact(fmu, name: str, fmi: str, adjoint: bool = False) -> np.ndarray:
    """The Jacobian from unit seeds: a column per directional derivative, or a row per adjoint one."""
    rows, columns = references(name, fmi)
    if adjoint:
        return np.array([fmu.getAdjointDerivative(rows, columns, list(np.eye(len(rows))[i]), len(columns))
                         for i in range(len(rows))]).reshape(len(rows), len(columns))
    return np.array([fmu.getDirectionalDerivative(rows, columns, list(np.eye(len(columns))[j]))
                     for j in range(len(columns))]).reshape(len(columns), len(rows)).T


def scales(values: np.ndarray) -> np.ndarray:
    return np.maximum(1.0, np.abs(values))


def fmu_differences(model, name: str, step: float = FMU_STEP) -> tuple[np.ndarray, np.ndarray]:
    """Central differences (relative step ``step``) through a Model Exchange instance
    (``support.model_exchange``) and the row values at its point; the point restored after."""
    spec = MODELS[name].spec
    outputs, columns = native.jacobian_layout(spec)
    states = [state.name for state in spec.states]

    def rows() -> np.ndarray:
        return np.concatenate([model.get(outputs), model.derivatives()])

    def put(column: str, value: float) -> None:
        if column in states:
            x = model.get_states()
            x[states.index(column)] = value
            model.set_states(x)
        else:
            model.set({column: float(value)})

    point = np.array(model.get(columns), dtype=float)
    base = rows()
    differences = np.zeros((base.size, len(columns)))
    for j, column in enumerate(columns):
        h = step * scales(point)[j]
        put(column, point[j] + h)
        above = rows()
        put(column, point[j] - h)
        differences[:, j] = (above - rows()) / (2.0 * h)
        put(column, point[j])
    return differences, base


def analysed(name: str, values: dict) -> SteppedModel:
    """A model of ``name`` at the parameters of ``values`` with the data derived from them built."""
    spec = MODELS[name].spec
    return _analysed(name, tuple((v.name, values.get(v.name, v.start)) for v in spec.of("parameter")))


@functools.lru_cache(maxsize=4)
def _analysed(name: str, parameters: tuple[tuple[str, Any], ...]) -> SteppedModel:
    """A model of ``name`` whose data derived from ``parameters`` (its ``derived_state``: CriticalSpeeds'
    analysis) is built: the differences perturb inputs and states only, so one point's rows share it."""
    model = MODELS[name]()
    for key, value in parameters:
        setattr(model, key, value)
    errors = model.extra_parameter_errors()
    assert not errors, errors
    return model


def core_rows(name: str, values: dict, time: float) -> np.ndarray:
    """The rows from the Python core at ``values`` (parameters, inputs, states) and ``time``, evaluated as
    Model Exchange evaluates (internal state reset; a source's state is the solver's)."""
    model = MODELS[name]()
    spec = model.spec
    for key, value in values.items():
        setattr(model, key, value)
    model.reset_internal_state()
    built = analysed(name, values)
    for attribute in model.derived_state:
        setattr(model, attribute, getattr(built, attribute))
    errors = model.extra_parameter_errors()  # nothing left to build: the parameters are those analysed
    assert not errors, errors
    states = {state.name: getattr(model, state.name) for state in spec.states}
    if isinstance(model, TimeSourceModel):
        model.at_time(time)
    elif spec.states:
        model.evaluate(time)
    else:
        model.start(time)  # no state: the outputs of the inputs, at any time
    for state, value in states.items():
        setattr(model, state, value)
    outputs, _ = native.jacobian_layout(spec)
    return np.array([getattr(model, o) for o in outputs] + [getattr(model, s.derivative) for s in spec.states],
                    dtype=float)


#: What the extrapolation multiplies the values' rounding by, in units of |f| / h: its weights 1/45, 20/45, 64/45 on
#: the central differences of steps h, h/2, h/4, whose rounding is up to that of the values times |f| / step.
EXTRAPOLATION_ROUNDING = (1.0 + 20.0 * 2.0 + 64.0 * 4.0) / 45.0


def extrapolated(function: Callable[[float], np.ndarray], x: float, h: float) -> np.ndarray:
    """Richardson-extrapolated central differences of ``function`` at ``x``: D(h), D(h/2), D(h/4) combined
    to cancel the h^2 and h^4 terms of the truncation error (error O(h^6))."""
    def central(step: float) -> np.ndarray:
        return (function(x + step) - function(x - step)) / (2.0 * step)
    d1, d2, d4 = central(h), central(h / 2), central(h / 4)
    r1, r2 = (4.0 * d2 - d1) / 3.0, (4.0 * d4 - d2) / 3.0
    return (16.0 * r2 - r1) / 15.0


def core_differences(name: str, values: dict, time: float) -> np.ndarray:
    """Richardson-extrapolated central differences of the Python core (:func:`extrapolated`)."""
    _, columns = native.jacobian_layout(MODELS[name].spec)
    point = np.array([values[c] for c in columns], dtype=float)
    size = core_rows(name, values, time).size
    jacobian = np.zeros((size, len(columns)))
    for j, column in enumerate(columns):
        jacobian[:, j] = extrapolated(lambda x: core_rows(name, {**values, column: x}, time), point[j],
                                      core_step(name) * scales(point)[j])
    return jacobian


def row_scales(jacobian: np.ndarray, point: np.ndarray) -> np.ndarray:
    """Each row's largest entry times its column's scale (1 for a row of zeros): what the row's output
    moves by when a known moves by its scale."""
    row_scale = np.max(np.abs(jacobian) * scales(point), axis=1, initial=0.0)
    row_scale[row_scale == 0.0] = 1.0
    return row_scale


def scaled_error(jacobian: np.ndarray, other: np.ndarray, point: np.ndarray) -> np.ndarray:
    """|other - jacobian| of each entry times its column's scale, over its row's scale."""
    return np.abs(other - jacobian) * scales(point) / row_scales(jacobian, point)[:, None]
