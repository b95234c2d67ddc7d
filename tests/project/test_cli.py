"""The console script as a user meets it, each command in a process of its own: a mistake ends in
one line and a non-zero exit before any work starts, help needs no optional package, a sweep whose
every run failed says why and fails, long work shows its progress."""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from fmu_harness import cli
from fmu_harness.checks import interop

SCRIPT = Path(sys.executable).with_name("driveline-fmus.exe" if sys.platform == "win32" else "driveline-fmus")
OPTIONAL = ("pyarrow", "distributed", "dask", "libcosimpy", "ecospy", "fmu_manipulation_toolbox")


def driveline_fmus(*arguments: str, cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([str(SCRIPT), *arguments], capture_output=True, text=True, timeout=600, cwd=cwd,
                          env={**os.environ, **(env or {})})


def assert_one_line_mistake(run: subprocess.CompletedProcess, *words: str) -> None:
    assert run.returncode != 0 and run.stdout == ""
    assert len(run.stderr.splitlines()) == 1 and "Traceback" not in run.stderr, run.stderr
    assert all(word in run.stderr for word in words), run.stderr


@pytest.mark.parametrize("arguments, words", [
    (["biuld"], ["invalid choice: 'biuld'"]),
    (["build", "Tripod"], ["no model 'Tripod'", "did you mean TripodCoupling"]),
    (["sweep", "--grid", "beta=0.1", "--workers", "-2"], ["--workers", "at least 1"]),
    (["sweep", "--grid", "beta=0.1", "--turns", "-1"], ["turns must be a whole number of at least 1, got -1"]),
    (["sweep", "--grid", "beta=0.1", "--steps-per-turn", "0"], ["steps per turn must be", "got 0"]),
    (["sweep", "--grid", "beta=0.1", "--step", "nan"], ["the step must be a finite positive", "got nan"]),
    (["sweep", "--grid", "beta=0.1", "--duration", "-1"], ["the duration must be a finite positive"]),
    (["sweep", "--grid", "beta"], ["expected name=v1,v2"]),
    (["sweep", "--grid", "beta=0.1", "--models", "nowhere"], ["no folder nowhere", "driveline-fmus build"]),
    (["interop", "--models", "nowhere"], ["no built FMU in nowhere", "driveline-fmus build"]),
    (["sweep", "--grid", "beta=0.1", "--step", "-2e-4"], ["the step must be a finite positive", "got -0.0002"]),
    (["sweep", "--grid", "beta=0.1", "--out", "x.xlsx"], ["--out", "x.xlsx: write a .parquet or a .csv file"]),
    (["map", "--out", "map.xlsx"], ["--out", "map.xlsx: write a .parquet or a .csv file"]),
    (["map", "--duration", "1"], ["--duration 1 s", "less than the 2 revolutions", "at least 1.4 s"]),
    (["map", "--phases", "0"], ["--phases must be at least 1, got 0"]),
    (["map", "--joints", "plain,triple"], ["--joints: no joint type 'triple' (choose from plain, single, double)"]),
    (["map", "--joints", "double,double"], ["--joints double,double: a type named twice"]),
    (["map", "--envelope", "envelope.xlsx"], ["--envelope", "envelope.xlsx: write a .parquet or a .csv file"]),
])
def test_a_mistake_is_one_line_and_a_non_zero_exit(arguments, words, tmp_path):
    assert_one_line_mistake(driveline_fmus(*arguments, cwd=tmp_path), *words)


@pytest.mark.parametrize("arguments, words", [
    (["--model", "Tripod"], ["no FMU", "Tripod.fmu", "the FMUs there:", "TripodCoupling"]),
    (["--layout", "nope.toml"], ["nope.toml", "No such file"]),
    (["--grid", "phi_out=1"], ["phi_out: no parameter or input of TripodCoupling"]),
    (["--grid", "beta=0:1:0"], ["no points"]),
    (["--grid", "beta=0.9,1.0"], ["sweep: refused: every point, none run: input beta = 51.5662 deg must not exceed "
                                  "beta_max = 45 deg (and 1 more reason)"]),
])
def test_a_sweep_is_refused_before_its_cluster_starts(arguments, words, tripod_fmu, tmp_path):
    arguments = ["--grid", "beta=0.1", *arguments] if "--grid" not in arguments else arguments
    run = driveline_fmus("sweep", *arguments, "--models", str(tripod_fmu.parent), cwd=tmp_path)
    assert_one_line_mistake(run, *words)


def test_check_refuses_in_the_words_and_status_of_system(tripod_fmu, tmp_path):
    """The words and status ``driveline-fmus system`` ends with for the same value
    (tests/fmu/test_system_command.py): ``refused:``, status 1."""
    run = driveline_fmus("check", str(tripod_fmu), "beta=0.9", cwd=tmp_path)
    assert_one_line_mistake(run, "driveline-fmus check: refused: TripodCoupling (TripodCoupling): input beta = 51.5662 "
                                 "deg must not exceed beta_max = 45 deg")
    assert run.returncode == 1


def test_help_shows_the_defaults(tmp_path):
    shown = " ".join(driveline_fmus("sweep", "--help", cwd=tmp_path).stdout.split())
    assert "steps of one turn of the run (default 360)" in shown and "local cluster size (default" in shown
    assert "folder of built FMUs (default models)" in shown


def test_run_outside_a_built_folder_tells_a_wheel_user_what_to_do(tmp_path):
    run = driveline_fmus("run", cwd=tmp_path)
    assert_one_line_mistake(run, "no native FMU", "`driveline-fmus build`", "zig")
    assert "build_fmu.py" not in run.stderr and "C compiler" not in run.stderr


def test_a_sweep_whose_every_run_failed_names_the_reasons_and_fails(tripod_fmu, tmp_path):
    """One point refused before it runs (r < 0 breaks a declared bound), two that fail on the
    workers (no whole turn at omega_in = 0)."""
    run = driveline_fmus("sweep", "--grid", "r=-0.01,0.02,0.026", "omega_in=0", "--models", str(tripod_fmu.parent),
                         "--workers", "1", "--steps-per-turn", "4", "--out", "sweep.csv", cwd=tmp_path)
    assert run.returncode == 1 and "Traceback" not in run.stderr
    assert "3 runs, 3 failed" in run.stdout and (tmp_path / "sweep.csv").is_file()
    with (tmp_path / "sweep.csv").open(newline="") as table:  # the units of the points' variables, none on text
        assert next(csv.reader(table))[:5] == ["r [m]", "omega_in [rad/s]", "status", "reason", "phi_in_min [rad]"]
    reasons = [line for line in run.stderr.splitlines() if " failed: " in line]
    assert reasons[0].startswith("  2 failed: ValueError: a run of whole input turns needs a finite non-zero omega_in")
    assert reasons[1] == "  1 failed: parameter r = -10 mm must be positive" and len(reasons) == 2
    assert "sweep [1/2]" in run.stderr and "sweep [2/2]" in run.stderr
    assert run.stderr.splitlines()[-1] == "driveline-fmus sweep: every run failed"


def _without_optional_packages(folder: Path) -> dict[str, str]:
    """An environment in which the optional packages fail to import, as on a default install."""
    for name in OPTIONAL:
        (folder / name).mkdir(parents=True)
        message = f"No module named {name!r}"
        (folder / name / "__init__.py").write_text(f"raise ModuleNotFoundError({message!r}, name={name!r})\n")
    return {"PYTHONPATH": os.pathsep.join([str(folder), os.environ.get("PYTHONPATH", "")])}


@pytest.mark.parametrize("command", [*cli.COMMANDS, None])
def test_help_needs_no_optional_package(command, tmp_path):
    run = driveline_fmus(*[command] * bool(command), "--help", cwd=tmp_path,
                         env=_without_optional_packages(tmp_path / "stubs"))
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith(f"usage: driveline-fmus {command or ''}".rstrip())


def test_a_sweep_without_its_extra_names_it_in_one_line(tripod_fmu, tmp_path):
    run = driveline_fmus("sweep", "--grid", "beta=0.1", "--models", str(tripod_fmu.parent), cwd=tmp_path,
                         env=_without_optional_packages(tmp_path / "stubs"))
    assert_one_line_mistake(run, "needs pyarrow", "pip install 'driveline-fmus[sweep]'")


def test_the_importer_matrix_shows_its_progress(fmu_path, tmp_path):
    models = tmp_path / "models"
    models.mkdir()
    shutil.copy(fmu_path("SpeedSource"), models)
    run = driveline_fmus("interop", "--models", str(models), cwd=tmp_path)
    assert run.returncode == 0, run.stderr[-2000:]
    shown = [line for line in run.stderr.splitlines() if line.startswith("importer matrix [")]
    total = len(interop.IMPORTERS)
    assert shown[0] == f"importer matrix [1/{total}] SpeedSource Python FMI 2.0 in {interop.IMPORTERS[0].name}"
    assert shown[-1] == f"importer matrix [{total}/{total}] SpeedSource Python FMI 2.0 in {interop.IMPORTERS[-1].name}"
    assert "| `SpeedSource` | Python | 2.0 |" in run.stdout
