"""Sweeps of an SSP system (``driveline-fmus sweep --system PACKAGE.ssp``): one run of the whole system
per point, its components' parameters set from the point.

A point's names are ``component.variable``: a parameter of the component's FMU or an input no
connection feeds. One name may join several with ``+`` and set them all to its value:
``mounts.beta_design_left+mounts.beta_design_right=0.1,0.2`` bends both halfshafts alike. The package's own bindings hold
for everything a point leaves alone.

Masters (``--master``): ``jacobi``, the project's fixed-step Jacobi master
(:func:`fmu_harness.runs.system.run_jacobi`); ``gauss-seidel``, the same master stepping the
components one after the other in the package's order (for ``VehicleLaunch.ssp`` that is
:data:`fmu_harness.runs.system.LAUNCH_ORDER`). Both run in the package's container
(:mod:`fmu_harness.runs.container`, built once by the client for the master's scheme and step and
sent to every worker), which gives the master's results bit for bit at a fraction of its cost; a
package the container cannot carry (Python FMUs) runs in the master itself. ``libcosim``, libcosim's Jacobi master running the
whole launch in C++ (:func:`fmu_harness.runs.libcosim_run.cosim_run`; the ``interop`` extra). A point
whose start values a component would refuse, or whose step is above a ``VehicleDriveline``'s
limit for a Jacobi coupling (``jacobi`` and ``libcosim``), is not run: its row fails with the reason.
"""

from __future__ import annotations

import functools
import math
import tempfile
import zipfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from fmpy import extract, read_model_description
from fmpy.model_description import ModelDescription

from . import container, ssp_package
from .libcosim_run import cosim_run
from .result_table import unit_of
from .ssp_package import SspSystem
from .start_values import refusals
from .system import run_jacobi, step_limit_error

MASTERS = ("jacobi", "gauss-seidel", "libcosim")
CONTAINED = ("jacobi", "gauss-seidel")  # the masters a container runs
JOIN = "+"
Value = float | int | str
Point = dict[str, Value]
Target = tuple[str, str]

SYSTEM_METRICS: dict[str, tuple[tuple[str, str], ...]] = {
    "VehicleLaunch": (
        ("drive.v_x", "max"),
        ("drive.T_load_left", "peak_abs"),
        ("drive.T_load_right", "peak_abs"),
        ("joint_left.Rz_in", "peak_abs"),
        ("joint_right.Rz_in", "peak_abs"),
        ("mounts.pitch_ddot", "peak_abs"),
        ("mounts.x_ddot", "peak_abs"),
        ("mounts.z_ddot", "peak_abs"),
    ),
}
"""(output, statistic) metric columns of the systems the project packages; any other system gets
the :data:`GENERIC` statistics of every Real output of every component."""
GENERIC = ("min", "max", "mean")


@dataclass(frozen=True)
class DerivedMetrics:
    """Metric columns a study computes from a run's recorded outputs on the worker (the shudder map's
    third-order peak, :mod:`fmu_harness.shudder_map`): ``compute(time, {output: values})`` gives the
    values of ``columns``, in ``units``, from the ``outputs`` it names. ``compute`` travels to the workers
    by reference: a module-level function of an importable module."""

    outputs: tuple[str, ...]
    columns: tuple[str, ...]
    compute: Callable[[np.ndarray, dict[str, np.ndarray]], Sequence[float]]
    units: tuple[str, ...]

    def __post_init__(self) -> None:
        if len(self.units) != len(self.columns):
            raise ValueError(f"{len(self.columns)} derived metrics {', '.join(self.columns)} with "
                             f"{len(self.units)} units: give each one")


def targets(name: str) -> list[Target]:
    """``a.x+b.y`` -> ``[("a", "x"), ("b", "y")]``; ValueError for a part that is no ``component.variable``."""
    found = []
    for part in name.split(JOIN):
        component, dot, variable = part.partition(".")
        if not (dot and component and variable):
            raise ValueError(f"{name}: each name of a system sweep is component.variable (several joined by {JOIN})")
        found.append((component, variable))
    return found


@dataclass(frozen=True)
class SystemInterface:
    """What a sweep needs of an SSP package: its components' models, what a point may set, the
    package's bindings and connections, and the Real outputs."""

    name: str
    models: dict[str, str]
    """Each component's model name (its FMU's ``modelName``), in the package's order."""
    settable: dict[Target, str]
    """FMI type of each parameter and unconnected input, by (component, variable)."""
    package: SspSystem
    outputs: tuple[str, ...]
    """Every Real output as ``component.variable``."""
    derived: tuple[DerivedMetrics, ...] = ()
    units: dict[str, str] = field(default_factory=dict)
    """The unit of every settable variable and Real output, by ``component.variable`` (``1`` without one)."""

    @classmethod
    def of(cls, path: Path, derived: Sequence[DerivedMetrics] = ()) -> SystemInterface:
        """The package's interface with the ``derived`` metrics; raises :class:`ssp_package.PackageError`
        (a ValueError) for a package that cannot be read, ValueError for a derived metric's output the
        system has not."""
        package = ssp_package.read(path)
        connected = {end for _, end in package.connections}
        descriptions = _descriptions(path, package)
        settable = {(c.name, v.name): v.type for c in package.components for v in descriptions[c.name].modelVariables
                    if v.causality == "parameter" or (v.causality == "input" and (c.name, v.name) not in connected)}
        outputs = tuple(f"{c.name}.{v.name}" for c in package.components for v in descriptions[c.name].modelVariables
                        if v.causality == "output" and v.type in ("Real", "Float64"))
        missing = sorted({name for metrics in derived for name in metrics.outputs} - set(outputs))
        if missing:
            raise ValueError(f"{', '.join(missing)}: no Real output of {package.name}")
        units = {f"{c.name}.{v.name}": unit_of(v)
                 for c in package.components for v in descriptions[c.name].modelVariables}
        return cls(package.name, {c.name: descriptions[c.name].modelName for c in package.components},
                   settable, package, outputs, tuple(derived), units)

    def changes(self, point: Point) -> dict[Target, tuple[str, Value]]:
        """``{(component, variable): (type, value)}`` of a point; ValueError for a name the system cannot set."""
        found = {}
        for name, value in point.items():
            for target in targets(name):
                if target[0] not in self.models:
                    raise ValueError(f"{name}: {self.name} has no component {target[0]!r} "
                                     f"(it has {', '.join(self.models)})")
                if target not in self.settable:
                    raise ValueError(f"{name}: {'.'.join(target)} is no parameter or unconnected input of "
                                     f"{target[0]} ({self.models[target[0]]})")
                found[target] = (self.settable[target], value)
        return found

    def system(self, point: Point) -> SspSystem:
        """The package's system with the point's values bound."""
        changes = self.changes(point)
        components = [replace(c, parameters={**c.parameters, **{v: value for (n, v), (_, value) in changes.items()
                                                                 if n == c.name}}) for c in self.package.components]
        return replace(self.package, components=components)

    def statistics(self) -> list[tuple[str, str]]:
        """(output, statistic) of every metric column."""
        known = SYSTEM_METRICS.get(self.name)
        if known is not None and all(output in self.outputs for output, _ in known):
            return list(known)
        return [(output, statistic) for output in self.outputs for statistic in GENERIC]

    def metric_columns(self) -> list[str]:
        return [f"{output}_{statistic}" for output, statistic in self.statistics()] + [
            column for metrics in self.derived for column in metrics.columns]

    def metric_units(self) -> list[str]:
        """The unit of each of :meth:`metric_columns`: its output's, a derived metric's its own."""
        return [self.units[output] for output, _ in self.statistics()] + [
            unit for metrics in self.derived for unit in metrics.units]

    def unit(self, name: str) -> str:
        """The unit of a point's name: its first target's (all take the same value)."""
        return self.units[".".join(targets(name)[0])]

    def recorded(self) -> list[str]:
        """The outputs a run records: those of the metrics."""
        derived = [name for metrics in self.derived for name in metrics.outputs]
        return list(dict.fromkeys([*(output for output, _ in self.statistics()), *derived]))

    def refusal(self, point: Point, step_size: float, master: str) -> str | None:
        """Why the point is not run: the first start value a component would refuse at initialisation
        (the model's own checks, as ``driveline-fmus system`` makes them), or its step above a drive's
        limit for a Jacobi coupling; None to run it."""
        system = self.system(point)
        for component in system.components:
            reasons = _refusals(self.models[component.name], tuple(sorted(component.parameters.items())))
            if reasons:
                return f"{component.name} ({self.models[component.name]}): {reasons[0]}"
        if master != "gauss-seidel":
            return step_limit_error(system, self.models, step_size)
        return None


@functools.lru_cache(maxsize=4096)
def _refusals(model: str, values: tuple[tuple[str, Value], ...]) -> list[str]:
    """:func:`refusals` of a component's start values, each distinct set checked once (a grid repeats
    them, and ``CriticalSpeeds`` analyses its structure there, 0.04 to 0.5 s)."""
    return refusals(model, dict(values))


def _descriptions(path: Path, package: SspSystem) -> dict[str, ModelDescription]:
    """Each component's model description, read from the package's FMUs."""
    with tempfile.TemporaryDirectory(prefix="driveline-sweep-") as scratch, zipfile.ZipFile(path) as archive:
        found = {}
        for component in package.components:
            archive.extract(component.source, scratch)
            found[component.name] = read_model_description(str(Path(scratch) / component.source))
        return found


def container_of(path: Path, interface: SystemInterface, step_size: float, master: str) -> bytes | None:
    """The package at ``path`` as one container FMU stepping by ``master``'s scheme at ``step_size``; None for
    a master no container runs or a package it cannot carry."""
    if master not in CONTAINED:
        return None
    with tempfile.TemporaryDirectory(prefix="driveline-sweep-") as scratch, zipfile.ZipFile(path) as archive:
        archive.extractall(scratch)
        fmus = {c.name: Path(scratch) / c.source for c in interface.package.components}
        try:
            built = container.build(interface.package, fmus, Path(scratch) / "container.fmu", step_size,
                                    sequential=master == "gauss-seidel")
        except container.ContainerRefused:
            return None
        return built.read_bytes()


@dataclass(frozen=True)
class UnpackedSystem:
    """A package on a worker: its file, each component's FMU extracted and its description parsed, and
    its container's file, extracted folder and description when there is one."""

    path: Path
    fmus: dict[str, Path]
    unpacked: dict[str, tuple[str, ModelDescription]]
    container: tuple[Path, str, ModelDescription] | None = None

    @classmethod
    def write(cls, data: bytes, folder: Path, interface: SystemInterface,
              container_data: bytes | None = None) -> UnpackedSystem:
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{interface.name}.ssp"
        path.write_bytes(data)
        with zipfile.ZipFile(path) as archive:
            archive.extractall(folder / "package")
        fmus, by_source = {}, {}
        for component in interface.package.components:
            fmus[component.name] = folder / "package" / component.source
            if component.source not in by_source:
                target = folder / "extracted" / Path(component.source).stem
                unzipdir = extract(str(fmus[component.name]), unzipdir=target)
                by_source[component.source] = (unzipdir, read_model_description(unzipdir))
        contained = None
        if container_data is not None:
            fmu = folder / "container.fmu"
            fmu.write_bytes(container_data)
            unzipdir = extract(str(fmu), unzipdir=folder / "extracted" / "container")
            contained = (fmu, unzipdir, read_model_description(unzipdir))
        return cls(path, fmus, {c.name: by_source[c.source] for c in interface.package.components}, contained)


STATISTICS: dict[str, Callable[[np.ndarray], Any]] = {
    "min": np.min,
    "max": np.max,
    "mean": np.mean,
    "p2p": np.ptp,
    "peak_abs": lambda x: np.max(np.abs(x)),
}


def run_system(interface: SystemInterface, unpacked: UnpackedSystem, point: Point, stop_time: float,
               step_size: float, master: str, scratch: Path) -> dict[str, float]:
    """One run of the system at ``point`` by ``master``: the metric columns. Raises what the run raises."""
    outputs = interface.recorded()
    system = interface.system(point)
    if master == "libcosim":
        package = ssp_package.with_parameters(unpacked.path, interface.changes(point), scratch / unpacked.path.name)
        rows = cosim_run(package, step_size, stop_time, outputs)
    elif master in CONTAINED and unpacked.container is not None:
        fmu, unzipdir, description = unpacked.container
        changes = {f"{component}.{variable}": value for (component, variable), (_, value) in interface.changes(point).items()}
        rows = container.run(fmu, changes, stop_time, step_size, outputs, unpacked=(unzipdir, description))
    else:
        order = [c.name for c in system.components] if master == "gauss-seidel" else None
        rows = run_jacobi(unpacked.fmus, {c.name: c.parameters for c in system.components}, system.connections,
                          stop_time, step_size, outputs, order=order, unpacked=unpacked.unpacked)
    if not np.all(np.isfinite(rows)):
        raise ValueError("the run gave values that are not finite")
    column = {name: rows[:, i + 1] for i, name in enumerate(outputs)}
    metrics = {f"{output}_{statistic}": float(STATISTICS[statistic](column[output]))
               for output, statistic in interface.statistics()}
    for derived in interface.derived:
        values = derived.compute(rows[:, 0], {name: column[name] for name in derived.outputs})
        metrics |= {name: float(value) for name, value in zip(derived.columns, values, strict=True)}
    return metrics


def stop_and_step(interface: SystemInterface, duration: float | None, step_size: float | None) -> tuple[float, float]:
    """(stop time, step) of every run: ``duration`` or the package's stop time, and ``step_size``,
    a whole number of steps; ValueError otherwise."""
    stop_time = duration if duration is not None else interface.package.stop_time
    if stop_time is None:
        raise ValueError(f"{interface.name} states no stop time: give --duration")
    if step_size is None:
        raise ValueError("a system sweep needs --step (a package states no communication step)")
    if not (math.isfinite(stop_time) and math.isfinite(step_size) and 0.0 < step_size <= stop_time):
        raise ValueError(f"step {step_size!r} and duration {stop_time!r}: need 0 < step <= duration, finite")
    if abs(stop_time / step_size - round(stop_time / step_size)) > 1e-9 * stop_time / step_size:
        raise ValueError(f"the duration {stop_time!r} s is no whole number of steps of {step_size!r} s")
    return stop_time, step_size

