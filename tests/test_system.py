"""The driveline system as an SSP package: its structure, and the same results from our fmpy
master, libcosim and Ecos."""

from __future__ import annotations

import importlib.resources
import importlib.util
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from fmpy import read_model_description

from driveline.catalog import MODELS
from fmu_harness import importers, system

SSD = {"ssd": system.SSD, "ssv": system.SSV}


@pytest.fixture(scope="module")
def driveline_ssp(fmu_dir: Path) -> Path:
    return system.write_ssp(system.driveline(), fmu_dir)


@pytest.fixture(scope="module")
def master_result(fmu_dir: Path) -> np.ndarray:
    return system.simulate(system.driveline(), fmu_dir)


def test_the_system_has_the_source_the_coupling_and_the_watcher_when_there_is_one():
    models = {c.model for c in system.driveline().components}
    assert {"SpeedSource", "TripodCoupling"} <= models
    assert (system.WATCHER in models) == (system.WATCHER in MODELS)


def test_system_structure_is_valid_ssp_1_0(driveline_ssp):
    """Against the SSP 1.0 schemas that pyssp-standard ships."""
    if importlib.util.find_spec("pyssp_standard") is None or importlib.util.find_spec("xmlschema") is None:
        pytest.skip("pyssp-standard is not installed on this platform (pip install '.[interop]')")
    import xmlschema

    schema = xmlschema.XMLSchema(str(importlib.resources.files("pyssp_standard") / "resources" / "SystemStructureDescription.xsd"))
    with zipfile.ZipFile(driveline_ssp) as archive:
        schema.validate(archive.read("SystemStructure.ssd").decode())


def test_package_wires_existing_variables_and_binds_parameters(driveline_ssp, tmp_path):
    with zipfile.ZipFile(driveline_ssp) as archive:
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


def test_the_master_feeds_the_coupling_with_the_source_speed(master_result):
    driveline = system.driveline()
    outputs = driveline.outputs()
    column = {name: master_result[:, i + 1] for i, name in enumerate(outputs)}
    h = driveline.step_size
    # Jacobi: the coupling holds the source speed of t_k over the step to t_(k+1)
    held = np.concatenate([[driveline.component("source").parameters["omega_start"]], column["source.omega"][:-1]])
    np.testing.assert_allclose(column["coupling.phi_in"], np.cumsum(held * h), rtol=1e-12)


@pytest.mark.parametrize("engine", ["libcosimpy", "ecospy"])
def test_importers_run_the_package_like_the_master(engine, driveline_ssp, master_result):
    """Same FMUs, same Jacobi scheme, same inputs: every output within 1e-9 of its largest
    magnitude (measured: at most 7e-11, on delta_phi = phi_out - phi_in, a small difference of
    two angles near 180 rad)."""
    if importlib.util.find_spec(engine) is None:
        pytest.skip(f"{engine} is not installed on this platform (pip install '.[interop]')")
    driveline = system.driveline()
    if engine == "ecospy":
        session = importers.ecos_session(driveline.step_size, ssp=driveline_ssp, parameter_set=driveline.name)
    else:
        session = importers.cosim_session(driveline.step_size, ssp=driveline_ssp)
    try:
        result = importers.record(session, len(master_result), driveline.step_size, driveline.outputs())
    finally:
        session.close()
    scale = np.maximum(np.abs(master_result).max(axis=0), 1e-300)
    names = ["time", *driveline.outputs()]
    # a_plunger_sum cancels three plunger accelerations of ~1e3 m/s^2 down to ~1e-2: its round-off
    # follows the terms (F_plunger1 / m_plunger), not the sum (measured 4e-9 of the sum)
    mass = next(v.start for v in driveline.component("coupling").spec.variables if v.name == "m_plunger")
    scale[names.index("coupling.a_plunger_sum")] = np.abs(master_result[:, names.index("coupling.F_plunger1")]).max() / mass
    deviation = np.abs(result - master_result).max(axis=0) / scale
    assert deviation.max() <= 1e-9, dict(zip(names, deviation))
