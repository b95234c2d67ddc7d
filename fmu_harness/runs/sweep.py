"""Parameter sweeps of one FMU or of an SSP system on Dask distributed: one run per point, one tidy table.

Usage::

    python -m fmu_harness.runs.sweep --grid beta=0:0.7:8 omega_in=100,200,300 r=0.02,0.026
    python -m fmu_harness.runs.sweep --model CardanJoint --points points.csv --out cardan.parquet
    python -m fmu_harness.runs.sweep --grid beta=0.1,0.3 --scheduler tcp://host:8786
    python -m fmu_harness.runs.sweep --system models/native/VehicleLaunch.ssp --step 4e-4 \
        --grid mounts.beta_design_left+mounts.beta_design_right=0.1,0.2 motor.T_level=100,200

A grid axis is ``name=v1,v2,...`` or ``name=start:stop:count`` (``count`` values, both ends
included); the grid is the cartesian product of its axes. A points file is CSV (a header of
names) or JSON (a list of objects). Each name must be a parameter (set as a start value) or an
input (held constant) of the FMU. A run lasts ``--turns`` input turns at the point's
``omega_in`` in ``--steps-per-turn`` steps unless ``--duration`` / ``--step`` are given.

With ``--system`` each point is one run of the whole system, its names ``component.variable``
(several joined by ``+`` take the same value), by the ``--master`` of
:mod:`fmu_harness.runs.system_sweep`; the package is shipped and unpacked like an FMU.

Every point of an FMU sweep is one :func:`fmu_harness.runs.runner.simulate` call on a worker. The FMU's bytes are
scattered to the workers once, extracted and their model description parsed once per worker
process, so workers need no shared file system. A refused or crashed run becomes a ``failed``
row with its reason; a point whose parameters break the spec's bounds or relations, which the
FMU would refuse at initialisation, is not run (:mod:`fmu_harness.runs.start_values`). The command
ends non-zero when every run failed and names the distinct reasons, before any worker starts when
every point is refused so. Its arguments, the FMU or package, the layout and the scheduler's
address are checked before the cluster starts; Dask and pyarrow (the ``sweep`` extra) are imported
when a sweep runs, so ``--help`` needs neither.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import importlib
import itertools
import json
import logging
import math
import os
import socket
import sys
import tempfile
import threading
import zipfile
from collections import Counter
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from fmpy import extract, read_model_description
from fmpy.model_description import ModelDescription

from driveline.catalog import MODELS

from ..console import CommandParser, Progress, optional, refused, summary
from .result_table import headed, unheaded, unit_of
from .runner import StepRefused, simulate
from .start_values import refusals
from .system_sweep import (
    MASTERS,
    STATISTICS,
    DerivedMetrics,
    SystemInterface,
    UnpackedSystem,
    container_of,
    run_system,
    stop_and_step,
)

if TYPE_CHECKING:
    import pyarrow as pa
    from distributed import Client, Future

COMMAND = "driveline-fmus sweep"
EXTRA = "sweep"

Value = float | int | str
Point = dict[str, Value]

SPEED = "omega_in"
"""The input whose turns set the default run length."""

GENERIC = ("min", "max", "mean")
"""Statistics of every Real output of any FMU, as columns ``<output>_<statistic>``."""
SPECIFIC: dict[str, tuple[tuple[str, str], ...]] = {
    "TripodCoupling": (
        ("delta_phi", "peak_abs"),
        ("Rz_out", "p2p"),
        ("Rx_in", "p2p"),
        ("Ry_in", "p2p"),
        ("Rx_in", "peak_abs"),
        ("Ry_in", "peak_abs"),
        ("Rx_out", "peak_abs"),
        ("Ry_out", "peak_abs"),
        ("Rz_out", "peak_abs"),
        ("omega_out", "p2p"),
    ),
}
"""Further (output, statistic) columns per model name."""

DEFAULT_MODEL = "TripodCoupling"
DEFAULT_MASTER = "gauss-seidel"
"""The master of a system sweep: see docs/sweeps.md for the measured choice."""

CRITICAL_SPEEDS_MODEL = "CriticalSpeeds"
MARGIN = "critical_speed_margin"


def _value(text: str) -> Value:
    """A number from its text (int if it reads as one), else the text itself."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def parse_axis(text: str) -> tuple[str, list[Value]]:
    """``name=v1,v2,...`` or ``name=start:stop:count`` -> (name, values)."""
    name, sep, values = text.partition("=")
    if not (sep and name and values):
        raise ValueError(f"grid axis {text!r}: expected name=v1,v2,... or name=start:stop:count")
    bounds = values.split(":")
    if len(bounds) == 3:
        return name, np.linspace(float(bounds[0]), float(bounds[1]), int(bounds[2])).tolist()
    return name, [_value(v) for v in values.split(",")]


def grid(axes: Mapping[str, Sequence[Value]]) -> list[Point]:
    """Cartesian product of named value lists, the last axis varying fastest."""
    return [dict(zip(axes, values)) for values in itertools.product(*axes.values())]


def read_points(path: Path) -> list[Point]:
    """Points from a CSV file (header of names) or a JSON file (list of objects)."""
    if path.suffix.lower() == ".json":
        return [dict(point) for point in json.loads(path.read_text())]
    with path.open(newline="") as handle:
        return [{k: _value(v) for k, v in row.items()} for row in csv.DictReader(handle)]


@dataclass(frozen=True)
class Timing:
    """Length and step of every run.

    By default ``turns`` input turns at the point's ``omega_in`` in ``steps_per_turn`` steps;
    ``duration`` and ``step_size`` [s] override either. An FMU without an ``omega_in`` input
    runs its default experiment unless both are given.
    """

    turns: int = 1
    steps_per_turn: int = 360
    duration: float | None = None
    step_size: float | None = None

    def __post_init__(self) -> None:
        for name, count in (("turns", self.turns), ("steps per turn", self.steps_per_turn)):
            if not (isinstance(count, int) and count >= 1):
                raise ValueError(f"{name} must be a whole number of at least 1, got {count!r}")
        for name, seconds in (("duration", self.duration), ("step", self.step_size)):
            if seconds is not None and not (math.isfinite(seconds) and seconds > 0.0):
                raise ValueError(f"the {name} must be a finite positive number of seconds, got {seconds!r}")

    def resolve(self, speed: float | None, default: tuple[float, float] | None) -> tuple[float, float]:
        """(stop time, step size) for a run at input speed ``speed`` [rad/s]."""
        if self.duration is not None and self.step_size is not None:
            return self.duration, self.step_size
        if speed is not None:
            if not (math.isfinite(speed) and speed != 0.0):
                raise ValueError(f"a run of whole input turns needs a finite non-zero {SPEED}, got {speed!r}")
            turn = 2.0 * math.pi / abs(speed)
            default = self.turns * turn, turn / self.steps_per_turn
        elif default is None:
            raise ValueError(f"the FMU has no {SPEED} input and no default experiment: give a duration and step size")
        return (
            default[0] if self.duration is None else self.duration,
            default[1] if self.step_size is None else self.step_size,
        )


@dataclass(frozen=True)
class Interface:
    """What a sweep needs of an FMU's model description."""

    model: str
    causality: dict[str, str]
    """Causality (``parameter`` or ``input``) of every settable variable."""
    outputs: tuple[str, ...]
    """Real outputs, summarised per run."""
    speed_start: float | None
    """Start value of the ``omega_in`` input; None without one."""
    default_experiment: tuple[float, float] | None
    units: dict[str, str] = field(default_factory=dict)
    """The unit of every settable variable and Real output (``1`` without one)."""

    @classmethod
    def of(cls, path: Path) -> Interface:
        description = read_model_description(str(path))
        variables = description.modelVariables
        speed = [v for v in variables if v.name == SPEED and v.causality == "input"]
        experiment = description.defaultExperiment
        return cls(
            model=description.modelName,
            causality={v.name: v.causality for v in variables if v.causality in ("parameter", "input")},
            outputs=tuple(
                v.name for v in variables if v.causality == "output" and v.type in ("Real", "Float64", "Float32")
            ),
            speed_start=float(speed[0].start) if speed and speed[0].start is not None else None,
            default_experiment=(
                (float(experiment.stopTime), float(experiment.stepSize))
                if experiment and experiment.stopTime and experiment.stepSize
                else None
            ),
            units={v.name: unit_of(v) for v in variables},
        )

    def split(self, point: Point) -> tuple[Point, Point]:
        """(start values, constant inputs) of a point; unknown names raise ValueError."""
        unknown = sorted(set(point) - set(self.causality))
        if unknown:
            raise ValueError(
                f"{', '.join(unknown)}: no parameter or input of {self.model} "
                f"(settable: {', '.join(self.causality)})"
            )
        parameters = {k: v for k, v in point.items() if self.causality[k] == "parameter"}
        return parameters, {k: v for k, v in point.items() if self.causality[k] == "input"}

    def speed(self, point: Point) -> float | None:
        """The point's input speed [rad/s] (its value or the FMU's start value)."""
        return None if self.speed_start is None else float(point.get(SPEED, self.speed_start))

    def statistics(self) -> list[tuple[str, str]]:
        """(output, statistic) of every metric column."""
        generic = [(output, statistic) for output in self.outputs for statistic in GENERIC]
        return generic + [s for s in SPECIFIC.get(self.model, ()) if s[0] in self.outputs]

    def metric_columns(self) -> list[str]:
        return [f"{output}_{statistic}" for output, statistic in self.statistics()]

    def metric_units(self) -> list[str]:
        """The unit of each of :meth:`metric_columns`: its output's (every statistic keeps it)."""
        return [self.units[output] for output, _ in self.statistics()]

    def unit(self, name: str) -> str:
        """The unit of a point's name."""
        return self.units[name]

    def run(
        self,
        path: Path,
        point: Point,
        timing: Timing,
        unzipdir: str | None = None,
        description: ModelDescription | None = None,
    ) -> dict[str, Any]:
        """One FMU run of ``point``: status, reason and metrics, never an exception. ``unzipdir``
        and ``description``: the FMU already extracted and its model description parsed."""
        try:
            start_values, inputs = self.split(point)
            stop_time, step_size = timing.resolve(self.speed(point), self.default_experiment)
            result = simulate(
                path, stop_time, step_size, inputs, start_values, self.outputs, unzipdir=unzipdir, description=description
            )
        except Exception as error:  # noqa: BLE001 - any failure of a run is a result of the sweep
            return failed(error)
        metrics = {
            f"{output}_{statistic}": float(STATISTICS[statistic](result[output]))
            for output, statistic in self.statistics()
        }
        return {"status": "ok", "reason": None, **metrics}


def failed(error: BaseException) -> dict[str, Any]:
    """The status and reason columns of a failed run."""
    reason = str(error) if isinstance(error, StepRefused) else f"{type(error).__name__}: {error}"
    return {"status": "failed", "reason": reason}


@dataclass(frozen=True)
class ShippedFmu:
    """An FMU's bytes and interface, scattered once to every worker."""

    interface: Interface
    digest: str
    data: bytes

    @classmethod
    def read(cls, path: Path) -> ShippedFmu:
        data = path.read_bytes()
        return cls(Interface.of(path), hashlib.sha256(data).hexdigest(), data)

    def run(self, point: Point, timing: Timing) -> dict[str, Any]:
        """On a worker: one run of ``point``."""
        unpacked = _unpacked(self)
        return self.interface.run(unpacked.path, point, timing, unpacked.unzipdir, unpacked.description)


@dataclass(frozen=True)
class ShippedSystem:
    """An SSP package's bytes and interface with the runs' stop time, step and master, scattered once
    to every worker (:mod:`fmu_harness.runs.system_sweep`)."""

    interface: SystemInterface
    digest: str
    data: bytes
    stop_time: float
    step_size: float
    master: str
    container: bytes | None = None
    """The package as one container FMU for the master's scheme and step (:func:`container_of`), if it runs one."""

    @classmethod
    def read(cls, path: Path, duration: float | None, step_size: float | None, master: str,
             derived: Sequence[DerivedMetrics] = ()) -> ShippedSystem:
        """Raises ValueError for a package that cannot be read, a bad timing or an unknown master."""
        if master not in MASTERS:
            raise ValueError(f"no master {master!r} (the masters: {', '.join(MASTERS)})")
        interface = SystemInterface.of(path, derived)
        data = path.read_bytes()
        return cls(interface, hashlib.sha256(data).hexdigest(), data, *stop_and_step(interface, duration, step_size),
                   master)

    def contained(self, path: Path) -> ShippedSystem:
        """The same with the package at ``path`` as its master's container (:func:`container_of`), when one runs it."""
        built = container_of(path, self.interface, self.step_size, self.master)
        if built is None:
            return self
        return replace(self, digest=hashlib.sha256(self.data + built).hexdigest(), container=built)

    def run(self, point: Point, timing: Timing) -> dict[str, Any]:
        """On a worker: one run of the system at ``point`` (``timing`` is the FMU sweep's, unused)."""
        try:
            with _UNPACK_LOCK:
                if self.digest not in _UNPACKED:
                    folder = _scratch() / f"ssp-{self.digest[:16]}"
                    _UNPACKED[self.digest] = UnpackedSystem.write(self.data, folder, self.interface, self.container)
            with tempfile.TemporaryDirectory(dir=_scratch()) as scratch:
                metrics = run_system(self.interface, _UNPACKED[self.digest], point, self.stop_time, self.step_size,
                                     self.master, Path(scratch))
        except Exception as error:  # noqa: BLE001 - any failure of a run is a result of the sweep
            return failed(error)
        return {"status": "ok", "reason": None, **metrics}


@dataclass(frozen=True)
class UnpackedFmu:
    """An FMU on a worker: its file, extracted folder and parsed model description."""

    path: Path
    unzipdir: str
    description: ModelDescription


_UNPACKED: dict[str, UnpackedFmu | UnpackedSystem] = {}
_UNPACK_LOCK = threading.Lock()


def _scratch() -> Path:
    """The worker's scratch space."""
    from distributed import get_worker

    return Path(get_worker().local_directory)


def _unpacked(fmu: ShippedFmu) -> UnpackedFmu:
    """The FMU written, extracted and parsed once per worker process in the worker's scratch space."""
    with _UNPACK_LOCK:
        if fmu.digest not in _UNPACKED:
            folder = _scratch() / f"fmu-{fmu.digest[:16]}"
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / f"{fmu.interface.model}.fmu"
            path.write_bytes(fmu.data)
            unzipdir = extract(path, unzipdir=folder / "extracted")
            _UNPACKED[fmu.digest] = UnpackedFmu(path, unzipdir, read_model_description(unzipdir))
        return _UNPACKED[fmu.digest]


def run_point(shipped: ShippedFmu | ShippedSystem, point: Point, timing: Timing) -> dict[str, Any]:
    """Worker task: run one point of the sweep."""
    return shipped.run(point, timing)


def _outcome(future: Future) -> dict[str, Any]:
    """A task's row: its result, or a failure when it raised, lost its worker or was cancelled."""
    if future.status == "finished":
        return future.result()
    if future.status == "error":
        return failed(future.exception())
    return {"status": "failed", "reason": f"the Dask task was {future.status}"}


def critical_speeds(layout: str = "") -> list[float] | None:
    """The first three forward critical speeds [rad/s] of the driveline ``layout``, or None while
    the catalog holds no ``CriticalSpeeds`` model; a layout the model refuses raises ValueError.

    They are the outputs ``omega_crit_1..3`` of the catalog's ``CriticalSpeeds`` model, the code
    its FMU wraps, initialised at its start values with ``layout`` (its ``layout`` parameter: a
    TOML file or the name of a shipped description, read by the model's own loader): the sweep
    reads the model through its declared interface only, runs on the client, which may not hold
    the CriticalSpeeds FMU, and needs no FMU instance for it."""
    model_class = MODELS.get(CRITICAL_SPEEDS_MODEL)
    if model_class is None:
        return None
    model = model_class()
    model.layout = layout
    errors = model.initialize(0.0)
    if errors:
        raise ValueError(f"{CRITICAL_SPEEDS_MODEL} with layout {layout!r}: {'; '.join(errors)}")
    return [getattr(model, f"omega_crit_{k}") for k in (1, 2, 3)]


def critical_speed_margins(speeds: Sequence[float], critical: Sequence[float]) -> list[float]:
    """``(|speed| - n_c) / n_c`` for the nearest ``n_c`` of the ``critical`` speeds. The sign
    follows the ``CriticalSpeeds`` model's ``resonance_margin`` (negative below the critical
    speed); a speed that is zero or not finite has no margin (NaN)."""

    def margin(speed: float) -> float:
        if not (math.isfinite(speed) and speed != 0.0):
            return math.nan
        nearest = min(critical, key=lambda c: abs(c - abs(speed)))
        return (abs(speed) - nearest) / nearest

    return [margin(speed) for speed in speeds]


@dataclass(frozen=True)
class Plan:
    """A sweep checked before anything runs: the FMU read, every point's names known to it, the
    timing valid, the points the FMU would refuse (:func:`refused_points`, not run) and the
    critical speeds of the margin (None when there is no margin)."""

    fmu: ShippedFmu | ShippedSystem
    points: Sequence[Point]
    timing: Timing
    refused: dict[int, str]
    critical: list[float] | None

    @classmethod
    def of(cls, fmu: Path, points: Sequence[Point], timing: Timing = Timing(), layout: str = "") -> Plan:
        """Raises ValueError for no points, unknown names or a refused layout, OSError or BadZipFile for an
        unreadable FMU."""
        if not points:
            raise ValueError("no points to run")
        shipped = ShippedFmu.read(fmu)
        for point in points:
            shipped.interface.split(point)
        refused = refused_points(shipped.interface.model, points)
        if shipped.interface.speed_start is None:
            if layout:
                raise ValueError(f"the layout sets the critical-speed margin, which needs an {SPEED} input: "
                                 f"{shipped.interface.model} has none")
            return cls(shipped, points, timing, refused, None)
        return cls(shipped, points, timing, refused, critical_speeds(layout))

    @classmethod
    def of_system(cls, package: Path, points: Sequence[Point], duration: float | None, step_size: float | None,
                  master: str, derived: Sequence[DerivedMetrics] = ()) -> Plan:
        """A sweep of the SSP system ``package`` (:mod:`fmu_harness.runs.system_sweep`): every run lasts
        ``duration`` (default the package's stop time) in steps of ``step_size`` by ``master``, with the
        ``derived`` metrics besides the system's own. Raises
        ValueError for no points, a package that cannot be read, a bad timing or an unknown name; the
        points a component would refuse or whose step is too long are not run."""
        if not points:
            raise ValueError("no points to run")
        shipped = ShippedSystem.read(package, duration, step_size, master, derived)
        for point in points:
            shipped.interface.changes(point)
        found = {i: shipped.interface.refusal(point, shipped.step_size, master) for i, point in enumerate(points)}
        refused = {i: reason for i, reason in found.items() if reason}
        if len(refused) < len(points):
            shipped = shipped.contained(package)
        return cls(shipped, points, Timing(), refused, None)


def run(client: Client, plan: Plan, show_progress: bool = False) -> pa.Table:
    """Run every point of ``plan`` on the client's workers; one row per point, in its order.

    Columns: the points' names, ``status`` (ok/failed), ``reason`` (null when ok), the
    metrics of :meth:`Interface.statistics` (null when failed) and, when available,
    ``critical_speed_margin`` (see :func:`critical_speed_margins`; null without one). Every numeric column carries its
    unit as the field's metadata :data:`UNIT_KEY` (:func:`with_units`).
    """
    pa = optional("pyarrow", EXTRA, COMMAND)
    distributed = optional("distributed", EXTRA, COMMAND)
    interface, points = plan.fmu.interface, plan.points
    payload = client.scatter(plan.fmu, broadcast=True, hash=False)
    futures = {i: client.submit(run_point, payload, point, plan.timing, pure=False)
               for i, point in enumerate(points) if i not in plan.refused}
    at = {future.key: points[i] for i, future in futures.items()}
    with Progress("sweep", len(futures), enabled=show_progress) as shown:
        for future in distributed.as_completed(futures.values()):
            shown.advance(" ".join(f"{k}={v}" for k, v in at[future.key].items()) + f": {_outcome(future)['status']}")
    rows = [{**point, **({"status": "failed", "reason": plan.refused[i]} if i in plan.refused
                         else _outcome(futures[i]))} for i, point in enumerate(points)]
    metrics = interface.metric_columns()
    names = list(dict.fromkeys(name for point in points for name in point))
    types = {"status": pa.string(), "reason": pa.string(), **{m: pa.float64() for m in metrics}}
    columns = [*names, "status", "reason", *metrics]
    table = pa.table({c: pa.array([row.get(c) for row in rows], types.get(c)) for c in columns})
    units = {**{name: interface.unit(name) for name in names}, **dict(zip(metrics, interface.metric_units()))}
    if plan.critical is not None:
        margins = critical_speed_margins([interface.speed(point) for point in points], plan.critical)
        table = table.append_column(MARGIN, pa.array(margins, pa.float64(), from_pandas=True))  # NaN: null
        units[MARGIN] = "1"
    return with_units(table, units)


UNIT_KEY = b"unit"
"""The key of a numeric column's unit in its Parquet field's metadata."""


def with_units(table: pa.Table, units: Mapping[str, str]) -> pa.Table:
    """``table`` with each numeric column's unit of ``units`` as its field's metadata :data:`UNIT_KEY`; a
    text column (a point's text values, ``status``, ``reason``) carries none."""
    pa = optional("pyarrow", EXTRA, COMMAND)
    fields = [f.with_metadata({UNIT_KEY: units[f.name].encode()})
              if pa.types.is_integer(f.type) or pa.types.is_floating(f.type) else f for f in table.schema]
    return table.cast(pa.schema(fields))


def units_of(table: pa.Table) -> dict[str, str]:
    """``{column: unit}`` of a table's numeric columns (:func:`with_units`)."""
    return {f.name: f.metadata[UNIT_KEY].decode() for f in table.schema if f.metadata and UNIT_KEY in f.metadata}


def sweep(
    client: Client,
    fmu: Path,
    points: Sequence[Point],
    timing: Timing = Timing(),
    show_progress: bool = False,
    layout: str = "",
) -> pa.Table:
    """:func:`run` of the :class:`Plan` of these arguments."""
    return run(client, Plan.of(fmu, points, timing, layout), show_progress)


def refused_points(model: str, points: Sequence[Point]) -> dict[int, str]:
    """``{index: reason}`` of the points whose values the FMU of ``model`` would refuse at
    initialisation by the spec's bounds and relations (its first reason); such a point is not
    run. The model's own checks (a structural analysis) are left to the run on a worker."""
    found = {i: refusals(model, point, declared_only=True) for i, point in enumerate(points)}
    return {i: reasons[0] for i, reasons in found.items() if reasons}


def write_table(table: pa.Table, path: Path) -> None:
    """Parquet, the units in the fields' metadata, or CSV when ``path`` ends in ``.csv``, each numeric
    column headed ``name [unit]`` (:func:`fmu_harness.runs.result_table.headed`), a text column ``name``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix.lower() == ".csv":
        units = units_of(table)
        headers = [headed(name, units[name]) if name in units else name for name in table.column_names]
        optional("pyarrow.csv", EXTRA, COMMAND).write_csv(table.rename_columns(headers), path)
    else:
        optional("pyarrow.parquet", EXTRA, COMMAND).write_table(table, path)


def failure_reasons(table: pa.Table) -> Counter[str]:
    """How many runs failed for each distinct reason."""
    return Counter(r for s, r in zip(table.column("status").to_pylist(), table.column("reason").to_pylist())
                   if s == "failed")


def print_reasons(reasons: Counter[str]) -> None:
    """Each distinct reason of failed runs with their number, most frequent first, on standard error."""
    for reason, count in reasons.most_common():
        print(f"  {count} failed: {reason}", file=sys.stderr)


@contextmanager
def open_client(scheduler: str | None = None, workers: int = 2) -> Iterator[Client]:
    """A client of the scheduler at ``scheduler``, else of a local cluster of ``workers``
    single-threaded worker processes (closed on exit)."""
    distributed = optional("distributed", EXTRA, COMMAND)
    if scheduler:
        try:
            client = distributed.Client(scheduler, timeout=CONNECT_SECONDS)
        except (OSError, TimeoutError) as error:
            raise SystemExit(f"{COMMAND}: no Dask scheduler answered at {scheduler} ({error})") from None
        with client:
            yield client
        return
    # a worker whose heartbeat meets the scheduler already closed at the end logs a traceback (a known race of
    # Dask's shutdown): the local cluster's own logs stay below CRITICAL; what a run raises is its row's reason
    cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                                       silence_logs=logging.CRITICAL)
    with cluster, distributed.Client(cluster) as client:
        yield client


CONNECT_SECONDS = 5.0
"""How long the sweep tries to reach a scheduler."""


def check_scheduler(address: str, seconds: float = CONNECT_SECONDS) -> None:
    """ValueError in one line unless something listens at the TCP scheduler address ``address``
    (``tcp://host:port``, ``host:port``); another protocol is left to Dask."""
    scheme, _, location = address.rpartition("://")
    if scheme not in ("", "tcp", "tls"):
        return
    host, colon, port = location.rpartition(":")
    if not (colon and host and port.isdigit()):
        raise ValueError(f"--scheduler {address}: expected tcp://host:port")
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=seconds).close()
    except OSError as error:
        raise ValueError(f"--scheduler {address}: no scheduler answers there ({error.strerror or error})") from None


TABLE_SUFFIXES = (".parquet", ".csv")


def table_file(text: str) -> Path:
    """An argparse type: the file a sweep's table goes to, Parquet or CSV by its suffix."""
    path = Path(text)
    if path.suffix.lower() not in TABLE_SUFFIXES:
        raise argparse.ArgumentTypeError(f"{text}: write a .parquet or a .csv file")
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{text}: a folder, not a file to write")
    return path


def workers_count(text: str) -> int:
    """An argparse type: the number of local workers, at least 1."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number of at least 1, got {text}")
    return value


def default_workers() -> int:
    """Local workers by default: one per core."""
    return os.cpu_count() or 1


def _fmu_file(models: Path, model: str) -> Path:
    """The FMU ``model`` in ``models``; ValueError naming the FMUs there when it is not one of them."""
    path = models / f"{model}.fmu"
    if path.is_file():
        return path
    if not models.is_dir():
        raise ValueError(f"no folder {models} of built FMUs (`driveline-fmus build` builds them; --models names another)")
    built = sorted(p.stem for p in models.glob("*.fmu"))
    there = f"the FMUs there: {', '.join(built)}" if built else "none is there"
    raise ValueError(f"no FMU {path} ({there}; `driveline-fmus build` builds them)")


def run_plan(plan: Plan, scheduler: str | None, workers: int) -> pa.Table:
    """:func:`run` of a checked plan on the scheduler at ``scheduler`` or a local cluster of ``workers``,
    with progress; ends the command first when every point is refused (naming the reasons) or an
    optional package the run needs is missing."""
    if len(plan.refused) == len(plan.points):
        reasons = Counter(plan.refused.values())
        more = len(reasons) - 1
        raise refused(COMMAND, f"every point, none run: {reasons.most_common(1)[0][0]}"
                               + (f" (and {more} more reason{'s' * (more > 1)})" if more else ""))
    optional("pyarrow", EXTRA, COMMAND)  # before the cluster starts
    if isinstance(plan.fmu, ShippedSystem) and plan.fmu.master == "libcosim":
        optional("libcosimpy", "interop", f"{COMMAND} --master libcosim")
    what = plan.fmu.interface.name if isinstance(plan.fmu, ShippedSystem) else plan.fmu.interface.model
    with open_client(scheduler, workers) as client:
        print(f"{len(plan.points)} runs of {what} on {client.scheduler.address}")
        return run(client, plan, show_progress=True)


def read_table(path: Path) -> pa.Table:
    """A table :func:`write_table` wrote, its columns by name and their units in the fields' metadata."""
    if path.suffix.lower() == ".csv":
        table = optional("pyarrow.csv", EXTRA, COMMAND).read_csv(path)
        names, units = zip(*map(unheaded, table.column_names))
        return with_units(table.rename_columns(list(names)), {n: u for n, u in zip(names, units) if u is not None})
    return optional("pyarrow.parquet", EXTRA, COMMAND).read_table(path)


def main(argv: list[str] | None = None) -> None:
    parser = CommandParser(description=summary(__doc__))
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--grid", nargs="+", metavar="AXIS", help="name=v1,v2,... or name=start:stop:count")
    source.add_argument("--points", type=Path, help="CSV or JSON file of points")
    swept = parser.add_mutually_exclusive_group()
    swept.add_argument("--model", help=f"FMU name (default {DEFAULT_MODEL})")
    swept.add_argument("--system", type=Path, help="an SSP package: names are component.variable, joined by +")
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs")
    parser.add_argument("--turns", type=int, default=1, help=f"run length in turns of {SPEED} (default 1)")
    parser.add_argument("--steps-per-turn", type=int, default=360, help="steps of one turn of the run")
    parser.add_argument("--duration", type=float,
                        help="run length [s] instead of whole turns (of a system: instead of its stop time)")
    parser.add_argument("--step", type=float, help="communication step size [s] (needed by a system)")
    parser.add_argument("--master", choices=MASTERS, default=DEFAULT_MASTER,
                        help=f"the master of a system sweep (default {DEFAULT_MASTER})")
    parser.add_argument("--workers", type=workers_count, default=default_workers(), help="local cluster size")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://host:8786")
    parser.add_argument(
        "--layout", default="", help="driveline of the critical-speed margin: TOML file or shipped name"
    )
    parser.add_argument("--out", type=table_file, default=Path("results/sweep.parquet"), help=".parquet or .csv")
    args = parser.parse_args(argv)

    try:
        points = grid(dict(map(parse_axis, args.grid))) if args.grid else read_points(args.points)
        if args.system is not None:
            if args.layout:
                raise ValueError("--layout sets the critical-speed margin of an FMU sweep, not of a system")
            plan = Plan.of_system(args.system, points, args.duration, args.step, args.master)
        else:
            timing = Timing(args.turns, args.steps_per_turn, args.duration, args.step)
            plan = Plan.of(_fmu_file(args.models, args.model or DEFAULT_MODEL), points, timing, args.layout)
        if args.scheduler:
            check_scheduler(args.scheduler)
    except (ValueError, OSError, zipfile.BadZipFile) as error:
        parser.error(str(error))
    table = run_plan(plan, args.scheduler, args.workers)
    write_table(table, args.out)
    reasons = failure_reasons(table)
    print(f"{table.num_rows} runs, {reasons.total()} failed -> {args.out}")
    print_reasons(reasons)
    if reasons.total() == table.num_rows:
        sys.exit(f"{COMMAND}: every run failed")


if __name__ == "__main__":
    # Dask pickles ``__main__`` functions by value; run the module's own import instead.
    importlib.import_module(__spec__.name).main()
