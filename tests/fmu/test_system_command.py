"""``driveline-fmus system``: any SSP package run to a CSV file by the project's master (Jacobi or
Gauss-Seidel), libcosim or Ecos, with parameters set from the command line, and every mistake one line
before any work."""

from __future__ import annotations

import csv
import dataclasses
import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description

from fmu_harness import system_command
from fmu_harness.packaging import native
from fmu_harness.runs import system

STEP, STOP = 1e-3, 0.05


@pytest.fixture(scope="module")
def native_ssp(fmi2_dir: Path, native_dir: Path) -> Path:
    return system.write_ssp(system.driveline(), fmi2_dir, native_dir)


def _run(package: Path, out: Path, *options: str) -> tuple[list[str], np.ndarray]:
    system_command.main([str(package), "--stop-time", str(STOP), "--step", str(STEP), "--out", str(out), *options])
    with out.open() as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array(rows[1:], dtype=float)


def _master(fmi2_dir: Path, native_dir: Path, **coupling: float) -> np.ndarray:
    """The package's system run by :func:`system.simulate` directly, the coupling's bindings changed."""
    driveline = system.driveline()
    components = tuple(dataclasses.replace(c, parameters={**c.parameters, **coupling}) if c.name == "coupling" else c
                       for c in driveline.components)
    changed = dataclasses.replace(driveline, components=components, stop_time=STOP, step_size=STEP)
    return system.simulate(changed, fmi2_dir, natives=native_dir)


def test_every_output_of_every_component_is_a_column_headed_with_its_unit(native_ssp, tmp_path, fmi2_dir, native_dir):
    """Time first, then each Real output of each component in the order of the package and of the FMU's
    model description, ``Component.variable [unit]``; a row at t = 0 (the outputs after initialisation), then
    the master's rows, bit for bit."""
    header, values = _run(native_ssp, tmp_path / "run.csv")
    expected = ["time [s]"]
    for component in system.driveline().components:
        path = native.fmu_path(native_dir, component.model)
        for v in read_model_description(str(path)).modelVariables:
            if v.causality == "output" and v.type == "Real":
                unit = v.unit or (v.declaredType and v.declaredType.unit) or "1"
                expected.append(f"{component.name}.{v.name} [{unit}]")
    assert header == expected
    assert values[0, 0] == 0.0 and values[1, 0] == STEP
    np.testing.assert_array_equal(values[1:], _master(fmi2_dir, native_dir))


def test_a_parameter_set_on_the_command_line_reaches_the_run(native_ssp, tmp_path, fmi2_dir, native_dir):
    """``--set coupling.T_load=200`` (bound in the package at 150): the run is the master's with 200."""
    _, values = _run(native_ssp, tmp_path / "run.csv", "--set", "coupling.T_load=200")
    np.testing.assert_array_equal(values[1:], _master(fmi2_dir, native_dir, T_load=200.0))


@pytest.mark.parametrize("engine", ["libcosim", "ecos"])
def test_the_engines_give_the_masters_results(engine, native_ssp, tmp_path, fmi2_dir, native_dir):
    """The same Jacobi scheme in libcosim and Ecos, with a parameter set: every column within 1e-9 of its
    largest magnitude (the importer matrix's tolerance; measured 7.7e-12 over 0.2 s), the sum of the
    plunger accelerations of its terms' magnitude."""
    if importlib.util.find_spec(f"{engine}py") is None:
        pytest.skip(f"{engine}py is not installed on this platform (pip install '.[interop]')")
    header, values = _run(native_ssp, tmp_path / "run.csv", "--engine", engine, "--set", "coupling.T_load=200")
    values = values[values[:, 0] > 0.0]  # Ecos's row at t = 0 (libcosim initialises in its first step)
    reference = _master(fmi2_dir, native_dir, T_load=200.0)
    scale = np.maximum(np.abs(reference).max(axis=0), 1e-300)
    # a_plunger_sum cancels three plunger accelerations down to 1e-7 of them: its round-off is the terms'
    mass = system.driveline().component("coupling").spec["m_plunger"].start
    scale[header.index("coupling.a_plunger_sum [m/s2]")] = np.abs(
        reference[:, header.index("coupling.F_plunger1 [N]")]).max() / mass
    assert (np.abs(values - reference).max(axis=0) / scale).max() <= 1e-9


def test_gauss_seidel_runs_the_launch_in_the_packages_order_at_a_step_jacobi_refuses(fmi2_dir, native_dir, tmp_path,
                                                                                      capsys):
    """``VehicleLaunch.ssp`` at 8e-4 s, above the drive's Jacobi limit (4.15e-4 s): the Jacobi master
    refuses it in one line naming the way out; ``--engine gauss-seidel`` runs it, every column bit for
    bit the master's in the package's order (:data:`system.LAUNCH_ORDER`)."""
    package = system.write_ssp(system.vehicle_launch(), fmi2_dir, native_dir)
    step, stop = 8e-4, 0.04
    arguments = [str(package), "--stop-time", str(stop), "--step", str(step), "--out", str(tmp_path / "run.csv")]
    with pytest.raises(SystemExit) as exit_status:
        system_command.main(arguments)
    err = capsys.readouterr().err
    assert exit_status.value.code == 2 and err.count("\n") == 1 and err.rstrip().endswith("or the Gauss-Seidel master")
    system_command.main([*arguments, "--engine", "gauss-seidel", "--output-interval", str(step)])
    with (tmp_path / "run.csv").open() as handle:
        header, *rows = list(csv.reader(handle))
    launch = dataclasses.replace(system.vehicle_launch(), stop_time=stop, step_size=step)
    outputs = [column.split(" [")[0] for column in header[1:]]
    expected = system.simulate(launch, fmi2_dir, outputs, natives=native_dir, order=system.LAUNCH_ORDER)
    np.testing.assert_array_equal(np.array(rows[1:], dtype=float), expected)


@pytest.mark.parametrize(("options", "words"), [
    (["--set", "coupling.T_load"], "write Component.name=value"),
    (["--set", "wheel.T_load=1"], "no component 'wheel' (it has source, coupling, critical)"),
    (["--set", "coupling.T_nope=1"], "has no variable 'T_nope'"),
    (["--set", "coupling.T_in=1"], "coupling.T_in is an output, not a parameter"),
    (["--set", "coupling.omega_in=1"], "it is a connected input"),
    (["--set", "coupling.T_load=abc"], "'abc' is no Real value"),
    (["--set", "coupling.kinematics=0.5"], "'0.5' is no Integer value"),
    (["--step", "0"], "need 0 < step <= stop time"),
    (["--step", "-2e-4"], "--step -0.0002 and --stop-time"),
    (["--step", "0.003"], "no whole number of steps"),
    (["--engine", "dymola"], "invalid choice: 'dymola'"),
    (["--engine", "model-exchange", "--rtol", "1e-20"], "need 1e-13 <= rtol <= 1e-2"),
    (["--rtol", "1e-6"], "--rtol is the model-exchange engine's; --engine master steps at --step"),
])
def test_a_mistake_is_one_line_and_status_2_before_any_work(options, words, native_ssp, tmp_path, capsys):
    out = tmp_path / "run.csv"
    with pytest.raises(SystemExit) as exit_status:
        _run(native_ssp, out, *options)
    err = capsys.readouterr().err
    assert exit_status.value.code == 2
    assert err.count("\n") == 1 and words in err and "error" in err
    assert not out.exists()


def test_model_exchange_of_python_fmus_is_one_line(fmi2_dir, tmp_path, capsys):
    """The Python package (co-simulation only): the engine is refused before any FMU is instantiated,
    naming each component whose FMU has no Model Exchange interface."""
    package = system.write_ssp(system.driveline(), fmi2_dir)
    with pytest.raises(SystemExit) as exit_status:
        _run(package, tmp_path / "run.csv", "--engine", "model-exchange")
    err = capsys.readouterr().err
    assert exit_status.value.code == 2 and err.count("\n") == 1
    assert ("model-exchange needs every FMU's Model Exchange interface; source (SpeedSource.fmu), coupling "
            "(TripodCoupling.fmu), critical (CriticalSpeeds.fmu) have none") in err
    assert not (tmp_path / "run.csv").exists()


def test_an_existing_folder_as_out_is_refused_before_the_run(native_ssp, tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_status:
        system_command.main([str(native_ssp), "--stop-time", "100", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert exit_status.value.code == 2 and err.count("\n") == 1 and f"--out {tmp_path}: a folder, not a file" in err


@pytest.mark.parametrize("engine, module", system_command.ENGINE_EXTRAS.items())
def test_an_engine_without_its_extra_names_it_in_one_line(engine, module, native_ssp, tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, module, None)
    with pytest.raises(SystemExit) as exit_status:
        _run(native_ssp, tmp_path / "run.csv", "--engine", engine)
    message = str(exit_status.value.code)
    assert message.count("\n") == 0 and f"--engine {engine} needs {module}" in message and "[interop]" in message
    assert not (tmp_path / "run.csv").exists()


@pytest.mark.parametrize("package", ["missing.ssp", "not_a_package.ssp"])
def test_a_file_that_is_no_package_is_one_line(package, tmp_path, capsys):
    (tmp_path / "not_a_package.ssp").write_text("time,x\n0,1\n")
    with pytest.raises(SystemExit) as exit_status:
        system_command.main([str(tmp_path / package), "--stop-time", "1"])
    err = capsys.readouterr().err
    assert exit_status.value.code == 2 and err.count("\n") == 1 and package in err


@pytest.mark.parametrize("engine", system_command.ENGINES)
def test_a_start_value_the_fmu_refuses_stops_every_engine_naming_the_component(engine, native_ssp, tmp_path,
                                                                               capsys):
    """A bend beyond beta_max, which the coupling refuses at ExitInitializationMode (libcosim would
    abort the process on the native FMU's Error): whatever the engine, the run stops before it
    starts, in one line naming the component, its model and the FMU's reason, status 1: the words and status of
    ``driveline-fmus check`` (tests/project/test_cli.py)."""
    with pytest.raises(SystemExit) as exit_status:
        _run(native_ssp, tmp_path / "run.csv", "--engine", engine, "--set", "coupling.beta=1.0")
    err = capsys.readouterr().err
    assert exit_status.value.code == 1 and err.count("\n") == 1
    assert ": refused: coupling (TripodCoupling): input beta = 57.2958 deg must not exceed beta_max = 45 deg" in err
    assert not (tmp_path / "run.csv").exists()


def test_rows_every_output_interval_to_csv_or_parquet(native_ssp, tmp_path, fmi2_dir, native_dir):
    """``--output-interval 3e-3`` at 1 ms steps: the row at t = 0, then every third row of the master's run,
    the last (at 50 ms, no whole number of intervals) kept; the same values to Parquet; an interval of no
    whole number of steps is one line. The default at a 1 ms step is every step (the first interval at or
    above 1 ms)."""
    every = _master(fmi2_dir, native_dir)
    header, values = _run(native_ssp, tmp_path / "run.csv", "--output-interval", "3e-3")
    assert values[0, 0] == 0.0
    np.testing.assert_array_equal(values[1:], np.vstack([every[2::3], every[-1:]]))
    pyarrow_parquet = pytest.importorskip("pyarrow.parquet")
    system_command.main([str(native_ssp), "--stop-time", str(STOP), "--step", str(STEP), "--out",
                         str(tmp_path / "run.parquet"), "--output-interval", "3e-3"])
    table = pyarrow_parquet.read_table(tmp_path / "run.parquet")
    assert table.column_names == header
    np.testing.assert_array_equal(np.column_stack([table.column(n).to_numpy() for n in header]), values)
    assert system_command.steps_per_row(None, STEP) == 1 and system_command.steps_per_row(None, 1e-4) == 10
    with pytest.raises(system_command.UsageError, match="--output-interval 0.0015: need a whole number of steps"):
        system_command.steps_per_row(1.5e-3, STEP)
