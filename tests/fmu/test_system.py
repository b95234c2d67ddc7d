"""The driveline system as an SSP package, with the Python FMUs and with the native ones where
they exist: its structure, and the same results from our fmpy master, libcosim and Ecos."""

from __future__ import annotations

import importlib.resources
import importlib.util
import zipfile
from dataclasses import replace
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from fmpy import read_model_description

from driveline.cardan import kinematics
from driveline.catalog import MODELS
from fmu_harness.checks import importers
from fmu_harness.packaging import fmu_path, native
from fmu_harness.runs import system
from support.native_agreement import SIGNAL_TOLERANCE, TOLERANCE

SSD = {"ssd": system.SSD, "ssv": system.SSV}
PACKAGES = ("driveline_ssp", "native_ssp")


@pytest.fixture(scope="module")
def driveline_ssp(fmi2_dir: Path) -> Path:
    return system.write_ssp(system.driveline(), fmi2_dir)


@pytest.fixture(scope="module")
def native_ssp(fmi2_dir: Path, native_dir: Path) -> Path:
    return system.write_ssp(system.driveline(), fmi2_dir, native_dir)


@pytest.fixture(scope="module")
def master_result(fmi2_dir: Path) -> np.ndarray:
    return system.simulate(system.driveline(), fmi2_dir)


def _deviation(result: np.ndarray, master_result: np.ndarray) -> dict[str, float]:
    """Each column's largest deviation from the master's, relative to the column's largest magnitude."""
    driveline = system.driveline()
    scale = np.maximum(np.abs(master_result).max(axis=0), 1e-300)
    names = ["time", *driveline.outputs()]
    # a_plunger_sum cancels three plunger accelerations of ~1e3 m/s^2 down to ~1e-2: its round-off
    # follows the terms (F_plunger1 / m_plunger), not the sum (measured 4e-9 of the sum)
    mass = next(v.start for v in driveline.component("coupling").spec.variables if v.name == "m_plunger")
    scale[names.index("coupling.a_plunger_sum")] = np.abs(master_result[:, names.index("coupling.F_plunger1")]).max() / mass
    return dict(zip(names, np.abs(result - master_result).max(axis=0) / scale))


def test_the_system_has_the_source_the_coupling_and_the_watcher_when_there_is_one():
    models = {c.model for c in system.driveline().components}
    assert {"SpeedSource", "TripodCoupling"} <= models
    assert (system.WATCHER in models) == (system.WATCHER in MODELS)


def test_system_structures_are_valid_ssp_1_0(driveline_ssp, native_ssp, fmi2_dir, native_dir):
    """Both packages, and both of the vehicle launch, against the SSP 1.0 schemas that pyssp-standard
    ships (loaded once: seconds)."""
    if importlib.util.find_spec("pyssp_standard") is None or importlib.util.find_spec("xmlschema") is None:
        pytest.skip("pyssp-standard is not installed on this platform (pip install '.[interop]')")
    import xmlschema

    schema = xmlschema.XMLSchema(str(importlib.resources.files("pyssp_standard") / "resources" / "SystemStructureDescription.xsd"))
    launch = system.vehicle_launch()
    launch_packages = (system.write_ssp(launch, fmi2_dir), system.write_ssp(launch, fmi2_dir, native_dir))
    for package in (driveline_ssp, native_ssp, *launch_packages):
        with zipfile.ZipFile(package) as archive:
            schema.validate(archive.read("SystemStructure.ssd").decode())


@pytest.mark.parametrize("package", PACKAGES)
def test_package_wires_existing_variables_and_binds_parameters(package, request, tmp_path):
    with zipfile.ZipFile(request.getfixturevalue(package)) as archive:
        archive.extractall(tmp_path)
    root = ET.parse(tmp_path / "SystemStructure.ssd").getroot()
    assert root.get("version") == "1.0"
    variables = {}
    for component in root.iterfind("ssd:System/ssd:Elements/ssd:Component", SSD):
        description = read_model_description(str(tmp_path / component.get("source")))
        variables[component.get("name")] = {v.name: v.causality for v in description.modelVariables}
        for connector in component.iterfind("ssd:Connectors/ssd:Connector", SSD):
            assert variables[component.get("name")][connector.get("name")] == connector.get("kind")
        for parameter in component.iterfind(".//ssv:Parameter", SSD):
            assert parameter.get("name") in variables[component.get("name")]
    connections = root.findall("ssd:System/ssd:Connections/ssd:Connection", SSD)
    assert connections
    for connection in connections:
        assert variables[connection.get("startElement")][connection.get("startConnector")] == "output"
        assert variables[connection.get("endElement")][connection.get("endConnector")] == "input"


def test_native_package_holds_the_native_fmu_of_each_model_that_has_one(native_ssp, fmi2_dir, native_dir):
    ported = set(native.native_models())
    assert "SpeedSource" in ported
    with zipfile.ZipFile(native_ssp) as archive:
        root = ET.fromstring(archive.read("SystemStructure.ssd"))
        for component in root.iterfind("ssd:System/ssd:Elements/ssd:Component", SSD):
            model = system.driveline().component(component.get("name")).model
            family, fmu = ("native", native.fmu_path(native_dir, model)) if model in ported else ("Python", fmu_path(fmi2_dir, model))
            assert archive.read(component.get("source")) == fmu.read_bytes(), model
            assert component.get("description") == f"{family} FMU of {model}"


def test_the_master_runs_the_native_variant_like_the_python_system(fmi2_dir, native_dir, master_result):
    """Within the native FMUs' own promise of each output's largest magnitude (tests/support/native_agreement.py:
    1e-12, the watcher's eigenvalue-conditioned outputs 1e-9 and 1e-8; measured: bit for bit but the
    tripod's theta, 1.4e-16, and the watcher's damping ratio, 6.9e-11)."""
    result = system.simulate(system.driveline(), fmi2_dir, natives=native_dir)
    deviation = _deviation(result, master_result)
    beyond = {name: d for name, d in deviation.items()
              if not d <= SIGNAL_TOLERANCE.get(name.rpartition(".")[2], TOLERANCE)}
    assert beyond == {}, deviation


def test_the_master_feeds_the_coupling_with_the_source_speed_and_acceleration(master_result):
    """Jacobi: the coupling takes the source's speed and acceleration of t_k over the step to
    t_(k+1) and advances phi_in by omega h + alpha h^2 / 2, exact on the ramp: its phase stays
    within 1e-4 rad of the source's exact angle over the 1 s run (measured 5.5e-5 rad, the sine's
    jerk h^3/6 per step; with the speed alone it fell 0.131 rad behind, h alpha t / 2)."""
    driveline = system.driveline()
    outputs = driveline.outputs()
    column = {name: master_result[:, i + 1] for i, name in enumerate(outputs)}
    h = driveline.step_size
    source = driveline.component("source").parameters
    speed = np.concatenate([[source["omega_out_start"]], column["source.omega_out"][:-1]])
    start_acceleration = source["ramp_rate"] + 2 * np.pi * source["sine_frequency"] * source["sine_amplitude"]
    acceleration = np.concatenate([[start_acceleration], column["source.alpha_out"][:-1]])
    np.testing.assert_allclose(column["coupling.phi_in"], np.cumsum((speed + 0.5 * acceleration * h) * h), rtol=1e-12)
    assert np.abs(column["coupling.phi_in"] - column["source.phi_out"]).max() < 1e-4


def test_a_cardan_joint_coupling_takes_the_source_acceleration_for_the_exact_c4(fmi2_dir, native_dir):
    """With CardanJoint as the coupling the package connects SpeedSource.alpha_out to its alpha_in,
    and the master run (the native variant, 0.2 s of the ramp and sine) gives alpha_out as (C4)
    with a_1 the source's acceleration of t_k at every step, the first included, within 1e-12 of
    its largest magnitude (the C and numpy sin and cos a few ulps apart)."""
    driveline = replace(system.driveline("CardanJoint"), stop_time=0.2)
    assert system.Connection(("source", "alpha_out"), ("coupling", "alpha_in")) in driveline.connections
    names = ["source.omega_out", "source.alpha_out", "coupling.phi_in", "coupling.alpha_out"]
    result = system.simulate(driveline, fmi2_dir, names, natives=native_dir)
    column = dict(zip(names, result[:, 1:].T))
    source = driveline.component("source").parameters
    start_acceleration = source["ramp_rate"] + 2 * np.pi * source["sine_frequency"] * source["sine_amplitude"]
    speed = np.concatenate([[source["omega_out_start"]], column["source.omega_out"][:-1]])
    acceleration = np.concatenate([[start_acceleration], column["source.alpha_out"][:-1]])
    beta = driveline.component("coupling").parameters["beta"]
    exact = kinematics.output_acceleration(column["coupling.phi_in"], beta, speed, acceleration)
    np.testing.assert_allclose(column["coupling.alpha_out"], exact, rtol=0.0, atol=1e-12 * np.abs(exact).max())


@pytest.mark.parametrize("package", PACKAGES)
@pytest.mark.parametrize("engine", ["libcosimpy", "ecospy"])
def test_importers_run_the_package_like_the_master(engine, package, request, master_result):
    """Same Jacobi scheme, same inputs, the Python FMUs or the native variant: every output
    within 1e-9 of its largest magnitude in the master's run of the Python system (measured: at
    most 7e-11, on delta_phi = phi_out - phi_in, a small difference of two angles near 180 rad;
    the same for both packages)."""
    if importlib.util.find_spec(engine) is None:
        pytest.skip(f"{engine} is not installed on this platform (pip install '.[interop]')")
    driveline_ssp = request.getfixturevalue(package)
    driveline = system.driveline()
    if engine == "ecospy":
        session = importers.ecos_session(driveline.step_size, ssp=driveline_ssp, parameter_set=driveline.name)
    else:
        session = importers.cosim_session(driveline.step_size, ssp=driveline_ssp)
    try:
        result = importers.record(session, len(master_result), driveline.step_size, driveline.outputs())
    finally:
        session.close()
    deviation = _deviation(result, master_result)
    assert max(deviation.values()) <= 1e-9, deviation
