"""The launch shudder map: peak third-order powertrain acceleration over bend angle, torque and friction.

The peak third-order powertrain acceleration of the vehicle launch over the joints' bend angle, the
launch torque and the joints' friction coefficient, each launch a run of the sweep layer.

Usage (``driveline-fmus map`` is ``python -m fmu_harness.shudder_map``)::

    driveline-fmus map [--package models/native/VehicleLaunch.ssp] [--count 8] [--joints 0,1,2]
        [--duration 4] [--step 2e-4] [--master gauss-seidel] [--workers N | --scheduler tcp://host:8786]
        [--out results/shudder_map.parquet] [--figure results/shudder_map.png]
    driveline-fmus map --figure-only [--out ...] [--figure ...]

The grid: ``--count`` values each of both joints' ``beta`` (5 to 20 deg), ``motor.T_level`` (20 to
100 % of the default car's motor peak, :data:`driveline.vehicle.compact_car.MOTOR_PEAK_TORQUE`) and
both joints' ``mu`` (0.02 to 0.1), the cartesian product (512 launches at the default 8), and with
``--joints`` the joints' ``tripod_type`` too (``--joints 0,1,2``: plain, single and double roller, a
dimension of its own, three times the launches; by default the plain tripod alone, no column), each one
launch of :mod:`fmu_harness.runs.system_sweep` with the launch's metrics and :data:`THIRD_ORDER`:
``mounts.pitch_ddot_order3_peak``, the peak third-order amplitude of the powertrain's pitch
acceleration over the left joint's turns (:func:`fmu_harness.studies.order_tracking.third_order_peak`;
the right joint turns negatively in its own frame), and ``mounts.pitch_ddot_order3_speed``, the joint's
speed there. A launch whose joint turns less than the order tracking's window fails with that
reason. The table goes to ``--out``, the figure (a panel per friction coefficient, a row of them per
joint: the peak over bend angle and torque) to ``--figure``; ``--figure-only`` draws the figure from a
table written before.
"""

from __future__ import annotations

import argparse
import importlib
import math
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from driveline.tripod.spec import DOUBLE_ROLLER, PLAIN_TRIPOD, SINGLE_ROLLER
from driveline.vehicle.compact_car import MASS, MOTOR_PEAK_TORQUE, RATIO, WHEEL_RADIUS

from .console import CommandParser, summary
from .runs import sweep
from .runs.system_sweep import DerivedMetrics
from .studies.order_tracking import REVOLUTIONS, third_order_peak

if TYPE_CHECKING:
    import pyarrow as pa
    from matplotlib.figure import Figure

COMMAND = "driveline-fmus map"
SHAFT, SIGNAL = "joint_left.phi_in", "mounts.pitch_ddot"
BETA = "joint_left.beta+joint_right.beta"
TORQUE = "motor.T_level"
MU = "joint_left.mu+joint_right.mu"
JOINT = "joint_left.tripod_type+joint_right.tripod_type"
JOINT_NAMES = {PLAIN_TRIPOD: "plain tripod", SINGLE_ROLLER: "single roller", DOUBLE_ROLLER: "double roller"}
PEAK = f"{SIGNAL}_order3_peak"
BETA_RANGE = (math.radians(5.0), math.radians(20.0))
TORQUE_RANGE = (0.2 * MOTOR_PEAK_TORQUE, MOTOR_PEAK_TORQUE)
MU_RANGE = (0.02, 0.1)


def pitch_third_order(time: np.ndarray, outputs: Mapping[str, np.ndarray]) -> tuple[float, float]:
    """The peak third-order pitch acceleration [rad/s2] over the left joint's turns and its speed there [rad/s]."""
    return third_order_peak(time, outputs[SHAFT], outputs[SIGNAL])


THIRD_ORDER = DerivedMetrics((SHAFT, SIGNAL), (PEAK, f"{SIGNAL}_order3_speed"), pitch_third_order, ("rad/s2", "rad/s"))


def shortest_duration(torque: float = TORQUE_RANGE[1], revolutions: float = REVOLUTIONS) -> float:
    """The launch length [s] in which the motor's ``torque`` [N.m] could at best turn the halfshaft
    ``revolutions`` times: the default car as one rigid mass, the torque a step at t = 0, no road load,
    no wheel or motor inertia (each makes the car slower; the tyres' slip, under 1 % here, is the only
    thing faster). The wheel turns ``a t^2 / (4 pi r)`` times at ``a = torque RATIO / (r MASS)``."""
    acceleration = torque * RATIO / (WHEEL_RADIUS * MASS)
    return math.sqrt(4.0 * math.pi * WHEEL_RADIUS * revolutions / acceleration)


def duration_error(duration: float) -> str | None:
    """Why ``duration`` [s] is too short for every launch of the map (the strongest one cannot turn the
    shaft the order tracking window's revolutions: :func:`shortest_duration`); None when it is not, or
    when it is no positive number (the plan refuses that)."""
    shortest = shortest_duration()
    if not (math.isfinite(duration) and 0.0 < duration < shortest):
        return None
    return (f"--duration {duration:g} s: the map's strongest launch ({TORQUE_RANGE[1]:g} N.m) turns the halfshaft "
            f"less than the {REVOLUTIONS:g} revolutions of the order tracking window in it; give at least "
            f"{math.ceil(shortest * 10.0) / 10.0:g} s (default 4)")


def axes(count: int, joints: Sequence[int] = (PLAIN_TRIPOD,)) -> dict[str, list[float]]:
    """The map's grid axes, ``count`` values each, both ends included; the joints' types ``joints`` a
    first axis of their own unless the plain tripod alone."""
    found = {} if tuple(joints) == (PLAIN_TRIPOD,) else {JOINT: list(joints)}
    return found | {name: np.linspace(*bounds, count).tolist()
                    for name, bounds in ((BETA, BETA_RANGE), (TORQUE, TORQUE_RANGE), (MU, MU_RANGE))}


def joint_types(text: str) -> list[int]:
    """``--joints``: tripod types (0 plain, 1 single roller, 2 double roller) separated by commas."""
    try:
        found = [int(part) for part in text.split(",")]
    except ValueError:
        found = []
    if not found or any(joint not in JOINT_NAMES for joint in found) or len(set(found)) < len(found):
        raise argparse.ArgumentTypeError(f"{text!r}: give distinct tripod types among 0, 1, 2, e.g. 0,1,2")
    return found


def draw(table: pa.Table, path: Path) -> Path:
    """The map's figure (:func:`map_figure`) saved to ``path``."""
    from .studies import figures  # matplotlib, when a figure is drawn: a mistake is refused before it loads

    path.parent.mkdir(parents=True, exist_ok=True)
    return figures.save(map_figure(table), path)


def map_figure(table: pa.Table) -> Figure:
    """A panel per friction coefficient, a row of them per joint: the peak third-order pitch acceleration
    [rad/s2] over the bend angle [deg] and the launch torque [% of the motor's peak], one colour scale
    for all panels; a failed launch is left blank."""
    from .studies import figures

    rows = table.to_pylist()
    betas, torques, mus = (sorted({row[name] for row in rows}) for name in (BETA, TORQUE, MU))
    joints = sorted({row[JOINT] for row in rows}) if JOINT in table.column_names else [PLAIN_TRIPOD]
    cases = [(joint, mu) for joint in joints for mu in mus]  # a panel each, a row of them per joint
    peaks = np.full((len(cases), len(torques), len(betas)), np.nan)
    for row in rows:
        if row["status"] == "ok":
            case = cases.index((row.get(JOINT, PLAIN_TRIPOD), row[MU]))
            peaks[case, torques.index(row[TORQUE]), betas.index(row[BETA])] = row[PEAK]
    columns = min(4, len(mus))
    lines = len(joints) * math.ceil(len(mus) / columns)
    fig, panels = figures.figure(lines, columns, squeeze=False, sharex=True, sharey=True,
                                 figsize=(3.2 * columns + 1.2, 2.9 * lines + 0.6), layout="constrained")
    top = np.nanmax(peaks) if np.any(np.isfinite(peaks)) else 1.0
    x, y = np.degrees(betas), 100.0 * np.array(torques) / MOTOR_PEAK_TORQUE
    per_joint = columns * math.ceil(len(mus) / columns)
    for k, panel in enumerate(panels.flat):
        joint, place = divmod(k, per_joint)
        if place >= len(mus):
            panel.set_visible(False)
            continue
        case = joint * len(mus) + place
        image = panel.pcolormesh(x, y, peaks[case], shading="nearest", vmin=0.0, vmax=top, cmap="viridis")
        panel.set_xlim(x[0], x[-1])  # the grid's range: its outer cells shown to their values, no further
        panel.set_ylim(y[0], y[-1])
        title = f"mu = {mus[place]:.3g}"
        panel.set_title(title if len(joints) == 1 else f"{JOINT_NAMES[joints[joint]]}, {title}", fontsize=9)
    for panel in panels[-1]:
        panel.set_xlabel("bend angle beta [deg]")
    for panel in panels[:, 0]:
        panel.set_ylabel("launch torque [% of peak]")
    fig.colorbar(image, ax=panels, label="peak 3rd-order pitch acceleration [rad/s2]")
    fig.suptitle(f"Launch shudder map: {len(rows)} launches of VehicleLaunch, both joints alike", fontsize=10)
    return fig


def main(argv: Sequence[str] | None = None) -> None:
    parser = CommandParser(description=summary(__doc__))
    parser.add_argument("--package", type=Path, default=Path("models") / "native" / "VehicleLaunch.ssp",
                        help="the launch's SSP package (default models/native/VehicleLaunch.ssp)")
    parser.add_argument("--count", type=int, default=8, help="values per axis (default 8: 512 launches)")
    parser.add_argument("--joints", type=joint_types, default=[PLAIN_TRIPOD],
                        help="tripod types swept, e.g. 0,1,2 (0 plain, 1 single, 2 double roller; default 0)")
    parser.add_argument("--duration", type=float, default=4.0, help="launch length [s] (default 4)")
    parser.add_argument("--step", type=float, default=2e-4, help="communication step [s] (default 2e-4)")
    parser.add_argument("--master", choices=sweep.MASTERS, default=sweep.DEFAULT_MASTER,
                        help=f"default {sweep.DEFAULT_MASTER} (docs/vehicle_launch.md, 'Throughput')")
    parser.add_argument("--workers", type=sweep.workers_count, default=sweep.default_workers(),
                        help="local cluster size")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://host:8786")
    parser.add_argument("--out", type=sweep.table_file, default=Path("results") / "shudder_map.parquet",
                        help=".parquet or .csv")
    parser.add_argument("--figure", type=Path, default=Path("results") / "shudder_map.png", help="PNG file to write")
    parser.add_argument("--figure-only", action="store_true", help="draw the figure from the table at --out")
    args = parser.parse_args(argv)
    if args.figure_only:
        if not args.out.is_file():
            parser.error(f"--figure-only: no table {args.out} (run the map first)")
        print(draw(sweep.read_table(args.out), args.figure))
        return
    if args.count < 2:
        parser.error(f"--count must be at least 2, got {args.count}")
    too_short = duration_error(args.duration)
    if too_short:
        parser.error(too_short)
    try:
        plan = sweep.Plan.of_system(args.package, sweep.grid(axes(args.count, args.joints)), args.duration, args.step,
                                    args.master, (THIRD_ORDER,))
        if args.scheduler:
            sweep.check_scheduler(args.scheduler)
    except (ValueError, OSError) as error:
        parser.error(str(error))
    table = sweep.run_plan(plan, args.scheduler, args.workers)
    sweep.write_table(table, args.out)
    failed = sweep.failure_reasons(table)
    if failed.total() < table.num_rows:
        print(draw(table, args.figure))
    print(f"{table.num_rows} launches, {failed.total()} failed -> {args.out}")
    sweep.print_reasons(failed)
    if failed.total() == table.num_rows:
        sys.exit(f"{COMMAND}: every launch failed, no figure drawn")


if __name__ == "__main__":
    # Dask pickles ``__main__`` functions by value; run the module's own import instead.
    importlib.import_module(__spec__.name).main()
