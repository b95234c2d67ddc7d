"""The vehicle launch system (``VehicleLaunch.ssp``, native variant): a closed loop through two tripod
joints with direct feedthrough, run by ``driveline-fmus system`` in the project's master, libcosim and Ecos."""

from __future__ import annotations

import csv
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from driveline.catalog import MODELS
from fmu_harness import system_command
from fmu_harness.runs import system

STEP, STOP = 1e-4, 0.05


@pytest.fixture(scope="module")
def launch_ssp(fmi2_dir: Path, native_dir: Path) -> Path:
    return system.write_ssp(system.vehicle_launch(), fmi2_dir, native_dir)


def _run(package: Path, out: Path, engine: str) -> tuple[list[str], np.ndarray]:
    system_command.main([str(package), "--stop-time", str(STOP), "--step", str(STEP), "--out", str(out),
                         "--engine", engine])
    with out.open() as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.fixture(scope="module")
def master(launch_ssp: Path, tmp_path_factory) -> tuple[list[str], np.ndarray]:
    return _run(launch_ssp, tmp_path_factory.mktemp("launch") / "master.csv", "master")


def test_the_launch_drives_the_car_through_both_joints(master):
    """50 ms into the motor's torque ramp: both halfshafts carry torque, both joints pass it on (T_in within
    1 % of T_load: the joints' inertia and friction), the car moves forward. Each joint's torques in its
    own frame, Z' towards its wheel: the right one's are negative; the mounts pitch under both."""
    header, values = master
    column = {name.split(" [")[0]: values[:, i] for i, name in enumerate(header)}
    for side, sense in zip(system.SIDES, (1.0, -1.0)):
        load, taken = column[f"drive.T_load_{side}"][-1], column[f"joint_{side}.T_in"][-1]
        assert sense * load > 1.0 and taken == pytest.approx(load, rel=1e-2)
    assert column["drive.v_x"][-1] > 0.0 and np.all(np.isfinite(values))
    if system.MOUNTS in MODELS:
        assert abs(column["mounts.pitch"][-1]) > 0.0


@pytest.mark.parametrize("engine", ["libcosim", "ecos"])
def test_the_engines_run_the_launch_like_the_master(engine, launch_ssp, master, tmp_path):
    """Same Jacobi scheme: every column within 1e-9 of its largest magnitude in the master's run, the
    plunger accelerations' sum of its terms' magnitude (measured over 0.5 s: 1.7e-6 of the sum's own
    magnitude, a cancellation of terms 1e5 times larger)."""
    if importlib.util.find_spec(f"{engine}py") is None:
        pytest.skip(f"{engine}py is not installed on this platform (pip install '.[interop]')")
    header, reference = master
    _, values = _run(launch_ssp, tmp_path / "run.csv", engine)
    scale = np.maximum(np.abs(reference).max(axis=0), 1e-300)
    mass = system.vehicle_launch().component("joint_left").spec["m_plunger"].start
    for side in system.SIDES:
        terms = np.abs(reference[:, header.index(f"joint_{side}.F_plunger1 [N]")]).max() / mass
        scale[header.index(f"joint_{side}.a_plunger_sum [m/s2]")] = terms
    assert (np.abs(values - reference).max(axis=0) / scale).max() <= 1e-9


def test_without_friction_the_joints_generate_no_axial_force(launch_ssp, master, tmp_path):
    """The generated axial force -Rz_in comes from friction alone: with mu = 0 on both joints it is 0
    over the run, where with the package's mu = 0.05 it reaches over 1 N within 50 ms."""
    system_command.main([str(launch_ssp), "--stop-time", str(STOP), "--step", str(STEP), "--out",
                         str(tmp_path / "run.csv"), "--set", "joint_left.mu=0", "--set", "joint_right.mu=0"])
    with (tmp_path / "run.csv").open() as handle:
        rows = list(csv.reader(handle))
    header, values = rows[0], np.array(rows[1:], dtype=float)
    friction_header, friction = master
    for side in system.SIDES:
        name = f"joint_{side}.Rz_in [N]"
        assert np.abs(friction[:, friction_header.index(name)]).max() > 1.0
        assert np.all(values[:, header.index(name)] == 0.0)
