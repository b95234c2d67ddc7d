"""Parameter sweeps on a real local Dask cluster (two worker processes) against direct fmpy runs."""

from __future__ import annotations

import json
import math

import numpy as np
import pyarrow.csv
import pyarrow.parquet
import pytest

from driveline.catalog import MODELS
from fmu_harness.runs import sweep as sweep_module
from fmu_harness.runs.runner import simulate
from fmu_harness.runs.system_sweep import STATISTICS
from fmu_harness.runs.sweep import (
    MARGIN,
    Timing,
    grid,
    main,
    open_client,
    parse_axis,
    read_table,
    sweep,
    units_of,
    write_table,
)

STEPS = 36
TIMING = Timing(steps_per_turn=STEPS)
TRIPOD_METRICS = {
    "delta_phi_peak_abs": lambda r: np.abs(r["delta_phi"]).max(),
    "Rz_out_p2p": lambda r: r["Rz_out"].max() - r["Rz_out"].min(),
    "Rx_in_p2p": lambda r: r["Rx_in"].max() - r["Rx_in"].min(),
    "Ry_in_p2p": lambda r: r["Ry_in"].max() - r["Ry_in"].min(),
    "Rx_in_peak_abs": lambda r: np.abs(r["Rx_in"]).max(),
    "Ry_in_peak_abs": lambda r: np.abs(r["Ry_in"]).max(),
    "Rx_out_peak_abs": lambda r: np.abs(r["Rx_out"]).max(),
    "Ry_out_peak_abs": lambda r: np.abs(r["Ry_out"]).max(),
    "Rz_out_peak_abs": lambda r: np.abs(r["Rz_out"]).max(),
    "omega_out_p2p": lambda r: r["omega_out"].max() - r["omega_out"].min(),
}


@pytest.fixture(scope="module")
def client():
    with open_client(workers=2) as client:
        yield client


def direct_metrics(fmu, point: dict) -> dict[str, float]:
    """The sweep's metrics of one point, from a run in this process."""
    turn = 2.0 * math.pi / point["omega_in"]
    inputs = {k: v for k, v in point.items() if k in ("omega_in", "beta", "T_load")}
    result = simulate(fmu, turn, turn / STEPS, inputs, {k: v for k, v in point.items() if k not in inputs})
    expected = {name: f(result) for name, f in TRIPOD_METRICS.items()}
    for name in result.dtype.names[1:]:
        expected.update({f"{name}_{s}": getattr(result[name], s)() for s in ("min", "max", "mean")})
    return expected


def test_sweep_matches_direct_runs_and_writes_parquet(client, tripod_fmu, tmp_path):
    points = grid({"beta": [0.2, 0.45, 0.7], "r": [0.02, 0.026], "omega_in": [150.0], "kinematics": [1]})
    table = sweep(client, tripod_fmu, points, TIMING)
    rows = table.to_pylist()
    assert [{k: row[k] for k in points[0]} for row in rows] == points
    assert {row["status"] for row in rows} == {"ok"} and {row["reason"] for row in rows} == {None}
    for point, row in zip(points, rows):
        expected = direct_metrics(tripod_fmu, point)
        assert set(row) - set(point) - {"status", "reason", MARGIN} == set(expected)
        off = {
            k: (row[k], v) for k, v in expected.items() if not math.isclose(row[k], v, rel_tol=1e-12, abs_tol=1e-12)
        }
        assert not off, f"{point}: {off}"
    assert rows[-1]["delta_phi_peak_abs"] > rows[0]["delta_phi_peak_abs"] > 0.0
    write_table(table, tmp_path / "sweep.parquet")
    written = pyarrow.parquet.read_table(tmp_path / "sweep.parquet")
    assert written.equals(table) and units_of(written) == spec_units(table.column_names)


def spec_units(columns: list[str]) -> dict[str, str]:
    """The unit of each numeric column of a TripodCoupling sweep from the model's spec (not the FMU's model
    description the sweep reads): a point's variable's, a statistic's output's, the margin's 1."""
    spec = MODELS["TripodCoupling"].spec
    names = {variable.name for variable in spec.variables}
    found = {}
    for name in columns:
        variable = name if name in names else next((v for v in names if name.startswith(f"{v}_")
                                                    and name[len(v) + 1:] in STATISTICS), None)
        if variable is not None:
            found[name] = spec[variable].unit or "1"
    return found | ({MARGIN: "1"} if MARGIN in columns else {})


def test_failed_points_are_reported_with_their_reason(client, tripod_fmu):
    points = [{"beta": 0.3}, {"beta": 0.9}, {"beta": 0.9, "beta_max": 1.0}, {"beta": 0.3, "omega_in": 0.0},
              {"beta": 0.3, "r": -1.0}]
    rows = sweep(client, tripod_fmu, points, TIMING).to_pylist()
    assert [row["status"] for row in rows] == ["ok", "failed", "ok", "failed", "failed"]
    assert rows[4]["reason"] == "parameter r = -1000 mm must be positive"  # checked, not run
    assert rows[1]["reason"] == "input beta = 51.5662 deg must not exceed beta_max = 45 deg"  # checked, not run
    assert rows[3]["reason"].startswith("ValueError: a run of whole input turns needs a finite non-zero omega_in")
    assert rows[1]["T_in_mean"] is None and rows[3]["T_in_mean"] is None
    assert rows[0]["T_in_mean"] == pytest.approx(100.0, rel=1e-4) and rows[2]["delta_phi_peak_abs"] > 0.0


def test_unknown_names_are_refused_before_running(client, tripod_fmu):
    with pytest.raises(ValueError, match="phi_out: no parameter or input of TripodCoupling"):
        sweep(client, tripod_fmu, [{"beta": 0.3}, {"phi_out": 1.0}], TIMING)


def test_grid_axes():
    assert parse_axis("beta=0:0.7:8") == ("beta", np.linspace(0.0, 0.7, 8).tolist())
    assert parse_axis("kinematics=0,1") == ("kinematics", [0, 1])
    assert grid({"a": [1, 2], "b": [3.5]}) == [{"a": 1, "b": 3.5}, {"a": 2, "b": 3.5}]
    with pytest.raises(ValueError, match="expected name=v1,v2"):
        parse_axis("beta")


def test_cli_with_points_file_on_a_running_scheduler(client, fmi2_dir, tmp_path):
    """A CSV table heads every numeric column ``name [unit]`` with the spec's unit, the text columns
    ``status`` and ``reason`` bare; read back, it is the table with its units."""
    points = tmp_path / "points.json"
    points.write_text(json.dumps([{"beta": 0.2, "omega_in": 300.0, "kinematics": 1},
                                  {"beta": 0.4, "omega_in": 0.0, "kinematics": 1}]))
    out = tmp_path / "sweep.csv"
    main(["--points", str(points), "--models", str(fmi2_dir), "--scheduler", client.scheduler.address,
          "--steps-per-turn", str(STEPS), "--out", str(out)])
    table = pyarrow.csv.read_csv(out)
    assert table.column("status").to_pylist() == ["ok", "failed"]
    assert table.column("beta [rad]").to_pylist() == [0.2, 0.4]
    back = read_table(out)
    units = spec_units(back.column_names)
    assert table.column_names == [f"{name} [{units[name]}]" if name in units else name for name in back.column_names]
    assert units_of(back) == units and {"omega_in", "kinematics", "Rz_out_p2p", MARGIN} <= set(units)
    assert set(back.column_names) - set(units) == {"status", "reason"}
    assert back.column(MARGIN).to_pylist()[1] is None  # no margin at omega_in = 0, an empty cell
    assert "nan" not in out.read_text()


def test_critical_speed_margin_of_the_critical_speeds_model(client, tripod_fmu, monkeypatch):
    from driveline.rotor import one_piece_shaft
    from driveline.rotor.model import SHAFT_PARAMETERS

    spec = MODELS["CriticalSpeeds"].spec
    critical = one_piece_shaft(**{name: spec[name].start for name in SHAFT_PARAMETERS}).critical_speeds(4)
    speeds = [150.0, 700.0, -700.0]
    table = sweep(client, tripod_fmu, [{"beta": 0.3, "omega_in": s} for s in speeds], TIMING)
    nearest = [min(critical, key=lambda c: abs(c - abs(s))) for s in speeds]
    assert table.column(MARGIN).to_pylist() == pytest.approx([(abs(s) - c) / c for s, c in zip(speeds, nearest)])
    # a catalog without the model (a copy: the shared one keeps its order for the other tests)
    monkeypatch.setattr(sweep_module, "MODELS", {name: model for name, model in MODELS.items() if name != "CriticalSpeeds"})
    assert MARGIN not in sweep(client, tripod_fmu, [{"beta": 0.3}], TIMING).column_names
