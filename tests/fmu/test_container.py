"""An SSP package as one co-simulation FMU (``fmu_harness.runs.container``, FMU Manipulation Toolbox's
container): the same runs as the project's master, the package's bindings and a host's values applied, the
drive's step limit kept inside, what it cannot carry refused in one line, the same bytes from a rebuild."""

from __future__ import annotations

import dataclasses
import importlib.util
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy.validation import validate_fmu

from fmu_harness import container_command
from fmu_harness.packaging import archive, native
from fmu_harness.runs import container, ssp_package, system
from fmu_harness.runs.runner import StepRefused
from fmu_harness.runs.ssp_package import SspComponent, SspSystem

STOP = 0.1
# Agreement of the container with the master at the same step and order: the container runs the same FMUs by the
# same scheme with the same values in the same order (its components initialised in the order the master reads
# their outputs). On the rubber layout the powertrain at rest is in equilibrium to rounding only (accelerations
# of 1e-19 m/s2 and less), and those values go round the loops inside initialisation in the other order: the
# first rows differ by up to 1.6e-11 of a column's largest magnitude (Jacobi: rows 1-4, Gauss-Seidel: row 1),
# then the launch's motion rounds them away and every later row is equal bit for bit (measured over the whole
# 4 s launch with the housings moving). AGREEMENT bounds the first rows; the last row must be equal. In the
# toolbox's own order the joints started from the package's bound bend angle, a few units in the last place from
# the mounts' (the runs parted by 5e-8 relative after 2 s, on the linear layout).
AGREEMENT = 1e-9
#: Another host's run of the container against fmpy's: 1e-9 of a column's largest magnitude leaves room for a host
#: that sums its time differently (the motor's ramp would differ in the last bits of t, 1e-16 relative).
HOST_AGREEMENT = 1e-9


@pytest.fixture(scope="module")
def packages(native_dir: Path) -> dict[str, Path]:
    """The launch's and the driveline's native packages (every component has a native FMU)."""
    return {made.name: system.write_ssp(made, native_dir, native_dir) for made in system.systems()}


def _fmus(package: Path, folder: Path) -> tuple[SspSystem, dict[str, Path]]:
    read = ssp_package.read(package)
    with zipfile.ZipFile(package) as archive_file:
        archive_file.extractall(folder)
    return read, {c.name: folder / c.source for c in read.components}


def _compare(package: Path, tmp_path: Path, step: float, sequential: bool,
             changes: dict[tuple[str, str], float] | None = None) -> None:
    """The container of ``package`` against the project's master over STOP: every Real output."""
    read, fmus = _fmus(package, tmp_path / "package")
    fmu = container.build(read, fmus, tmp_path / "container.fmu", step, sequential=sequential)
    changes = changes or {}
    bound = [dataclasses.replace(c, parameters={**c.parameters, **{v: x for (n, v), x in changes.items()
                                                                     if n == c.name}}) for c in read.components]
    outputs = [f"{c.name}.{v.get('name')}" for c in read.components
               for v in container.model_descriptions(read, fmus)[c.name].iter("ScalarVariable")
               if v.get("causality") == "output" and v.find("Real") is not None]
    order = [c.name for c in read.components] if sequential else None
    expected = system.run_jacobi(fmus, {c.name: c.parameters for c in bound}, read.connections, STOP, step, outputs,
                                 order=order)
    found = container.run(fmu, {f"{n}.{v}": x for (n, v), x in changes.items()}, STOP, step, outputs)
    assert found.shape == expected.shape
    scale = np.maximum(np.abs(expected).max(axis=0), 1e-300)
    worst = np.abs(found - expected).max(axis=0) / scale
    assert worst.max() <= AGREEMENT, (["time", *outputs][int(np.argmax(worst))], worst.max())
    last = [name for name, equal in zip(["time", *outputs], found[-1] == expected[-1]) if not equal]
    assert last == [], last[:5]


@pytest.mark.parametrize("sequential", [False, True], ids=["jacobi", "gauss-seidel"])
def test_the_launch_container_runs_as_the_master(packages, tmp_path, sequential):
    """All 200 outputs of the launch over 0.1 s at 1e-4 s, Jacobi and Gauss-Seidel in the package's order."""
    _compare(packages["VehicleLaunch"], tmp_path, 1e-4, sequential)


def test_the_driveline_container_runs_as_the_master(packages, tmp_path):
    """The driveline package (speed source, tripod joint, critical speeds) at its 1 ms step, from the first
    row: the container initialises the components in the order of their links, each leaving initialisation
    before its outputs feed the next; the master reads the outputs inside initialisation, where every FMU
    computes them from what has been set so far, so the watcher starts at the coupling's initial speed in
    both."""
    _compare(packages["Driveline"], tmp_path, 1e-3, False)


def test_a_hosts_values_replace_the_packages_bindings(packages, tmp_path):
    """A host sets the launch's torque, a halfshaft's design bend and a joint's friction: the run is the master's
    with those bindings (the toolbox re-applied a bound input's start value on entering initialisation, which
    undid a host's value: the joints' bends were such inputs before PowertrainMounts fed them)."""
    changes = {("motor", "T_level"): 200.0, ("mounts", "beta_design_left"): 0.25, ("joint_right", "mu"): 0.09}
    _compare(packages["VehicleLaunch"], tmp_path, 1e-4, False, changes)


def test_the_drives_step_limit_holds_inside(packages, tmp_path):
    """At 1.2 ms, above the drive's limit for any order, the container's first step fails with the drive's
    own reason."""
    read, fmus = _fmus(packages["VehicleLaunch"], tmp_path / "package")
    fmu = container.build(read, fmus, tmp_path / "coarse.fmu", 1.2e-3)
    with pytest.raises(StepRefused) as refused:
        container.run(fmu, {}, 2.4e-3, 1.2e-3, ["drive.v_x"])
    assert "drive.fmu: communication step 0.0012 s is above 0.00104 s" in str(refused.value)


def test_the_container_is_a_valid_fmu_and_the_same_bytes_again(packages, tmp_path):
    """fmpy validate finds nothing; two builds are equal byte for byte (sorted entries at one fixed time, no
    build time, a token from the contents); each exposed variable carries its component's unit; the
    package's bindings are the start values; the embedded FMUs travel with their binaries and descriptions but
    without their documentation and sources, the container with the package's page and the licence."""
    read, fmus = _fmus(packages["VehicleLaunch"], tmp_path / "package")
    first = container.build(read, fmus, tmp_path / "first.fmu", 1e-4)
    second = container.build(read, fmus, tmp_path / "second.fmu", 1e-4)
    assert first.read_bytes() == second.read_bytes()
    assert validate_fmu(str(first)) == []
    with zipfile.ZipFile(first) as built:
        assert {entry.date_time for entry in built.infolist()} == {archive.FIXED_TIME}
        description = built.read("modelDescription.xml")
        names = built.namelist()
    embedded = {name.split("/")[1] for name in names if name.startswith("resources/") and name.count("/") > 1}
    assert len(embedded) == len(read.components)
    assert {f"resources/{index}/modelDescription.xml" for index in embedded} <= set(names)
    assert not [name for name in names if "/documentation/" in name or "/sources/" in name]
    assert {"documentation/index.html", "documentation/licenses/LICENSE.txt"} <= set(names)
    assert b"generationDateAndTime" not in description
    from fmpy import read_model_description

    variables = {v.name: v for v in read_model_description(str(first)).modelVariables}
    assert variables["drive.v_x"].unit == "m/s" and variables["mounts.beta_design_left"].unit == "rad"
    assert float(variables["motor.T_level"].start) == 140.0
    assert float(variables["mounts.beta_design_left"].start) == pytest.approx(math.radians(8.0), rel=1e-15)
    assert not [v for v in variables.values() if v.causality == "local"]


def test_the_launchs_fmu_shows_its_selection_and_keeps_the_rest_readable(packages, native_dir, tmp_path):
    """The shipped launch FMU's outputs are the launch's selection (everything the shudder map reads among them),
    what fmpy records by default; every other output is a local variable of the same run bit for bit, FMI 2.0
    and 3.0 valid; a name that is no output is refused in one line."""
    from fmpy import read_model_description

    from fmu_harness import shudder_map

    shown = system.vehicle_launch().shown
    assert {shudder_map.SHAFT, shudder_map.SIGNAL, shudder_map.LATERAL, shudder_map.YAW} <= set(shown)
    read, fmus = _fmus(packages["VehicleLaunch"], tmp_path / "package")
    every = container.build(read, fmus, tmp_path / "every.fmu", 1e-4)
    selected = container.build(read, fmus, tmp_path / "selected.fmu", 1e-4, shown=shown)
    variables = read_model_description(str(selected)).modelVariables
    assert sorted(v.name for v in variables if v.causality == "output") == sorted(shown)
    hidden = [v.name for v in read_model_description(str(every)).modelVariables
              if v.causality == "output" and v.type == "Real" and v.name not in shown]
    assert len(hidden) > 150 and {v.name for v in variables if v.causality == "local"} >= set(hidden)
    names = [*shown, *hidden]
    assert np.array_equal(container.run(selected, {}, 0.01, 1e-4, names), container.run(every, {}, 0.01, 1e-4, names))
    assert validate_fmu(str(selected)) == []
    fmi3 = {c.name: native.fmu_path(native_dir, c.model, "3") for c in system.vehicle_launch().components}
    three = container.build(read, fmi3, tmp_path / "three.fmu", 1e-4, fmi_version=3, shown=shown)
    assert validate_fmu(str(three)) == []
    with pytest.raises(container.ContainerRefused) as refused:
        container.build(read, fmus, tmp_path / "wrong.fmu", 1e-4, shown=("drive.v_x", "drive.nope"))
    assert str(refused.value) == "VehicleLaunch: no output drive.nope to show"


def test_the_fmi3_container_runs_as_the_fmi2_one(packages, native_dir, tmp_path):
    """The FMI 3.0 container of the native FMI 3.0 FMUs gives the FMI 2.0 container's run bit for bit."""
    read, fmus = _fmus(packages["VehicleLaunch"], tmp_path / "package")
    models = {c.name: c.model for c in system.vehicle_launch().components}
    fmi3 = {name: native.fmu_path(native_dir, model, "3") for name, model in models.items()}
    outputs = ["drive.v_x", "drive.T_load_left", "mounts.pitch_ddot"]
    two = container.run(container.build(read, fmus, tmp_path / "two.fmu", 1e-4), {}, 0.02, 1e-4, outputs)
    three = container.run(container.build(read, fmi3, tmp_path / "three.fmu", 1e-4, fmi_version=3), {}, 0.02, 1e-4,
                          outputs)
    assert np.array_equal(two, three)


def test_what_the_container_cannot_carry_is_refused_in_one_line(packages, fmu_path, tmp_path):
    """Python FMUs (they need Python in the host), a binding of no variable, a connection of two inputs:
    each named, in one line, before the toolbox is called."""
    read, fmus = _fmus(packages["Driveline"], tmp_path / "package")
    python = SspSystem("P", [SspComponent("source", "resources/SpeedSource.fmu")], [], 1.0, None)
    with pytest.raises(container.ContainerRefused) as refused:
        container.build(python, {"source": fmu_path("SpeedSource")}, tmp_path / "p.fmu", 1e-3)
    assert "the Python FMU of source (SpeedSource.fmu), which need Python in the host" in str(refused.value)
    broken = dataclasses.replace(read, components=[dataclasses.replace(read.components[0], parameters={"nope": 1.0}),
                                                   *read.components[1:]],
                                 connections=[*read.connections, (("coupling", "beta"), ("critical", "omega_in"))])
    with pytest.raises(container.ContainerRefused) as refused:
        container.build(broken, fmus, tmp_path / "b.fmu", 1e-3)
    message = str(refused.value)
    assert "\n" not in message and "parameter source.nope: SpeedSource.fmu has no such variable" in message
    assert "connection coupling.beta -> critical.omega_in: coupling.beta is no output" in message


def test_the_command_refuses_a_step_above_the_drives_limit_in_one_line(packages, tmp_path, capsys):
    with pytest.raises(SystemExit) as ended:
        container_command.main([str(packages["VehicleLaunch"]), "--step", "5e-4", "--out", str(tmp_path / "x.fmu")])
    assert ended.value.code == 2
    error = capsys.readouterr().err
    assert len(error.splitlines()) == 1 and "drive (VehicleDriveline): --step 0.0005 s is above 0.000415 s" in error
    container_command.main([str(packages["VehicleLaunch"]), "--step", "5e-4", "--gauss-seidel",
                            "--out", str(tmp_path / "x.fmu")])
    assert (tmp_path / "x.fmu").is_file()


@pytest.mark.parametrize("engine", ["libcosimpy", "ecospy"])
def test_libcosim_and_ecos_run_the_container_as_fmpy_does(engine, packages, tmp_path):
    """The launch's container as one FMU in libcosim and in Ecos over 20 ms at its step: fmpy's run within
    HOST_AGREEMENT (measured: equal bit for bit; both call the same doStep with the same values)."""
    if importlib.util.find_spec(engine) is None:  # not imported here: Ecos needs its tbb loaded first
        pytest.skip(f"{engine} is not installed (pip install '.[interop]')")
    from fmu_harness.checks import importers

    read, fmus = _fmus(packages["VehicleLaunch"], tmp_path / "package")
    fmu = container.build(read, fmus, tmp_path / "launch.fmu", 1e-4)
    outputs = ["drive.v_x", "drive.T_load_left", "drive.T_load_right", "mounts.pitch_ddot"]
    expected = container.run(fmu, {}, 0.02, 1e-4, outputs)
    session = {"libcosimpy": importers.cosim_session, "ecospy": importers.ecos_session}[engine](
        1e-4, fmus={"launch": fmu})
    try:
        found = importers.record(session, 200, 1e-4, [f"launch.{name}" for name in outputs])
    finally:
        session.close()
    scale = np.abs(expected).max(axis=0)
    assert (np.abs(found - expected).max(axis=0) <= HOST_AGREEMENT * scale).all()
