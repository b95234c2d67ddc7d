"""The CriticalSpeeds model and FMU: lookups against the transfer-matrix core, re-analysis, refusals."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from driveline.rotor import Unbalance, example_path, load_driveline, one_piece_shaft
from driveline.rotor.damped import DampedRotor
from driveline.rotor.driveline import EXCITED_SHARE
from driveline.rotor.fem import elements_by_length
from driveline.rotor.model import CriticalSpeedsModel
from driveline.rotor.spec import OMEGA_IN_MAX_MIN, SPEC
from driveline.rotor.unbalance_outputs import DAMPED_MODES, DAMPING_POINTS, FE_ELEMENTS, TABLE_ELEMENTS
from fmu_harness.runs.runner import FmuInstance, StepRefused, simulate

from support import model_checks

ROTOR_B = dict(L_shaft=1.4, D_outer=0.0762, D_inner=0.0729, E=2.1e11, density=7850.0,
               m_joint=2.5, Jp_joint=0.004, Jd_joint=0.002, k_bearing=1e7)


@pytest.fixture(scope="module")
def rotor_b():
    return one_piece_shaft(**ROTOR_B)


def test_critical_speeds_and_interpolated_whirl_match_the_core(rotor_b):
    model = model_checks.started(CriticalSpeedsModel)
    assert (model.omega_crit_1, model.omega_crit_2, model.omega_crit_3) == tuple(rotor_b.critical_speeds(3))
    for speed in (0.0, 123.4, 777.7, 1499.0):  # off the spline knots
        model.omega_in = -speed  # the sign of the speed is ignored
        assert model.step(0.0, 0.01) == []
        direct = rotor_b.whirl_frequencies(speed, 2)
        interpolated = [model.whirl_forward_1, model.whirl_forward_2, model.whirl_backward_1, model.whirl_backward_2]
        # cubic splines through 41 Campbell points: measured 3e-14 (this rotor), 1e-12 (two-piece)
        np.testing.assert_allclose(interpolated, [*direct.forward[:2], *direct.backward[:2]], rtol=1e-9)
        if speed:
            every = rotor_b.order_resonances((1, 2, 3), ("forward", "backward"), None, 2 * 1500.0)
            margins = [(speed - r.spin) / r.spin for r in every]
            closest = every[int(np.argmin(np.abs(margins)))]
            assert model.resonance_speed == pytest.approx(closest.spin, rel=1e-12)
            assert (model.resonance_order, model.resonance_whirl) == (closest.order, 1 if closest.whirl == "forward" else -1)
            assert model.resonance_margin == pytest.approx((speed - closest.spin) / closest.spin)
            assert model.resonance_count == sum(abs(m) < 0.1 for m in margins)
            assert model.resonance_warning == (model.resonance_count > 0)
            assert model.speed_ratio == pytest.approx(speed / model.omega_crit_1)


def test_every_resonance_in_the_band_counts(fmu_path, fmi):
    # Two-piece example (Timoshenko tubes) at 330.5 rad/s with orders 1, 2, 3, 6: the nearest
    # resonance in rad/s (6x forward at 299.2, margin +10.5 %) lies outside the 10 % band, but
    # the 6x backward one at 358.9 (-7.9 %) and the 6x forward one at 363.4 (-9.1 %) lie inside.
    result = simulate(fmu_path("CriticalSpeeds", fmi), 0.02, 0.01, inputs={"omega_in": lambda t: 330.5},
                      start_values={"layout": "two_piece_propshaft", "orders": "1,2,3,6"})
    last = result[-1]
    assert bool(last["resonance_warning"]) and last["resonance_count"] == 2
    assert (last["resonance_order"], last["resonance_whirl"]) == (6, -1)
    assert last["resonance_speed"] == pytest.approx(358.93, abs=0.01)  # 361.6 with Rayleigh tubes (the issue)
    assert last["resonance_margin"] == pytest.approx((330.5 - last["resonance_speed"]) / last["resonance_speed"])


def test_analysis_runs_only_when_the_structure_changes():
    model = model_checks.started(CriticalSpeedsModel)
    analysis = model._analysis
    for k in range(5):
        model.omega_in = 100.0 + k
        assert model.step(k * 0.01, 0.01) == []
    assert model._analysis is analysis
    model.k_bearing = 2e6  # a softer bearing, mid-run
    assert model.step(0.05, 0.01) == []
    assert model._analysis is not analysis
    assert model.omega_crit_1 == pytest.approx(one_piece_shaft(**{**ROTOR_B, "k_bearing": 2e6}).critical_speeds(1)[0])


def test_shipped_layout_by_name():
    model = model_checks.started(CriticalSpeedsModel, layout="two_piece_propshaft")
    expected = load_driveline(example_path("two_piece_propshaft")).critical_speeds(3)
    assert model.omega_crit_1 == expected[0]


@pytest.mark.parametrize(
    "values, fragment",
    [
        ({"D_inner": 0.08}, "D_inner"),
        ({"L_shaft": -1.0}, "L_shaft"),
        ({"density": 0.0}, "density"),
        ({"orders": "1,two"}, "'two'"),
        ({"layout": "missing.toml"}, "missing.toml"),
        ({"omega_in_max": 0.0}, "omega_in_max"),
        ({"c_bearing": -1.0}, "c_bearing"),
        ({"unbalance_position": 1.5}, "unbalance_position"),
        ({"response_position": -0.1}, "response_position"),
        ({"unbalance": -1e-4}, "unbalance"),
    ],
)
def test_non_physical_structure_is_refused_with_the_value_named(values, fragment):
    model = CriticalSpeedsModel()
    for name, value in values.items():
        setattr(model, name, value)
    errors = model.initialize(0.0)
    assert errors and fragment in errors[0]


def test_malformed_description_file_is_refused(tmp_path):
    broken = tmp_path / "broken.toml"
    broken.write_text("[[segments]]\nlength = 'long'\n")
    model = CriticalSpeedsModel()
    model.layout = str(broken)
    errors = model.initialize(0.0)
    assert errors and "length" in errors[0]


def test_fmu_follows_a_speed_ramp_and_refuses_overspeed(fmu_path, rotor_b):
    path = fmu_path("CriticalSpeeds")
    result = simulate(path, 1.0, 0.05, inputs={"omega_in": lambda t: 1400.0 * t})
    np.testing.assert_allclose(result["omega_crit_1"], rotor_b.critical_speeds(1)[0], rtol=1e-12)
    np.testing.assert_allclose(result["speed_ratio"][1:], 1400.0 * (result["time"][1:] - 0.05) / result["omega_crit_1"][1:], rtol=1e-12)
    with FmuInstance(path) as fmu:
        fmu.initialize({"omega_in": 100.0})
        fmu.step(0.01)
        fmu.set({"omega_in": 1600.0})
        with pytest.raises(StepRefused) as refused:
            fmu.step(0.01)
    assert "omega_in_max" in refused.value.messages[0]
    with pytest.raises(StepRefused) as refused:
        simulate(path, 0.1, 0.05, start_values={"D_inner": 0.09})
    assert any("D_inner" in message for message in refused.value.messages)


def test_short_shaft_reports_how_many_critical_speeds_it_has(fmu_path, fmi):
    # A 0.06 m tube has only two forward critical speeds below the 1e5 rad/s search limit:
    # accepted, counted, and the missing one reads as the limit. (A 0.1 m Rayleigh tube had two;
    # the Timoshenko tube has a third at 7.25e4 rad/s.)
    result = simulate(fmu_path("CriticalSpeeds", fmi), 0.02, 0.01, start_values={"L_shaft": 0.06})
    expected = one_piece_shaft(**{**ROTOR_B, "L_shaft": 0.06}).critical_speeds(3)
    assert expected.size == 2 and result["critical_speed_count"][-1] == 2
    np.testing.assert_array_equal([result["omega_crit_1"][-1], result["omega_crit_2"][-1]], expected)
    assert result["omega_crit_3"][-1] == 1e5


def test_layout_path_any_case_relative_to_the_working_directory(tmp_path, monkeypatch):
    (tmp_path / "Shaft.TOML").write_text(example_path("two_piece_propshaft").read_text())
    monkeypatch.chdir(tmp_path)
    model = model_checks.started(CriticalSpeedsModel, layout="Shaft.TOML")
    assert model.omega_crit_1 == load_driveline(example_path("two_piece_propshaft")).critical_speeds(3)[0]
    broken = CriticalSpeedsModel()
    broken.layout = "missing.toml"
    errors = broken.initialize(0.0)
    assert errors and str(tmp_path / "missing.toml") in errors[0]  # the full path


def test_unbalance_outputs_match_the_damped_model():
    model = model_checks.started(CriticalSpeedsModel, c_bearing=800.0, unbalance=2e-4, unbalance_position=0.3,
                                 response_position=0.6)
    d = dataclasses.replace(one_piece_shaft(**ROTOR_B, c_bearing=800.0), unbalances=[Unbalance(0.42, 2e-4)])
    rotor, coarse = DampedRotor(d, elements_by_length(d, FE_ELEMENTS)), DampedRotor(d, elements_by_length(d, TABLE_ELEMENTS))
    speeds = np.linspace(0.0, 1500.0, DAMPING_POINTS)
    for speed in (*speeds, 123.4, 655.0, 1234.5):
        model.omega_in = speed
        assert model.step(0.0, 0.01) == []
        response = rotor.unbalance_response([speed], positions=[0.84])
        assert model.unbalance_response == pytest.approx(response.major[0, 0], rel=1e-12, abs=0.0)
        assert model.bearing_force_max == pytest.approx(np.max(response.bearing_forces), rel=1e-12, abs=0.0)
        if speed in speeds:  # on a knot of the table: exact
            excited = [m for m in coarse.modes(speed, 4 * DAMPED_MODES) if m.forward_share >= EXCITED_SHARE]
            nearest = min(excited[:DAMPED_MODES], key=lambda m: abs(m.frequency - speed))
            assert model.damping_ratio == pytest.approx(nearest.damping_ratio, rel=1e-9)


def test_fmu_unbalance_response_peaks_at_the_first_critical_speed(fmu_path, fmi):
    # A ramp through the first critical speed of the (Timoshenko) tube, 655.23 rad/s: the response
    # peaks there (FE_ELEMENTS elements: the peak lies 1.1e-4 above the exact root, measured), and
    # the damping ratio read there is the first forward mode's (2.5e-3 at 800 N s/m; the table's
    # splines are within 1e-4 of the table model's, and that within 0.4 % of a fine mesh's).
    result = simulate(fmu_path("CriticalSpeeds", fmi), 1.0, 0.001, inputs={"omega_in": lambda t: 640.0 + 30.0 * t},
                      start_values={"c_bearing": 800.0})
    critical = result["omega_crit_1"][-1]
    peak = int(np.argmax(result["unbalance_response"]))
    speed_at_peak = 640.0 + 30.0 * (result["time"][peak] - 0.001)
    assert speed_at_peak == pytest.approx(critical, rel=3e-4)
    assert result["bearing_force_max"][peak] == np.max(result["bearing_force_max"])
    d = one_piece_shaft(**ROTOR_B, c_bearing=800.0)
    rotor = DampedRotor(d, elements_by_length(d, FE_ELEMENTS))
    first = min(DampedRotor(d, elements_by_length(d, TABLE_ELEMENTS)).modes(speed_at_peak, 4), key=lambda m: abs(m.frequency - speed_at_peak))
    fine = min(DampedRotor(d, 48).modes(speed_at_peak, 4), key=lambda m: abs(m.frequency - speed_at_peak))
    assert first.whirl == "forward"
    assert result["damping_ratio"][peak] == pytest.approx(first.damping_ratio, rel=1e-4)
    assert result["damping_ratio"][peak] == pytest.approx(fine.damping_ratio, rel=4e-3)
    expected = rotor.unbalance_response([speed_at_peak], [Unbalance(0.7, 1e-4)], [0.7])
    assert result["unbalance_response"][peak] == pytest.approx(expected.major[0, 0], rel=1e-9)


def test_shear_parameter_selects_the_beam_theory(fmu_path, fmi):
    rayleigh = simulate(fmu_path("CriticalSpeeds", fmi), 0.01, 0.01, start_values={"shear": False})
    timoshenko = simulate(fmu_path("CriticalSpeeds", fmi), 0.01, 0.01)
    assert rayleigh["omega_crit_1"][-1] == pytest.approx(one_piece_shaft(**ROTOR_B, shear=False).critical_speeds(1)[0],
                                                         rel=1e-12)
    assert timoshenko["omega_crit_1"][-1] == pytest.approx(one_piece_shaft(**ROTOR_B).critical_speeds(1)[0], rel=1e-12)
    assert timoshenko["omega_crit_1"][-1] / rayleigh["omega_crit_1"][-1] - 1 == pytest.approx(-0.0078, abs=1e-4)


def test_a_layout_brings_its_own_unbalance_and_damping(tmp_path):
    text = example_path("two_piece_propshaft").read_text().replace("stiffness = 1.0e6", "stiffness = 1.0e6\ndamping = 300.0")
    layout = tmp_path / "unbalanced.toml"
    layout.write_text(text + "\n[[unbalances]]\nposition = 0.35\namount = 5e-5\nphase = 1.0\n")
    model = model_checks.started(CriticalSpeedsModel, layout=str(layout), unbalance=1.0, response_position=0.25)
    d = load_driveline(layout)
    expected = DampedRotor(d, elements_by_length(d, FE_ELEMENTS)).unbalance_response([300.0], positions=[0.25 * d.length])
    assert model.unbalance_response == pytest.approx(expected.major[0, 0], rel=1e-12)  # the FMU's unbalance is not used
    assert model.bearing_force_max == pytest.approx(np.max(expected.bearing_forces), rel=1e-12)
    plain = model_checks.started(CriticalSpeedsModel, layout="two_piece_propshaft")
    assert plain.unbalance_response == 0.0 and plain.bearing_force_max == 0.0  # no [[unbalances]]


#: The edges of every Real parameter that the property tests draw (``support.alongside_the_core``:
#: +-1e300, one below the minimum, one above the maximum), and omega_in_max's declared minimum from
#: both sides with the values of issue 34 (1e-300 and 1e-150 rad/s: the Python core's tables
#: overflowed while the native ones ran).
EDGES = [(v.name, value) for v in SPEC.of("parameter") if v.type == "Real"
         for value in (1e300, -1e300, *([v.min - 1.0] if v.min is not None else []),
                       *([v.max + 1.0] if v.max is not None else []))] + [
    ("omega_in_max", OMEGA_IN_MAX_MIN), ("omega_in_max", math.nextafter(OMEGA_IN_MAX_MIN, 0.0)),
    ("omega_in_max", 1e-150), ("omega_in_max", 1e-300)]


@pytest.mark.parametrize("name, value", EDGES)
def test_parameter_edges_get_the_cores_answer(family, name, value):
    """At each edge both families give the core's answer: refused with its reason, or run with its
    outputs (the family's tolerance)."""
    start = {name: value, "omega_in": 0.0}
    core = CriticalSpeedsModel()
    for variable, start_value in start.items():
        setattr(core, variable, start_value)
    errors = core.initialize(0.0)
    outputs = [v.name for v in SPEC.of("output") if v.type == "Real"]
    with family.open("CriticalSpeeds") as fmu:
        if errors:
            with pytest.raises(StepRefused) as refused:  # native: at initialisation; Python: the first step
                fmu.initialize(start)
                fmu.step(1e-2)
            assert any(family.reason(errors[0]) in family.reason(message) for message in refused.value.messages)
        else:
            fmu.initialize(start)
            family.assert_outputs_agree(outputs, [fmu.get(outputs)], [[getattr(core, o) for o in outputs]])


def test_a_tunable_parameter_is_checked_at_the_next_step_and_after_a_restored_state(family):
    """The parameters' checks follow every change: a tunable parameter set beyond its bound in Step Mode
    is refused at the next step with its reason, and a restored FMU state that holds the bad value
    too; set back, or restored to a state of valid parameters, the steps go on with the outputs of
    an instance never changed (the native layer checks the parameters again only after such a change)."""
    start = {"omega_in": 100.0}
    outputs = ["omega_crit_1", "speed_ratio"]
    with family.open("CriticalSpeeds") as fmu, family.open("CriticalSpeeds", instance_name="untouched") as untouched:
        for instance in (fmu, untouched):
            instance.initialize(start)
            instance.step(1e-2)
        good = fmu.get_state()
        fmu.set({"L_shaft": -1.0})
        with pytest.raises(StepRefused) as refused:
            fmu.step(1e-2)
        assert any("L_shaft" in message for message in refused.value.messages)
        bad = fmu.get_state()
        fmu.set_state(good)
        fmu.step(1e-2)
        untouched.step(1e-2)
        assert fmu.get(outputs) == untouched.get(outputs)
        fmu.set_state(bad)
        with pytest.raises(StepRefused):
            fmu.step(1e-2)
        fmu.set({"L_shaft": 1.4})
        fmu.step(1e-2)
        untouched.step(1e-2)
        assert fmu.get(outputs) == untouched.get(outputs)
        for state in (good, bad):
            fmu.free_state(state)
