"""The main job end to end on freshly built FMUs: it exits 0, its CSV files start with the time or
the swept variable and head every column with its unit, repeat no row, and its Campbell diagram
reaches every critical speed; its Python FMUs' process exits 0 every time."""

from __future__ import annotations

import csv
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from driveline.catalog import MODELS
from driveline.mounts.model import PowertrainMountsModel
from driveline.mounts.rigid_body import COORDINATES
from fmu_harness.checks import python_fmu_check
from fmu_harness.runs.runner import FmuInstance
from fmu_harness.runs import system
from fmu_harness.studies import critical_speed_study, launch_study, order_tracking
from fmu_harness.runs.result_table import table_errors
from fmu_harness.packaging import native

FIRST_COLUMNS = {"time [s]", "beta [deg]", "mode [1]"}  # time, the swept bend angle, the mode number
HEADED = re.compile(r"^\w+( \w+)* \[[^\]]+\]$")  # name [unit]
RUNS = 20


@pytest.fixture(scope="module")
def models(fmu_path, fmi2_dir, native_dir, tmp_path_factory) -> Path:
    """A models folder as the build leaves it: the FMI 2.0 Python FMUs, the native ones and the native
    launch package in native/."""
    system.write_ssp(system.vehicle_launch(), fmi2_dir, native_dir)
    folder = tmp_path_factory.mktemp("main_job_models")
    for name in MODELS:
        (folder / f"{name}.fmu").symlink_to(fmu_path(name))
    (folder / "native").symlink_to(native.fmu_path(native_dir, "CardanJoint").parent, target_is_directory=True)
    return folder


@pytest.fixture(scope="module")
def results(models, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("results")
    done = subprocess.run([sys.executable, "-m", "fmu_harness.main", "--models", str(models), "--out", str(out)],
                          capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr
    assert {Path(line).name for line in done.stdout.split()} == {path.name for path in out.iterdir()}
    shown = done.stderr.splitlines()  # each study's start shown before its end
    assert shown.index("main job [1/6] tripod coupling ...") < shown.index("main job [1/6] tripod coupling done")
    assert "main job [5/6] launch shudder ..." in shown and "beta_rate" not in done.stderr  # no notice of a default
    return out


def test_every_csv_starts_with_time_at_0_or_the_swept_variable_with_units_and_no_repeated_row_nor_empty_cell(results):
    tables = sorted(results.glob("*.csv"))
    assert [t.name for t in tables] == ["coupling_comparison.csv", "critical_speeds.csv", "critical_speeds_ramp.csv",
                                        "launch_shudder_peaks.csv", "powertrain_modes.csv", "tripod_coupling.csv",
                                        "vehicle_launch.csv"]
    for table in tables:
        header, *rows = list(csv.reader(table.open()))
        assert header[0] in FIRST_COLUMNS, table.name
        assert rows and all(len(row) == len(header) for row in rows), table.name
        assert len(set(map(tuple, rows))) == len(rows), f"{table.name} repeats a row"
        cells = [[float(cell) if HEADED.match(name) else cell for name, cell in zip(header, row)] for row in rows]
        assert table_errors(header, cells) == [], table.name  # a number under name [unit], a text under name
        if header[0] == "time [s]":
            assert float(rows[0][0]) == 0.0, f"{table.name} starts at {rows[0][0]} s"


def test_every_figure_is_named_in_the_docs_page_it_belongs_to(results):
    pages = " ".join(page.read_text() for page in (Path(__file__).resolve().parents[2] / "docs").glob("*.md"))
    figures = sorted(path.name for path in results.glob("*.png"))
    assert len(figures) == 16 and [name for name in figures if name not in pages] == []


def test_ramp_rows_belong_to_their_own_speed_and_pass_every_critical_speed(results):
    """speed_ratio = omega_in / omega_crit_1 is computed by the FMU from the speed it stepped with."""
    ramp = np.genfromtxt(results / "critical_speeds_ramp.csv", delimiter=",", names=True)
    names = ramp.dtype.names  # genfromtxt drops the brackets: omega_in_rads, speed_ratio_1, ...
    omega, ratio, first = (ramp[n] for n in ("omega_in_rads", "speed_ratio_1", "omega_crit_1_rads"))
    np.testing.assert_allclose(ratio * first, omega, rtol=1e-14, atol=1e-12)
    criticals = np.genfromtxt(results / "critical_speeds.csv", delimiter=",", skip_header=1)[:, 1]
    # the ramp ends 10 % past the third critical speed, as the README says
    assert len(criticals) == 3 and omega[-1] == pytest.approx(1.1 * ramp["omega_crit_3_rads"][0], rel=1e-12)
    assert "time_s" in names and np.all(np.diff(omega) > 0)
    # The figure's crossing of the 1x line with each forward branch the FMU outputs is its critical
    # speed (a root search of its own), to the linear interpolation between 300 ramp samples on a
    # branch that changes by 1 % over the ramp (measured 1.8e-10 and 9.6e-11).
    for k in (1, 2):
        (found,) = critical_speed_study.crossings(omega, ramp[f"whirl_forward_{k}_rads"], 1)
        assert found == pytest.approx(ramp[f"omega_crit_{k}_rads"][0], rel=1e-8)
    assert (results / "campbell_diagram.png").stat().st_size > 50_000


def test_ramp_records_the_unbalance_response_peak(results, models):
    """The unbalance response peaks within 1e-4 of the first critical speed, 0.4 % wide at half its
    height (14.39 mm at 655.28 rad/s), where equal steps of 7.3 rad/s recorded 5.25 mm. The ramp's
    largest value is within 0.1 % of the FMU's own peak, found by a bounded search to 1e-7 of the
    speed within 3 % of where the ramp recorded it (the ramp samples detunings from 1e-5 to 3 %,
    30 % apart, on both sides of each critical speed)."""
    ramp = np.genfromtxt(results / "critical_speeds_ramp.csv", delimiter=",", names=True)
    omega, response = ramp["omega_in_rads"], ramp["unbalance_response_m"]
    recorded = int(np.argmax(response))
    with FmuInstance(native.fmu_path(models, "CriticalSpeeds")) as instance:
        instance.initialize({"omega_in_max": float(omega[-1]), "omega_in": 0.0})
        read, write = instance.reader(["unbalance_response"]), instance.writer(["omega_in"])

        def at(speed: float) -> float:
            write([speed])
            instance.step(1e-3)
            return read()[0]

        found = minimize_scalar(lambda w: -at(w), bounds=(0.97 * omega[recorded], 1.03 * omega[recorded]),
                                method="bounded", options={"xatol": 1e-7 * omega[recorded]})
    assert response[recorded] == pytest.approx(-found.fun, rel=1e-3)
    assert found.x == pytest.approx(ramp["omega_crit_1_rads"][0], rel=1e-3)


def test_python_fmu_check_lists_every_model_with_a_c_port(results):
    report = (results / python_fmu_check.REPORT).read_text()
    for name in native.native_models():
        assert f"| {name} |" in report


def test_the_python_fmus_process_exits_0_every_time(models, tmp_path):
    """The process that loads the pythonfmu FMUs, the part of the main job where the wrapper uses
    freed memory at exit (docs/robustness.md, defect 10), run 20 times."""
    codes = [subprocess.run(python_fmu_check.command(models, models, tmp_path), capture_output=True,
                            timeout=300).returncode for _ in range(RUNS)]
    assert codes == [0] * RUNS


def test_the_modal_table_is_the_cores_for_the_default_layout(results):
    """powertrain_modes.csv: the FMU's frequencies and shares of the default layout (rubber, at the weight's
    equilibrium), those of the core (driveline.mounts) within 1e-9 (the native FMU computes them with its own
    eigensolver)."""
    table = np.genfromtxt(results / "powertrain_modes.csv", delimiter=",", skip_header=1, usecols=(1, 4, 5, 6, 7, 8, 9))
    model = PowertrainMountsModel()
    assert model.initialize(0.0) == []
    np.testing.assert_allclose(table[:, 0], [getattr(model, f"f_mode_{j}") for j in range(1, 7)], rtol=1e-9)
    np.testing.assert_allclose(table[:, 1:], [[getattr(model, f"share_{j}_{name}") for name in COORDINATES]
                                              for j in range(1, 7)], rtol=0.0, atol=1e-9)
    assert (results / "powertrain_decoupling.png").stat().st_size > 30_000


def test_the_launchs_third_order_peaks_lie_at_the_mount_modes_crossings_delayed_by_the_sweep(results):
    """vehicle_launch.csv (every 3.2 ms of the main job's 40 s launch at 20 N.m, the right joint 90 deg ahead
    of the left, the mounts on their rubber default): each mount mode's share of the powertrain's acceleration
    (the core's mode shapes at the mounts' operating point), its third order over the left halfshaft's speed.
    Every mode whose crossing 3 x f_shaft = f_mode the launch passes (1-5) peaks within 1 % of where a single
    mode of its frequency and damping ratio, forced over the launch's own angle history, peaks (measured at most
    0.60 %, mode 5: the rubber's storage stiffness grows with frequency, the single mode's does not; 0.36 % on
    the linear layout); that reference lies above the crossing by the sweep (5.6 % for mode 1, 2.9 % for mode 2,
    2.4, 2.1, 1.5 % for modes 3-5), and where it is below 2 %, so that the 1 % leaves the peak within 3 % of the
    crossing speed, the issue's check holds (measured 2.17 %, mode 5). The study's peak table holds the FMU's
    mode frequencies; its figures are written."""
    run = np.genfromtxt(results / "vehicle_launch.csv", delimiter=",", names=True)
    body, found = launch_study.powertrain_modes()
    accelerations = np.column_stack([run[f"{name}_ddot_{'rads2' if name in ('roll', 'pitch', 'yaw') else 'ms2'}"]
                                     for name in ("x", "y", "z", "roll", "pitch", "yaw")])
    time, angle = run["time_s"], run["phi_out_left_rad"]
    shares = launch_study.modal_accelerations(body, found, accelerations)
    damping = found.damping_ratios
    crossings = launch_study.crossing_speeds(found.frequencies)
    checked = []
    for j in range(6):
        speeds, amplitude = order_tracking.order_track(time, angle, shares[:, j], 3)
        if crossings[j] > speeds[-1]:
            continue
        (peak,) = order_tracking.peaks_near(speeds, amplitude, crossings[j:j + 1], launch_study.WINDOW_MARGIN)
        swept = launch_study.swept_peak(time, angle, found.frequencies[j], damping[j])
        assert peak is not None, f"mode {j + 1}: no third-order peak near its crossing"
        assert peak[1] == pytest.approx(swept, rel=1e-2), f"mode {j + 1}"
        if swept < 1.02 * crossings[j]:
            assert peak[1] == pytest.approx(crossings[j], rel=3e-2), f"mode {j + 1}"
            checked.append(j + 1)
    assert checked == [5]
    table = np.genfromtxt(results / "launch_shudder_peaks.csv", delimiter=",", skip_header=1, usecols=(1, 4, 6))
    np.testing.assert_allclose(table[:, 0], found.frequencies, rtol=1e-9)
    for name in ("launch_speed_torque.png", "launch_axial_force.png", "launch_shudder_orders.png"):
        assert (results / name).stat().st_size > 30_000
