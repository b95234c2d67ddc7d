"""PowertrainMounts' halfshaft outputs through the FMUs, both families and FMI versions: a loaded run's
geometry is the core's (the Python FMUs bit for bit, the native ones within their tolerances), the switch
holds the design, and a start beyond a joint's stroke is refused with the core's one line."""

from __future__ import annotations

import math

import pytest

from driveline.mounts.halfshafts import GEOMETRY
from driveline.mounts.model import PowertrainMountsModel
from driveline.mounts.spec import SIDES
from support.alongside_the_core import expect_refused_parameters

NAME = "PowertrainMounts"
OUTPUTS = [f"{name}_{side}" for side in SIDES for name in GEOMETRY]
#: A launch-sized load, off every axis, and a non-default wheel placement (a tilted plane, a plunge)
START = {"Rz_in_left": -300.0, "Rz_in_right": 250.0, "T_in_left": 400.0, "T_in_right": -380.0, "F_y": 500.0,
         "psi_design_right": 0.4, "plunge_design_left": 0.003, "l_right": 0.65}


def _core_rows(changes: list[dict[str, float]], step: float) -> list[list[float]]:
    model = PowertrainMountsModel()
    for name, value in START.items():
        setattr(model, name, value)
    assert model.initialize(0.0) == []
    rows = []
    for k, values in enumerate(changes):
        for name, value in values.items():
            setattr(model, name, value)
        assert model.step(k * step, step) == []
        rows.append([getattr(model, name) for name in OUTPUTS])
    return rows


def test_a_loaded_run_gives_the_cores_geometry(family, fmi):
    """40 steps of 1 ms under loads that change every step (first-order hold): every halfshaft output after
    each step, the core's."""
    step = 1e-3
    changes = [{"M_x": 150.0 * math.sin(0.3 * k), "Rz_in_dot_left": 2000.0 * math.cos(0.2 * k)} for k in range(40)]
    rows = []
    with family.open(NAME, fmi) as fmu:
        fmu.initialize(START)
        for k, values in enumerate(changes):
            fmu.set(values)
            fmu.step(step)
            rows.append(fmu.get(OUTPUTS))
    core = _core_rows(changes, step)
    assert any(row[OUTPUTS.index("beta_ddot_left")] != 0.0 for row in core)
    family.assert_outputs_agree(OUTPUTS, rows, core)


def test_with_the_housings_held_the_outputs_are_the_design(family, fmi):
    with family.open(NAME, fmi) as fmu:
        fmu.initialize({**START, "housing_motion": 0})
        fmu.step(1e-3)
        found = dict(zip(OUTPUTS, fmu.get(OUTPUTS)))
    assert (found["beta_left"], found["psi_right"], found["plunge_left"]) == (math.radians(8.0), 0.4, 0.003)
    assert all(value == 0.0 for name, value in found.items() if "dot" in name)


@pytest.mark.parametrize("values", [{"F_y": 2000.0, "plunge_max_left": 0.001, "plunge_min_left": -0.001},
                                    {"F_z": 20000.0, "beta_max_right": math.radians(6.01)},
                                    {"beta_design_left": math.radians(50.0)}])
def test_a_start_beyond_a_joints_limits_is_refused_with_the_cores_line(family, fmi, values):
    """A start beyond the stroke or the largest bend, and a design beyond the largest bend: the core's one line."""
    model = PowertrainMountsModel()
    for name, value in values.items():
        setattr(model, name, value)
    errors = model.initialize(0.0)
    assert len(errors) == 1
    with family.open(NAME, fmi) as fmu:
        expect_refused_parameters(fmu, values, errors, family.reason)
