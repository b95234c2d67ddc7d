"""The launch shudder map: peak third-order powertrain acceleration over joint, bend, torque, friction and phase.

The peak third-order powertrain acceleration of the vehicle launch over the joints' type, their bend
angle, the launch torque, the joints' friction coefficient and the right joint's phase against the
left's, each launch a run of the sweep layer; for each type, bend, torque and friction the worst phase
and the envelope over the phases.

Usage (``driveline-fmus map`` is ``python -m fmu_harness.shudder_map``)::

    driveline-fmus map [--package models/native/VehicleLaunch.ssp] [--count 8]
        [--phases 4] [--joints plain] [--duration 4] [--step 2e-4] [--master gauss-seidel]
        [--workers N | --scheduler tcp://host:8786]
        [--out results/shudder_map.parquet] [--envelope results/shudder_map_envelope.csv]
        [--figure results/shudder_map.png]
    driveline-fmus map --figure-only [--out ...] [--envelope ...] [--figure ...]

The grid: the ``--joints`` types of :data:`JOINT_TYPES` (both joints' ``tripod_type`` alike; the plain
tripod alone by default), ``--count`` values each of both halfshafts' design bend (``mounts.beta_design_*``, the joints'
bends following the powertrain from there; 5 to 20 deg), ``motor.T_level`` (20 to
100 % of the default car's motor peak, :data:`driveline.vehicle.compact_car.MOTOR_PEAK_TORQUE`) and
both joints' ``mu`` (0.02 to 0.1), and ``--phases`` values of the right joint's ``phi_in_start`` (the left
joint's stays 0) spread over the third of a turn after which a tripod joint repeats itself
(:data:`PHASE_PERIOD`; 0, 30, 60, 90 deg at the default 4), the cartesian product (2,048 launches at the
defaults, as many again for each further type), each one launch of :mod:`fmu_harness.runs.system_sweep`
with the launch's metrics and
:data:`THIRD_ORDERS`: for the powertrain's pitch, lateral and yaw accelerations at its centre of gravity
(``mounts.pitch_ddot``, ``mounts.y_ddot``, ``mounts.yaw_ddot``) the peak third-order amplitude over the
left joint's turns (``..._order3_peak``, :func:`fmu_harness.studies.order_tracking.third_order_peak`; the
right joint turns negatively in its own frame) and the joint's speed there (``..._order3_speed``). A
launch whose joint turns less than the order tracking's window fails with that reason. The table goes
to ``--out``; the envelope over the phases (:func:`envelope`: for each type, bend, torque and friction each
peak's largest and smallest value over the phases and the phase of the largest, the worst) to
``--envelope``; the figure (a panel per friction coefficient, a row of them per joint type with its own
colour scale: the worst phase's pitch peak over bend angle and torque, each cell labelled with its worst
phase) to ``--figure``; ``--figure-only`` draws the
figure from a table written before.
"""

from __future__ import annotations

import importlib
import math
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from driveline.tripod.spec import DOUBLE_ROLLER, PLAIN_TRIPOD, SINGLE_ROLLER
from driveline.vehicle.compact_car import MASS, MOTOR_PEAK_TORQUE, RATIO, WHEEL_RADIUS

from .console import CommandParser, summary
from .runs import sweep
from .runs.system_sweep import DerivedMetrics
from .studies.order_tracking import REVOLUTIONS, third_order_peak

if TYPE_CHECKING:
    import pyarrow as pa

COMMAND = "driveline-fmus map"
SHAFT, SIGNAL = "joint_left.phi_in", "mounts.pitch_ddot"
LATERAL, YAW = "mounts.y_ddot", "mounts.yaw_ddot"
BETA = "mounts.beta_design_left+mounts.beta_design_right"
TORQUE = "motor.T_level"
MU = "joint_left.mu+joint_right.mu"
PHASE = "joint_right.phi_in_start"
JOINT = "joint_left.tripod_type+joint_right.tripod_type"
JOINT_TYPES = {"plain": PLAIN_TRIPOD, "single": SINGLE_ROLLER, "double": DOUBLE_ROLLER}
"""The ``--joints`` names of TripodCoupling's ``tripod_type`` (docs/tripod_coupling.md, "Roller tripods")."""
PEAK = f"{SIGNAL}_order3_peak"
BETA_RANGE = (math.radians(5.0), math.radians(20.0))
TORQUE_RANGE = (0.2 * MOTOR_PEAK_TORQUE, MOTOR_PEAK_TORQUE)
MU_RANGE = (0.02, 0.1)
PHASE_PERIOD = 2.0 * math.pi / 3.0
"""A tripod joint turned by a third of a turn is the same joint: the relative phase repeats after it [rad]."""


def pitch_third_order(time: np.ndarray, outputs: Mapping[str, np.ndarray]) -> tuple[float, float]:
    """The peak third-order pitch acceleration [rad/s2] over the left joint's turns and its speed there [rad/s]."""
    return third_order_peak(time, outputs[SHAFT], outputs[SIGNAL])


def lateral_third_order(time: np.ndarray, outputs: Mapping[str, np.ndarray]) -> tuple[float, float]:
    """The peak third-order lateral acceleration [m/s2] over the left joint's turns and its speed there [rad/s]."""
    return third_order_peak(time, outputs[SHAFT], outputs[LATERAL])


def yaw_third_order(time: np.ndarray, outputs: Mapping[str, np.ndarray]) -> tuple[float, float]:
    """The peak third-order yaw acceleration [rad/s2] over the left joint's turns and its speed there [rad/s]."""
    return third_order_peak(time, outputs[SHAFT], outputs[YAW])


THIRD_ORDER = DerivedMetrics((SHAFT, SIGNAL), (PEAK, f"{SIGNAL}_order3_speed"), pitch_third_order, ("rad/s2", "rad/s"))
THIRD_ORDERS = (
    THIRD_ORDER,
    DerivedMetrics((SHAFT, LATERAL), (f"{LATERAL}_order3_peak", f"{LATERAL}_order3_speed"), lateral_third_order,
                   ("m/s2", "rad/s")),
    DerivedMetrics((SHAFT, YAW), (f"{YAW}_order3_peak", f"{YAW}_order3_speed"), yaw_third_order, ("rad/s2", "rad/s")),
)
PEAKS = tuple(metric.columns[0] for metric in THIRD_ORDERS)
"""The peak columns the envelope over the phases reports."""


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


def joint_types(names: str) -> list[int]:
    """The ``tripod_type`` of each comma-separated name of :data:`JOINT_TYPES` in ``names``, in their order.
    Raises ValueError naming an unknown or repeated type."""
    found = [name.strip() for name in names.split(",")]
    for name in found:
        if name not in JOINT_TYPES:
            raise ValueError(f"--joints: no joint type {name!r} (choose from {', '.join(JOINT_TYPES)})")
    if len(set(found)) < len(found):
        raise ValueError(f"--joints {names}: a type named twice")
    return [JOINT_TYPES[name] for name in found]


def joint_of(row: Mapping[str, Any]) -> int:
    """The joints' ``tripod_type`` of a map's ``row``; a table written before the type axis is the plain tripod's."""
    return int(row.get(JOINT, PLAIN_TRIPOD))


def joint_name(tripod_type: int) -> str:
    """The :data:`JOINT_TYPES` name of ``tripod_type``."""
    return next(name for name, value in JOINT_TYPES.items() if value == tripod_type)


def phases(count: int) -> list[float]:
    """``count`` phases [rad] of the right joint against the left, evenly over :data:`PHASE_PERIOD` from 0."""
    return (np.arange(count) * (PHASE_PERIOD / count)).tolist()


def axes(count: int, phase_count: int = 1, types: Sequence[int] = (PLAIN_TRIPOD,)) -> dict[str, list[float]]:
    """The map's grid axes: the joints' ``types`` (slowest), ``count`` values each (both ends included) of
    bend, torque and friction and ``phase_count`` phases (:func:`phases`)."""
    found = {name: np.linspace(*bounds, count).tolist()
             for name, bounds in ((BETA, BETA_RANGE), (TORQUE, TORQUE_RANGE), (MU, MU_RANGE))}
    return {JOINT: list(types)} | found | {PHASE: phases(phase_count)}


def envelope(table: pa.Table) -> pa.Table:
    """For each joint type, bend, torque and friction of a map's ``table`` (:func:`joint_of`): how many
    phases ran (``phases``), and for
    each peak of :data:`PEAKS` its largest value over them (``..._max``), the phase there
    (``..._worst_phase`` [rad]) and its smallest value (``..._min``); a combination whose every launch
    failed has no row. The units those of the map's columns."""
    import pyarrow as pa  # the sweep extra, as the map's own table

    units = sweep.units_of(table)
    groups: dict[tuple[int, float, float, float], list[dict]] = {}
    for row in table.to_pylist():
        if row["status"] == "ok":
            groups.setdefault((joint_of(row), row[BETA], row[TORQUE], row[MU]), []).append(row)
    columns: dict[str, list[float]] = {JOINT: [], BETA: [], TORQUE: [], MU: [], "phases": []}
    found_units = {JOINT: "1", BETA: units[BETA], TORQUE: units[TORQUE], MU: units[MU], "phases": "1"}
    for peak in PEAKS:
        for suffix, unit in (("max", units[peak]), ("worst_phase", units[PHASE]), ("min", units[peak])):
            columns[f"{peak}_{suffix}"] = []
            found_units[f"{peak}_{suffix}"] = unit
    for (joint, beta, torque, mu), rows in sorted(groups.items()):
        columns[JOINT].append(joint)
        columns[BETA].append(beta)
        columns[TORQUE].append(torque)
        columns[MU].append(mu)
        columns["phases"].append(len(rows))
        for peak in PEAKS:
            worst = max(rows, key=lambda row: row[peak])
            columns[f"{peak}_max"].append(worst[peak])
            columns[f"{peak}_worst_phase"].append(worst[PHASE])
            columns[f"{peak}_min"].append(min(row[peak] for row in rows))
    found = pa.table({name: pa.array(values, type=pa.int64() if name in (JOINT, "phases") else pa.float64())
                      for name, values in columns.items()})
    return sweep.with_units(found, found_units)


def draw(table: pa.Table, path: Path) -> Path:
    """A panel per friction coefficient, a row of them per joint type (:func:`joint_of`): the peak
    third-order pitch acceleration [rad/s2] of the worst phase (:func:`envelope`) over the bend angle [deg]
    and the launch torque [% of the motor's peak], one colour scale per type (the roller tripods' peaks are
    several times below the plain tripod's), each cell labelled with its worst phase [deg] when the map has
    several; a combination whose every launch failed is left blank. One type's panels wrap at four a row."""
    from .studies import figures  # matplotlib, when a figure is drawn: a mistake is refused before it loads

    rows = envelope(table).to_pylist()
    launches = table.to_pylist()
    betas, torques, mus = (sorted({row[name] for row in launches}) for name in (BETA, TORQUE, MU))
    joints = sorted({joint_of(row) for row in launches})
    several = len({row[PHASE] for row in launches}) > 1
    peaks = np.full((len(joints), len(mus), len(torques), len(betas)), np.nan)
    worst = np.full_like(peaks, np.nan)
    for row in rows:
        cell = joints.index(row[JOINT]), mus.index(row[MU]), torques.index(row[TORQUE]), betas.index(row[BETA])
        peaks[cell], worst[cell] = row[f"{PEAK}_max"], row[f"{PEAK}_worst_phase"]
    columns = min(4, len(mus)) if len(joints) == 1 else len(mus)
    lines = math.ceil(len(mus) / columns) * len(joints)
    fig, panels = figures.figure(lines, columns, squeeze=False, sharex=True, sharey=True,
                                 figsize=(3.2 * columns + 1.2, 2.9 * lines + 0.6), layout="constrained")
    x, y = np.degrees(betas), 100.0 * np.array(torques) / MOTOR_PEAK_TORQUE
    for t, joint in enumerate(joints):
        own = panels.flat[t * columns: t * columns + len(mus)] if len(joints) > 1 else panels
        top = np.nanmax(peaks[t]) if np.any(np.isfinite(peaks[t])) else 1.0
        for k, panel in enumerate(np.ravel(own)):
            if k >= len(mus):
                panel.set_visible(False)
                continue
            image = panel.pcolormesh(x, y, peaks[t, k], shading="nearest", vmin=0.0, vmax=top, cmap="viridis")
            if several:
                for (i, j), phase in np.ndenumerate(worst[t, k]):
                    if np.isfinite(phase):
                        panel.text(x[j], y[i], f"{math.degrees(phase):.0f}", ha="center", va="center", fontsize=6,
                                   color="white" if peaks[t, k, i, j] < 0.6 * top else "black")
            panel.set_xlim(x[0], x[-1])  # the grid's range: its outer cells shown to their values, no further
            panel.set_ylim(y[0], y[-1])
            panel.set_title(f"{joint_name(joint)}, mu = {mus[k]:.3g}" if len(joints) > 1 else f"mu = {mus[k]:.3g}",
                            fontsize=9)
        label = "peak 3rd-order pitch acceleration\n[rad/s2], worst phase"
        fig.colorbar(image, ax=own, label=f"{label}, {joint_name(joint)}" if len(joints) > 1 else label)
    for panel in panels[-1]:
        panel.set_xlabel("bend angle beta [deg]")
    for panel in panels[:, 0]:
        panel.set_ylabel("launch torque [% of peak]")
    title = f"Launch shudder map: {len(table)} launches of VehicleLaunch, both joints alike"
    if joints != [PLAIN_TRIPOD]:
        title += f" ({', '.join(joint_name(joint) for joint in joints)})"
    if several:
        title += "; worst right-joint phase [deg] in each cell"
    fig.suptitle(title, fontsize=10)
    path.parent.mkdir(parents=True, exist_ok=True)
    return figures.save(fig, path)


def main(argv: Sequence[str] | None = None) -> None:
    parser = CommandParser(description=summary(__doc__))
    parser.add_argument("--package", type=Path, default=Path("models") / "native" / "VehicleLaunch.ssp",
                        help="the launch's SSP package (default models/native/VehicleLaunch.ssp)")
    parser.add_argument("--count", type=int, default=8, help="values per axis of bend, torque and friction (default 8)")
    parser.add_argument("--phases", type=int, default=4,
                        help="phases of the right joint over a third of a turn (default 4: 0, 30, 60, 90 deg; "
                             "2,048 launches with --count 8)")
    parser.add_argument("--joints", default="plain",
                        help=f"joint types of both joints, comma-separated, of {', '.join(JOINT_TYPES)} "
                             "(default plain; each further type as many launches again)")
    parser.add_argument("--duration", type=float, default=4.0, help="launch length [s] (default 4)")
    parser.add_argument("--step", type=float, default=2e-4, help="communication step [s] (default 2e-4)")
    parser.add_argument("--master", choices=sweep.MASTERS, default=sweep.DEFAULT_MASTER,
                        help=f"default {sweep.DEFAULT_MASTER} (docs/vehicle_launch.md, 'Throughput')")
    parser.add_argument("--workers", type=sweep.workers_count, default=sweep.default_workers(),
                        help="local cluster size")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://host:8786")
    parser.add_argument("--out", type=sweep.table_file, default=Path("results") / "shudder_map.parquet",
                        help=".parquet or .csv")
    parser.add_argument("--envelope", type=sweep.table_file, default=Path("results") / "shudder_map_envelope.csv",
                        help="the envelope over the phases, .csv or .parquet")
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
    if args.phases < 1:
        parser.error(f"--phases must be at least 1, got {args.phases}")
    too_short = duration_error(args.duration)
    if too_short:
        parser.error(too_short)
    try:
        types = joint_types(args.joints)
        plan = sweep.Plan.of_system(args.package, sweep.grid(axes(args.count, args.phases, types)), args.duration,
                                    args.step, args.master, THIRD_ORDERS)
        if args.scheduler:
            sweep.check_scheduler(args.scheduler)
    except (ValueError, OSError) as error:
        parser.error(str(error))
    table = sweep.run_plan(plan, args.scheduler, args.workers)
    sweep.write_table(table, args.out)
    failed = sweep.failure_reasons(table)
    if failed.total() < table.num_rows:
        sweep.write_table(envelope(table), args.envelope)
        print(args.envelope)
        print(draw(table, args.figure))
    print(f"{table.num_rows} launches, {failed.total()} failed -> {args.out}")
    sweep.print_reasons(failed)
    if failed.total() == table.num_rows:
        sys.exit(f"{COMMAND}: every launch failed, no figure drawn")


if __name__ == "__main__":
    # Dask pickles ``__main__`` functions by value; run the module's own import instead.
    importlib.import_module(__spec__.name).main()
