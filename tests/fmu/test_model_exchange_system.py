"""The Model Exchange engine (``fmu_harness/runs/model_exchange_system.py``, ``driveline-fmus system
--engine model-exchange``): the native FMUs' Model Exchange interfaces as one ODE, the connections
sorted by the declared direct dependencies, the launch's algebraic loop solved by Newton's method with
the FMUs' directional derivatives.

Evidence: the sorting against scipy's strongly connected components and the order it must respect; the
driveline (no loop) against the co-simulation master, whose difference must fall with the square of
its step (the exact phase integration of a held speed is second order); the vehicle launch against
the monolithic ODE of the physics cores (``launch_reference``), which solves the same loop by
successive substitution inside ``solve_ivp``: both integrate the same equations, so they agree to
the integrators' tolerance and converge as it tightens, where the co-simulation masters err by 1e-4
to 1e-2 at 1e-4 s; the exact system Jacobian against differences of the rates, and Radau on it.
"""

from __future__ import annotations

import csv
import dataclasses
import types
import zipfile
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from fmu_harness import system_command
from fmu_harness.packaging import native
from fmu_harness.runs import launch_reference, ssp_package, system
from fmu_harness.runs.model_exchange_system import ModelExchangeSystem, run_model_exchange, strongly_connected
from fmu_harness.runs.runner import StepRefused
from fmu_harness.runs.system import run_jacobi


def _unpacked(package: Path, folder: Path) -> tuple[ssp_package.SspSystem, dict[str, Path]]:
    found = ssp_package.read(package)
    with zipfile.ZipFile(package) as archive:
        archive.extractall(folder)
    return found, {c.name: folder / c.source for c in found.components}


@pytest.mark.parametrize("seed", range(5))
def test_the_blocks_are_the_strongly_connected_components_in_an_order_the_edges_allow(seed):
    """Random graphs of 30 nodes: the blocks partition the nodes as scipy's strong components do, and
    every edge goes from a block to itself or to a later one."""
    generator = np.random.default_rng(seed)
    edges = {k: sorted({int(j) for j in generator.integers(0, 30, size=generator.integers(0, 3))}) for k in range(30)}
    blocks = strongly_connected(30, edges)
    adjacency = csr_matrix(([1] * sum(map(len, edges.values())),
                            ([k for k, after in edges.items() for _ in after], [j for after in edges.values() for j in after])),
                           shape=(30, 30))
    count, labels = connected_components(adjacency, directed=True, connection="strong")
    assert len(blocks) == count
    assert all(len({labels[k] for k in block}) == 1 for block in blocks)
    position = {k: i for i, block in enumerate(blocks) for k in block}
    assert all(position[k] <= position[j] for k, after in edges.items() for j in after)


def test_the_driveline_converges_to_the_co_simulation_as_its_step_shrinks(fmi2_dir, native_dir, tmp_path):
    """``Driveline.ssp`` (speed source, tripod coupling, critical speeds; no loop), DOP853 at rtol 1e-10,
    against the Jacobi master at 1e-3 and 1e-4 s: the largest difference of the coupling's output angle
    and speed falls by at least 50 with the step (measured 100: the exact phase of a held speed is second
    order), of its axial reaction by at least 8 (measured 47, then 14 to 1e-5 s: first order, the
    acceleration held over a step)."""
    package, fmus = _unpacked(system.write_ssp(system.driveline(), fmi2_dir, native_dir), tmp_path / "package")
    parameters = {c.name: c.parameters for c in package.components}
    outputs = ["coupling.phi_out", "coupling.omega_out", "coupling.Rz_out"]
    exchanged = run_model_exchange(fmus, parameters, package.connections, 0.1, 1e-3, outputs, tmp_path / "me",
                                   rtol=1e-10)
    differences = []
    for step in (1e-3, 1e-4):
        rows = run_jacobi(fmus, parameters, package.connections, 0.1, step, outputs)[int(round(1e-3 / step)) - 1::
                                                                                    int(round(1e-3 / step))]
        np.testing.assert_allclose(rows[:, 0], exchanged[:, 0], rtol=1e-12)
        differences.append(np.abs(rows[:, 1:] - exchanged[:, 1:]).max(axis=0) / np.abs(exchanged[:, 1:]).max(axis=0))
    assert np.all(differences[1] * [50, 50, 8] <= differences[0]), differences


@pytest.fixture(scope="module")
def launch(fmi2_dir, native_dir, tmp_path_factory) -> tuple[ssp_package.SspSystem, dict[str, Path]]:
    """The launch without the housings' motion, the monolithic reference's (launch_reference)."""
    held = dataclasses.replace(system.vehicle_launch(housing_motion=False), name="VehicleLaunchHeld")
    return _unpacked(system.write_ssp(held, fmi2_dir, native_dir), tmp_path_factory.mktemp("launch"))


@pytest.fixture(scope="module")
def moving(fmi2_dir, native_dir, tmp_path_factory) -> tuple[ssp_package.SspSystem, dict[str, Path]]:
    """The package's launch: the joints' bends from PowertrainMounts."""
    return _unpacked(system.write_ssp(system.vehicle_launch(), fmi2_dir, native_dir), tmp_path_factory.mktemp("moving"))


def test_the_moving_housings_close_the_loop_through_the_mounts_and_the_masters_converge_to_it(moving, tmp_path):
    """With the housings' motion, the joints' reactions depend on their beta_ddot (the plungers' inertia) and the
    mounts' beta_ddot on the reactions and the drive's T_reaction: one loop, now with the mounts' second rates
    in it, solved by Newton's method on the FMUs' exact derivatives. The Jacobi master converges to that run at
    first order: over 20 ms its error halves with the step from 2e-5 s (measured within 0.4 % at 1e-5 s)."""
    package, fmus = moving
    parameters = {c.name: c.parameters for c in package.components}
    engine = ModelExchangeSystem(fmus, parameters, package.connections, tmp_path / "engine")
    named = [[f"{engine.connections[k][0][0]}.{engine.connections[k][0][1]}" for k in block] for block in engine.blocks]
    engine.close()
    (loop,) = [set(block) for block in named if len(block) > 1]
    assert {"mounts.beta_ddot_left", "mounts.beta_ddot_right", "joint_left.T_in", "drive.T_reaction"} <= loop
    outputs = ["mounts.beta_dot_left", "mounts.beta_ddot_right", "mounts.pitch_ddot", "drive.T_load_left"]
    exact = run_model_exchange(fmus, parameters, package.connections, 0.02, 1e-3, outputs, tmp_path / "me", rtol=1e-10)
    errors = []
    for step in (2e-5, 1e-5):
        rows = run_jacobi(fmus, parameters, package.connections, 0.02, step, outputs)[int(round(1e-3 / step)) - 1::
                                                                                    int(round(1e-3 / step))]
        errors.append(np.abs(rows[:, 1:] - exact[:, 1:]).max(axis=0) / np.abs(exact[:, 1:]).max(axis=0))
    assert np.all(errors[1] <= 1e-2) and np.all(np.abs(errors[0] / errors[1] - 2.0) <= 0.3), errors


def _loop(outputs, jacobian: np.ndarray) -> ModelExchangeSystem:
    """An engine whose one loop has the outputs ``outputs(v)`` of the values ``v`` carried, and the kept loop
    Jacobian ``jacobian`` (I - dy/dv): no FMU, :meth:`ModelExchangeSystem._solve_loop` alone."""
    engine = ModelExchangeSystem.__new__(ModelExchangeSystem)
    engine.connections = [(("source", f"y{k}"), ("target", f"u{k}")) for k in range(len(jacobian))]
    engine.instances = {"source": types.SimpleNamespace(time=0.0)}
    carried = [np.zeros(len(jacobian))]
    engine._carry = lambda block, values: carried.__setitem__(0, np.array(values))
    engine._outputs = lambda block: outputs(carried[0])
    engine._loop_jacobian = lambda block: jacobian
    return engine


def test_newton_at_its_rounding_floor_is_accepted_and_stalled_far_from_a_solution_refused():
    """A small value fed by a large one (v1 = 0.034 v0 - 33.2 with v0 = 1000, alpha_in from the torques) whose
    output rounds by +-2e-11 alternately, more than 1e-11 of v1 but within 1e-11 of the 35 that feed it: solved at
    the floor (the 2-cycle the launch met). A loop with no solution, whose updates stop falling at 1 (a residual of
    1 whatever v), is refused after 20 iterations."""
    calls = [0]

    def rounded(values: np.ndarray) -> np.ndarray:
        calls[0] += 1
        return np.array([1000.0, 0.034 * values[0] - 33.2 + (-1) ** calls[0] * 2e-11])

    engine = _loop(rounded, np.array([[1.0, 0.0], [-0.034, 1.0]]))
    engine._solve_loop([0, 1])
    assert calls[0] <= 4
    with pytest.raises(StepRefused, match="did not converge in 20 iterations"):
        _loop(lambda values: values + 1.0, np.eye(1))._solve_loop([0])


def test_the_moving_launch_passes_the_loops_rounding_floor(moving, tmp_path):
    """The package's launch through 0.5 s at the engine's defaults. At t = 0.4345 s Newton's updates on the loop
    stop falling at a 2-cycle of +-1.07e-11 on alpha_in_left = 0.79 rad/s2 (the rounding of the 1,115 N.m that
    feed it, carried through a loop Jacobian of condition 4.3e3; the residual 1.1e-12): the engine accepts
    that floor and goes on, where it refused the step before; the vehicle gains speed at every row."""
    package, fmus = moving
    rows = run_model_exchange(fmus, {c.name: c.parameters for c in package.components}, package.connections, 0.5,
                              0.05, ["drive.v_x"], tmp_path)
    assert rows[-1, 0] == pytest.approx(0.5) and np.all(np.diff(rows[:, 1]) > 0.0), rows


def test_the_launch_has_one_loop_the_joints_torques_and_the_side_gears_accelerations(launch, tmp_path):
    """The declared dependencies leave one algebraic loop: each joint's ``T_in`` (on its ``alpha_in``)
    and the drive's ``alpha_in_*`` (on both ``T_in``); the speeds, angles and halfshaft torques come
    before it, the housing loads after."""
    package, fmus = launch
    engine = ModelExchangeSystem(fmus, {c.name: c.parameters for c in package.components}, package.connections,
                                 tmp_path)
    named = [[f"{engine.connections[k][0][0]}.{engine.connections[k][0][1]}" for k in block] for block in engine.blocks]
    engine.close()
    loops = [block for block in named if len(block) > 1]
    assert [sorted(loop) for loop in loops] == [["drive.alpha_in_left", "drive.alpha_in_right", "joint_left.T_in",
                                                 "joint_right.T_in"]]
    order = {name: i for i, block in enumerate(named) for name in block}
    loop = order["joint_left.T_in"]
    assert all(order[f"drive.{name}_{side}"] < loop for name in ("T_load", "omega_in") for side in system.SIDES)
    assert all(order[f"joint_{side}.Rz_in"] > loop for side in system.SIDES)


@pytest.fixture(scope="module")
def monolithic() -> dict[str, np.ndarray]:
    """The monolithic launch at every 2 ms of 0.1 s, DOP853 at rtol 1e-12 (5.8e-10 from its run at 1e-10)."""
    return launch_reference.reference(np.arange(1, 51) * 2e-3, rtol=1e-12)


def _errors(rows: np.ndarray, monolithic: dict[str, np.ndarray]) -> np.ndarray:
    """Each signal's largest difference from the monolithic run, relative to its largest magnitude."""
    return np.array([np.abs(rows[:, i + 1] - monolithic[name]).max() / np.abs(monolithic[name]).max()
                     for i, name in enumerate(launch_reference.SIGNALS)])


def _launch(launch, folder: Path, rtol: float, method: str = "DOP853") -> np.ndarray:
    package, fmus = launch
    return run_model_exchange(fmus, {c.name: c.parameters for c in package.components}, package.connections,
                              0.1, 2e-3, list(launch_reference.SIGNALS), folder, rtol=rtol, method=method)


def test_the_launch_converges_to_the_monolithic_ode_as_the_tolerance_tightens(launch, monolithic, tmp_path):
    """0.1 s of the launch against ``launch_reference`` (the physics cores as one ODE): vehicle speed,
    halfshaft torque, generated axial force and pitch acceleration within 2e-8 of their largest
    magnitude at rtol 1e-10 (measured 8.5e-12 to 3.6e-9; the co-simulation masters at 1e-4 s: 3.3e-4 to
    4.5e-2), each error at least 10 times below its value at rtol 1e-8 (measured 36 to 170)."""
    loose, tight = (_errors(_launch(launch, tmp_path / str(rtol), rtol), monolithic) for rtol in (1e-8, 1e-10))
    assert np.all(tight <= 2e-8), tight
    assert np.all(tight * 10 <= loose), (loose, tight)


def test_radau_with_the_exact_system_jacobian_gives_the_launch(launch, monolithic, tmp_path):
    """The implicit Radau IIA method, its Newton iterations on the system Jacobian assembled from the FMUs'
    directional derivatives: within 1e-8 at rtol 1e-8 (measured 6.9e-11 to 1.1e-9)."""
    errors = _errors(_launch(launch, tmp_path, 1e-8, "Radau"), monolithic)
    assert np.all(errors <= 1e-8), errors


def test_the_system_jacobian_equals_central_differences_of_the_rates(launch, tmp_path):
    """Mid-launch (t = 0.05 s): the exact Jacobian of the stacked rates against their central differences
    with a relative step of 1e-5 (truncation and the loop's rounding, 2e-13 of alpha_in over the step,
    both near 1e-10), each entry scaled by its state's magnitude (at least 1e-3) over its row's largest:
    within 1e-8 (measured 1.4e-10)."""
    package, fmus = launch
    engine = ModelExchangeSystem(fmus, {c.name: c.parameters for c in package.components}, package.connections,
                                 tmp_path)
    state = solve_ivp(engine.rates, (0.0, 0.05), engine.start(), method="DOP853", rtol=1e-6, atol=1e-12).y[:, -1]
    jacobian = engine.jacobian(0.05, state)
    scales = np.maximum(1e-3, np.abs(state))
    differences = np.zeros_like(jacobian)
    for k, scale in enumerate(scales):
        moved = np.zeros_like(state)
        moved[k] = 1e-5 * scale
        differences[:, k] = (engine.rates(0.05, state + moved) - engine.rates(0.05, state - moved)) / (2e-5 * scale)
    engine.close()
    rows = np.max(np.abs(jacobian) * scales, axis=1)
    error = np.abs(differences - jacobian) * scales / np.where(rows > 0.0, rows, 1.0)[:, None]
    assert error.max() <= 1e-8, error.max()


def test_fmi_3_gives_fmi_2s_launch_bit_for_bit(launch, native_dir, tmp_path):
    """The same launch from the FMI 3.0 native FMUs (the same C code behind the other API)."""
    package, fmus = launch
    models = {c.name: c.source.rsplit("/", 1)[-1].removesuffix(".fmu") for c in package.components}
    fmi3 = {name: native.fmu_path(native_dir, model, "3") for name, model in models.items()}
    parameters = {c.name: c.parameters for c in package.components}
    outputs = ["drive.v_x", "joint_left.T_in", "mounts.pitch_ddot"]
    found = [run_model_exchange(paths, parameters, package.connections, 0.02, 1e-3, outputs, tmp_path / version)
             for version, paths in (("2", fmus), ("3", fmi3))]
    np.testing.assert_array_equal(*found)


def test_a_loop_through_an_fmu_without_directional_derivatives_is_one_line(fmi2_dir, native_dir, tmp_path, capsys):
    """The launch package with the drive's FMU declaring no directional derivatives: the command stops
    before the run in one line naming the component and the loop, status 2."""
    package = system.write_ssp(system.vehicle_launch(), fmi2_dir, native_dir)
    drive = ssp_package.read(package).component("drive").source
    stripped = tmp_path / "stripped.ssp"
    with zipfile.ZipFile(package) as original, zipfile.ZipFile(stripped, "w") as copy:
        for item in original.namelist():
            data = original.read(item)
            copy.writestr(item, _without_derivatives(data, tmp_path) if item == drive else data)
    with pytest.raises(SystemExit) as exit_status:
        system_command.main([str(stripped), "--stop-time", "0.01", "--engine", "model-exchange", "--out",
                             str(tmp_path / "run.csv")])
    err = capsys.readouterr().err
    assert exit_status.value.code == 2 and err.count("\n") == 1
    assert "error: drive: the algebraic loop of " in err and "gives no directional derivatives" in err
    assert not (tmp_path / "run.csv").exists()


def _without_derivatives(fmu: bytes, folder: Path) -> bytes:
    """The FMU ``fmu`` (zip bytes) with providesDirectionalDerivative="false" in its description."""
    (folder / "in.fmu").write_bytes(fmu)
    with zipfile.ZipFile(folder / "in.fmu") as original, zipfile.ZipFile(folder / "out.fmu", "w") as copy:
        for item in original.namelist():
            data = original.read(item)
            if item == "modelDescription.xml":
                data = data.replace(b'providesDirectionalDerivative="true"', b'providesDirectionalDerivative="false"')
            copy.writestr(item, data)
    return (folder / "out.fmu").read_bytes()


def test_the_command_writes_the_engines_rows(moving, fmi2_dir, native_dir, tmp_path):
    """``driveline-fmus system VehicleLaunch.ssp --engine model-exchange``: the CSV file holds the
    engine's rows for every Real output, bit for bit."""
    package_path = system.write_ssp(system.vehicle_launch(), fmi2_dir, native_dir)
    system_command.main([str(package_path), "--stop-time", "0.01", "--step", "1e-3", "--engine", "model-exchange",
                         "--rtol", "1e-9", "--out", str(tmp_path / "run.csv")])
    with (tmp_path / "run.csv").open() as handle:
        header, *rows = list(csv.reader(handle))
    package, fmus = moving
    outputs = [column.split(" [")[0] for column in header[1:]]
    expected = run_model_exchange(fmus, {c.name: c.parameters for c in package.components}, package.connections,
                                  0.01, 1e-3, outputs, tmp_path / "engine", rtol=1e-9, initial=True)
    np.testing.assert_array_equal(np.array(rows, dtype=float), expected)
