"""Start values checked before an engine starts (``fmu_harness.runs.start_values``): the FMU's own
reason, in one line, from the importers' sessions, the system master, sweeps and the ``check``
command, before any engine or FMU is loaded."""

from __future__ import annotations

import dataclasses

import pytest

from fmu_harness.checks import importers
from fmu_harness.runs import start_values, sweep, system
from fmu_harness.runs.runner import StepRefused

#: A parameter of each kind of check, an input beyond its relation, and a value the FMUs refuse at
#: initialisation.
REFUSED = [("TripodCoupling", {"r": -1.0}), ("CardanJoint", {"beta_max": 2.0}),
           ("CriticalSpeeds", {"omega_in_max": 1e-300, "omega_in": 0.0}), ("CriticalSpeeds", {"omega_in_max": 1e300}),
           ("TripodCoupling", {"beta": 1.0})]


def _changed_system(name: str, component: str, **values: float) -> system.System:
    """The driveline with ``values`` bound on ``component``, named apart (its package is written next
    to the driveline's)."""
    driveline = system.driveline()
    changed = driveline.component(component)
    bound = dataclasses.replace(changed, parameters={**changed.parameters, **values})
    return dataclasses.replace(driveline, name=name,
                               components=tuple(bound if c is changed else c for c in driveline.components))


def _bad_system() -> system.System:
    """The driveline with a coupling whose groove radius is negative."""
    return _changed_system("NegativeGrooveRadius", "coupling", r=-1.0)


@pytest.mark.parametrize("model, values", REFUSED)
def test_the_reason_is_the_fmus_own(family, model, values):
    reasons = start_values.refusals(model, values)
    assert reasons
    with family.open(model) as fmu:
        with pytest.raises(StepRefused) as refused:  # native: at initialisation; Python: the first step
            fmu.initialize(values)
            fmu.step(1e-3)
    assert any(family.reason(reasons[0]) in family.reason(message) for message in refused.value.messages)


def test_accepted_values_and_models_outside_the_catalog_pass():
    assert start_values.refusals("TripodCoupling", {"r": 0.03, "beta": 0.2}) == []
    assert start_values.refusals("NoSuchModel", {"x": 1.0}) == []
    assert start_values.refusals("TripodCoupling", {"radius": 1.0}) == ["radius is no parameter or input of TripodCoupling"]


@pytest.mark.parametrize("session", [importers.cosim_session, importers.ecos_session])
def test_the_importers_sessions_refuse_before_the_engine_starts(session, fmi2_dir):
    fmus = {"joint": fmi2_dir / "TripodCoupling.fmu"}
    with pytest.raises(start_values.StartValuesRefused) as refused:
        session(1e-3, fmus, start_values={"joint.r": -1.0})
    assert str(refused.value) == "joint (TripodCoupling): parameter r = -1000 mm must be positive"


def test_an_ssp_package_is_checked_by_its_bindings(fmi2_dir, capsys):
    start_values.main([str(system.write_ssp(system.driveline(), fmi2_dir))])
    assert "every start value accepted (source, coupling, critical)" in capsys.readouterr().out
    bad = system.write_ssp(_bad_system(), fmi2_dir)
    with pytest.raises(SystemExit) as exited:
        start_values.main([str(bad)])
    assert exited.value.code == 1
    assert capsys.readouterr().err.endswith(": refused: coupling (TripodCoupling): parameter r = -1000 mm must be "
                                            "positive\n")
    with pytest.raises(start_values.StartValuesRefused):
        importers.cosim_session(1e-3, ssp=bad)


def test_an_fmu_is_checked_with_the_values_given(fmi2_dir, capsys):
    with pytest.raises(SystemExit) as exited:
        start_values.main([str(fmi2_dir / "CriticalSpeeds.fmu"), "omega_in_max=1e-300", "omega_in=0"])
    assert exited.value.code == 1
    assert capsys.readouterr().err.endswith(": refused: CriticalSpeeds (CriticalSpeeds): parameter omega_in_max = "
                                            "1e-300 rad/s is below its minimum 0.001 rad/s\n")


def test_the_system_master_refuses_before_loading_an_fmu(tmp_path):
    with pytest.raises(start_values.StartValuesRefused, match="coupling .TripodCoupling.: parameter r"):
        system.simulate(_bad_system(), tmp_path)  # an empty folder: no FMU is loaded


def test_a_sweep_whose_every_point_is_refused_exits_before_any_worker(fmi2_dir, capsys):
    with pytest.raises(SystemExit) as exited:
        sweep.main(["--grid", "r=-1,-2", "--models", str(fmi2_dir)])
    assert capsys.readouterr().err == ("driveline-fmus sweep: refused: every point, none run: parameter r = -1000 mm "
                                       "must be positive (and 1 more reason)\n")
    assert exited.value.code == 1
    assert sweep.refused_points("TripodCoupling", [{"r": 0.03}, {"r": -1.0}, {"beta": 0.9}]) == {
        1: "parameter r = -1000 mm must be positive", 2: "input beta = 51.5662 deg must not exceed beta_max = 45 deg"}


def test_a_connected_input_is_checked_at_the_start_of_the_output_feeding_it(fmi2_dir, capsys):
    """An engine sets a connected input to its output's value before ExitInitializationMode: the
    watcher's omega_in takes the coupling's omega_out start (0), not its own (300 rad/s), so an
    omega_in_max of 100 rad/s is accepted; an unconnected input's start beyond its relation (the
    coupling's beta above beta_max, refused by the FMUs at initialisation) is refused naming it."""
    start_values.main([str(system.write_ssp(_changed_system("SlowShaft", "critical", omega_in_max=100.0), fmi2_dir))])
    assert "every start value accepted" in capsys.readouterr().out
    with pytest.raises(SystemExit) as exited:
        start_values.main([str(system.write_ssp(_changed_system("OverBent", "coupling", beta=1.0), fmi2_dir))])
    assert exited.value.code == 1
    assert capsys.readouterr().err.endswith(": refused: coupling (TripodCoupling): input beta = 57.2958 deg must not "
                                            "exceed beta_max = 45 deg\n")
