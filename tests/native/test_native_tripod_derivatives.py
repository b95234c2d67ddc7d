"""TripodCoupling's exact directional derivatives (``fmu_src/native/models/tripod_coupling/``) in every mode.

The generic checks (``tests/native/test_native_derivatives.py``) run at the start values (closed form,
leading-order reactions) and the model's dependency points (exact with friction and the seed's eqs; rates
from the samples). Here each mode on its own: closed form with the rates from the inputs and the seed's
eqs, exact without friction, exact with friction (drive and coast: the efficiency's two branches), the
automatic rates while both are 0, each again in a moving housing (psi, psi_dot, psi_ddot, plunge_dot; the
roller tripods there), against central differences of the same FMU and the Python core's
extrapolated differences, with the tolerances of the generic test (``support.derivatives``) but for two
rows where large terms cancel (``a_plunger_sum`` and ``Rz_out`` of the exact reactions, held to the
differences' own rounding: ``support.derivatives.ROUNDING_ROWS``); their exact values are checked to 1e-10
in the columns where the outputs are polynomials (below).

Without friction every output is a polynomial of degree at most 2 in omega_in, alpha_in, T_load, beta_dot,
beta_ddot, psi_dot and psi_ddot (velocities linear in omega_in, beta_dot and psi_dot, accelerations and forces
quadratic in them, linear in alpha_in, beta_ddot, psi_ddot and T_load; plunge_dot acts through friction alone): one central difference of the core with a step of half the
column's scale is then exact up to rounding (measured 2.5e-11), every row included.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException

from driveline.catalog import MODELS
from driveline.tripod.spec import DOUBLE_ROLLER, EXACT, RATES_FROM_INPUTS, SINGLE_ROLLER
from fmu_harness.packaging import native
from support import derivatives
from support.model_exchange import ModelExchange

NAME = "TripodCoupling"
SPEC = MODELS[NAME].spec
TIME, SHIFT = 0.05, 0.4  # s, rad: as the generic test
RATES = {"alpha_in": 30.0, "beta_dot": 0.5, "beta_ddot": 3.0}
HOUSING = {"psi": 0.7, "psi_dot": 4.0, "psi_ddot": 25.0, "plunge_dot": 0.02}
POINTS = {
    "closed form, rates from the inputs, seed eqs": {"beta_rate": RATES_FROM_INPUTS, "seed_reactions": 1, **RATES},
    "exact, no friction, rates from the inputs": {"kinematics": EXACT, "beta_rate": RATES_FROM_INPUTS, **RATES},
    "exact, friction, drive": {"kinematics": EXACT, "mu": 0.05, **RATES},
    "exact, friction, coast, automatic rates at 0": {"kinematics": EXACT, "mu": 0.05, "T_load": -100.0,
                                                     "alpha_in": -20.0},
    # the moving housing: the bend plane turned by psi and turning, the spider plunging
    "closed form, moving housing, seed eqs": {"beta_rate": RATES_FROM_INPUTS, "seed_reactions": 1, **RATES, **HOUSING},
    "exact, no friction, moving housing": {"kinematics": EXACT, "beta_rate": RATES_FROM_INPUTS, **RATES, **HOUSING},
    "exact, friction, moving housing": {"kinematics": EXACT, "mu": 0.05, **RATES, **HOUSING},
    "single roller, friction, moving housing": {"kinematics": EXACT, "mu": 0.05, "tripod_type": SINGLE_ROLLER,
                                                **RATES, **HOUSING},
    "double roller, friction, moving housing": {"kinematics": EXACT, "mu": 0.05, "tripod_type": DOUBLE_ROLLER,
                                                "T_load": -300.0, **RATES, **HOUSING},
}
#: Without friction the outputs are polynomials of degree 2 in these too: psi_dot enters as omega_in does
#: (omega_in - psi_dot, plus psi_dot e_z in the output's angular velocity), psi_ddot as alpha_in, plunge_dot
#: not at all
POLYNOMIAL = ("omega_in", "alpha_in", "T_load", "beta_dot", "beta_ddot", "psi_dot", "psi_ddot", "plunge_dot")
FMU_TOLERANCE, CORE_TOLERANCE = 1e-7, 1e-10


def _at_point(native_dir, fmi: str, point: dict, folder) -> ModelExchange:
    model = ModelExchange(native.fmu_path(native_dir, NAME, fmi), fmi, point, folder)
    model.fmu.setTime(TIME)
    model.set_states(model.get_states() + SHIFT)
    return model


def _bounds(index: int) -> np.ndarray:
    """The (FMU, core) bound of each row."""
    return derivatives.row_bounds(NAME, FMU_TOLERANCE, CORE_TOLERANCE)[index]


def _core_values(model: ModelExchange, point: dict) -> dict:
    _, columns = derivatives.layout(NAME)
    return {v.name: v.start for v in SPEC.variables} | point | dict(zip(columns, model.get(columns)))


@pytest.mark.parametrize("point", POINTS)
def test_every_mode_equals_central_differences_of_the_fmu(native_dir, tmp_path, point, fmi):
    model = _at_point(native_dir, fmi, POINTS[point], tmp_path)
    _, columns = derivatives.layout(NAME)
    jacobian = derivatives.exact(model.fmu, NAME, fmi)
    differences, values = derivatives.fmu_differences(model, NAME)
    at = np.array(model.get(columns), dtype=float)
    rounding = 10 * np.finfo(float).eps * np.abs(values) / derivatives.FMU_STEP
    allowed = _bounds(0) + rounding / derivatives.row_scales(jacobian, at)
    assert np.all(derivatives.scaled_error(jacobian, differences, at) <= allowed[:, None])
    model.close()


@pytest.mark.parametrize("point", POINTS)
def test_every_mode_equals_the_cores_extrapolated_differences(native_dir, tmp_path, point):
    model = _at_point(native_dir, "2", POINTS[point], tmp_path)
    _, columns = derivatives.layout(NAME)
    jacobian = derivatives.exact(model.fmu, NAME, "2")
    values = _core_values(model, POINTS[point])
    reference = derivatives.core_differences(NAME, values, TIME)
    error = derivatives.scaled_error(jacobian, reference, np.array([values[c] for c in columns], dtype=float))
    assert np.all(error <= _bounds(1)[:, None])
    model.close()


@pytest.mark.parametrize("point", [p for p in POINTS if "mu" not in POINTS[p]])
def test_without_friction_the_polynomial_columns_are_exact(native_dir, tmp_path, point):
    """Every row, the cancelling ones included, in the columns where the outputs are polynomials of
    degree 2: one central difference of the core with a large step is exact up to rounding."""
    model = _at_point(native_dir, "2", POINTS[point], tmp_path)
    _, columns = derivatives.layout(NAME)
    jacobian = derivatives.exact(model.fmu, NAME, "2")
    values = _core_values(model, POINTS[point])
    at = np.array([values[c] for c in columns], dtype=float)
    reference = jacobian.copy()
    for column in POLYNOMIAL:
        j = columns.index(column)
        h = 0.5 * derivatives.scales(at)[j]
        above = derivatives.core_rows(NAME, {**values, column: at[j] + h}, TIME)
        below = derivatives.core_rows(NAME, {**values, column: at[j] - h}, TIME)
        reference[:, j] = (above - below) / (2.0 * h)
    assert derivatives.scaled_error(jacobian, reference, at).max() <= CORE_TOLERANCE
    model.close()


def test_co_simulation_gives_the_model_exchange_derivatives_with_friction(native_dir, tmp_path, fmi):
    """After a step the co-simulation instance's Jacobian is the Model Exchange one's at the same states
    and inputs, bit for bit: the warm start and the bend samples the step keeps do not enter it."""
    point = POINTS["exact, friction, drive"]
    path = native.fmu_path(native_dir, NAME, fmi)
    cs = ModelExchange(path, fmi, point, tmp_path / "cs", interface="CoSimulation")
    cs.fmu.doStep(0.0, 0.01)
    me = ModelExchange(path, fmi, point, tmp_path / "me")
    me.fmu.setTime(0.01)
    me.set_states(np.array(cs.get(["phi_in"]), dtype=float))
    assert np.array_equal(derivatives.exact(cs.fmu, NAME, fmi), derivatives.exact(me.fmu, NAME, fmi))
    me.close()
    cs.close()


def test_where_the_step_refuses_the_derivatives_are_refused_with_its_reason(native_dir, tmp_path, fmi):
    """Friction 0.3 at beta = 57 deg: the friction balance does not settle, the call is discarded with
    the step's words; at 17 deg again, the derivatives are given."""
    path = native.fmu_path(native_dir, NAME, fmi)
    model = ModelExchange(path, fmi, {"kinematics": EXACT, "mu": 0.3, "beta_max": math.radians(60.0), "beta": 0.3},
                          tmp_path)
    rows, columns = derivatives.references(NAME, fmi)
    model.set({"beta": 1.0})
    with pytest.raises(FMICallException) as refused:
        model.fmu.getDirectionalDerivative(rows, columns, [1.0] * len(columns))
    assert refused.value.status == 2
    assert model.log[-1] == ("the outputs at t = 0.0 s could not be computed (ArithmeticError: tripod friction "
                             "balance did not converge (friction coefficient too large?))")
    model.set({"beta": 0.3})
    assert np.all(np.isfinite(model.fmu.getDirectionalDerivative(rows, columns, [1.0] * len(columns))))
    model.close()
