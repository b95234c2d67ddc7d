"""Run an SSP package of FMUs and write every output of every component to a CSV file.

``driveline-fmus system PACKAGE.ssp`` writes the time first, each column headed ``Component.variable [unit]``, a row
every ``--output-interval`` (a whole number of steps; default the first at or above 1 ms: the 4 s launch at 0.1 ms
gives 4,000 rows, 6 MB, not 40,000 and 65 MB), to CSV or, for ``--out NAME.parquet``, Parquet (pyarrow, the ``sweep``
extra).

The engine is the project's fixed-step Jacobi master (``master``, :func:`fmu_harness.runs.system.run_jacobi`,
FMI 2.0 and 3.0 FMUs through fmpy), the same master stepping the components one after the other in the
package's order (``gauss-seidel``), libcosim (``libcosim``, FMI 2.0) or Ecos (``ecos``), the engines
of the importer matrix, or the FMUs' Model Exchange interfaces as one ODE (``model-exchange``,
:func:`fmu_harness.runs.model_exchange_system.run_model_exchange`; ``--step`` is then the output interval,
``--rtol`` the integrator's tolerance). ``--set Component.name=value`` binds a parameter (or an unconnected input's
start value) in a copy of the package, so every engine runs the same bindings.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import zipfile
from collections.abc import Callable
from pathlib import Path

import numpy as np
from fmpy import read_model_description
from fmpy.model_description import ModelDescription

from .console import CommandParser, optional, refused, require, summary
from .runs import ssp_package
from .runs.runner import StepRefused
from .runs.ssp_package import PackageError, SspSystem
from .runs.start_values import StartValuesRefused, check_start_values, engine_instances
from .runs.system import run_jacobi, step_limit_error
from .runs.result_table import headed, unit_of, write_csv

ENGINES = ("master", "gauss-seidel", "libcosim", "ecos", "model-exchange")
ENGINE_EXTRAS = {"libcosim": "libcosimpy", "ecos": "ecospy"}  # the module of the interop extra each engine needs
JACOBI_ENGINES = ("master", "libcosim", "ecos")  # each couples by Jacobi: the inputs of a step are all one step late
RTOL = 1e-8  # the model-exchange engine's relative tolerance unless --rtol
PROGRESS_SHARE = 0.1  # a progress line every tenth of the run when stderr is no terminal
OUTPUT_INTERVAL = 1e-3  # the rows' default interval [s], rounded up to a whole number of steps


class UsageError(ValueError):
    """A mistake in the command line, found before any work starts."""


def _description(path: Path) -> ModelDescription:
    try:
        return read_model_description(str(path))
    except Exception as error:  # noqa: BLE001 - fmpy raises many kinds for an unreadable FMU
        raise PackageError(f"{path.name}: no readable FMU ({type(error).__name__}: {error})") from None


def _parse_value(kind: str, text: str) -> float | int | bool | str:
    try:
        if kind == "Real":
            value = float(text)
            if not math.isfinite(value):
                raise ValueError
            return value
        if kind == "Integer":
            return int(text)
        if kind == "Boolean":
            return {"true": True, "1": True, "false": False, "0": False}[text.lower()]
        return text
    except (KeyError, ValueError):
        raise UsageError(f"--set: {text!r} is no {kind} value") from None


def parameter_changes(settings: list[str], system: SspSystem, descriptions: dict[str, ModelDescription]
                      ) -> dict[tuple[str, str], tuple[str, float | int | bool | str]]:
    """``--set Component.name=value`` items, checked against the components' FMUs: the variable must be
    a parameter or an input no connection feeds."""
    connected = {end for _, end in system.connections}
    changes = {}
    for setting in settings:
        target, equals, text = setting.partition("=")
        component, dot, variable = target.partition(".")
        if not (equals and dot and component and variable):
            raise UsageError(f"--set {setting!r}: write Component.name=value")
        system.component(component)
        found = next((v for v in descriptions[component].modelVariables if v.name == variable), None)
        if found is None:
            raise UsageError(f"--set {setting!r}: component {component} has no variable {variable!r}")
        if found.causality not in ("parameter", "input") or (component, variable) in connected:
            raise UsageError(f"--set {setting!r}: {component}.{variable} is no parameter or unconnected input "
                             f"(it is a connected {found.causality})" if (component, variable) in connected else
                             f"--set {setting!r}: {component}.{variable} is "
                             f"{'a local' if found.causality == 'local' else 'an ' + found.causality}, not a parameter")
        changes[component, variable] = (found.type, _parse_value(found.type, text))
    return changes


def output_columns(system: SspSystem, descriptions: dict[str, ModelDescription]) -> tuple[list[str], list[str]]:
    """Every Real output of every component: (``instance.variable`` names, CSV headers)."""
    names, headers = [], []
    for component in system.components:
        for variable in descriptions[component.name].modelVariables:
            if variable.causality == "output" and variable.type == "Real":
                names.append(f"{component.name}.{variable.name}")
                headers.append(headed(f"{component.name}.{variable.name}", unit_of(variable)))
    return names, headers


def progress_printer(stop_time: float, stream=sys.stderr) -> Callable[[int, int], None]:
    """``on_step(k, n)``: the time reached, on one line rewritten on a terminal, else every tenth."""
    interactive = stream.isatty()
    last_shown = [-1]

    def show(k: int, n: int) -> None:
        share = k / n
        tenth = int(share / PROGRESS_SHARE)
        if interactive and (k == n or k % max(1, n // 200) == 0):
            stream.write(f"\rsystem: t = {share * stop_time:.4g} of {stop_time:g} s ({100 * share:3.0f} %)")
            stream.write("\n" if k == n else "")
        elif not interactive and tenth != last_shown[0]:
            last_shown[0] = tenth
            stream.write(f"system: t = {share * stop_time:.4g} of {stop_time:g} s ({100 * share:.0f} %)\n")
        stream.flush()

    return show


def run_engine(engine: str, package: Path, system: SspSystem, fmus: dict[str, Path], outputs: list[str],
               stop_time: float, step_size: float, on_step: Callable[[int, int], None], rtol: float = RTOL) -> np.ndarray:
    """Rows of time and ``outputs`` for t_0 = 0 ... t_N from ``engine`` (``rtol``: Model Exchange's tolerance);
    libcosim's from t_1, as it initialises the FMUs in its first step."""
    steps = int(round(stop_time / step_size))
    if engine == "model-exchange":
        from .runs.model_exchange_system import NotRunnable, run_model_exchange

        with tempfile.TemporaryDirectory(prefix="driveline-model-exchange-") as scratch:
            try:
                return run_model_exchange(fmus, {c.name: c.parameters for c in system.components}, system.connections,
                                          stop_time, step_size, outputs, Path(scratch), rtol, on_step,
                                          initial=True)
            except NotRunnable as not_runnable:
                raise UsageError(str(not_runnable)) from None
    if engine in ("master", "gauss-seidel"):
        order = [c.name for c in system.components] if engine == "gauss-seidel" else None
        return run_jacobi(fmus, {c.name: c.parameters for c in system.components}, system.connections,
                          stop_time, step_size, outputs, on_step, order=order, initial=True)
    from .checks import importers  # the engines of the importer matrix, imported for them alone

    if engine == "libcosim":
        session = importers.cosim_session(step_size, ssp=package)
    else:
        session = importers.ecos_session(step_size, ssp=package, parameter_set=system.parameter_set)
    try:
        rows = [] if engine == "libcosim" else [[0.0, *session.get(outputs)]]
        for k in range(steps):
            if session.step() is False:
                raise StepRefused(f"{engine} step", "refused", k * step_size, [])
            rows.append([(k + 1) * step_size, *session.get(outputs)])
            on_step(k + 1, steps)
        return np.array(rows)
    finally:
        session.close()


def _arguments(argv: list[str] | None) -> argparse.Namespace:
    parser = CommandParser(description=summary(__doc__))
    parser.add_argument("package", type=Path, help="the SSP package (.ssp)")
    parser.add_argument("--stop-time", type=float, help="end of the run [s] (default: the package's DefaultExperiment)")
    parser.add_argument("--step", type=float, default=1e-3,
                        help="communication step [s], with model-exchange the output interval (default 1e-3)")
    parser.add_argument("--rtol", type=float, default=RTOL,
                        help=f"model-exchange: the integrator's relative tolerance (default {RTOL:g})")
    parser.add_argument("--out", type=Path,
                        help="CSV file, or .parquet for Parquet, to write (default: the package's name with .csv)")
    parser.add_argument("--output-interval", type=float,
                        help=f"time between rows [s], a whole number of steps (default: the first at or above "
                             f"{OUTPUT_INTERVAL:g} s)")
    parser.add_argument("--set", action="append", default=[], metavar="Component.name=value",
                        help="bind a parameter or an unconnected input's start value; repeatable")
    parser.add_argument("--engine", choices=ENGINES, default="master",
                        help="master: the project's Jacobi master (fmpy); gauss-seidel: the same master stepping the "
                             "components in the package's order; libcosim; ecos; model-exchange: the FMUs' Model "
                             "Exchange interfaces as one ODE (default master)")
    return parser.parse_args(argv)


def run(args: argparse.Namespace, scratch: Path) -> Path:
    """Check everything, then run and write the CSV file; the file's path."""
    out = args.out or Path(args.package.name).with_suffix(".csv")
    if out.is_dir() or not out.parent.is_dir():
        raise UsageError(f"--out {out}: a folder, not a file to write" if out.is_dir() else
                         f"--out {out}: no folder {out.parent}")
    if args.engine in ENGINE_EXTRAS:
        require(ENGINE_EXTRAS[args.engine], "interop", f"{sys.argv[0]} --engine {args.engine}")
    system = ssp_package.read(args.package)
    stop_time = args.stop_time if args.stop_time is not None else system.stop_time
    if stop_time is None:
        raise UsageError("the package has no DefaultExperiment stop time: give --stop-time")
    if not (math.isfinite(args.step) and args.step > 0.0 and math.isfinite(stop_time) and stop_time >= args.step):
        raise UsageError(f"--step {args.step!r} and --stop-time {stop_time!r}: need 0 < step <= stop time, finite")
    if not (math.isfinite(args.rtol) and 1e-13 <= args.rtol <= 1e-2):
        raise UsageError(f"--rtol {args.rtol!r}: need 1e-13 <= rtol <= 1e-2")
    if args.rtol != RTOL and args.engine != "model-exchange":
        raise UsageError(f"--rtol is the model-exchange engine's; --engine {args.engine} steps at --step")
    if abs(stop_time / args.step - round(stop_time / args.step)) > 1e-9 * stop_time / args.step:
        raise UsageError(f"--stop-time {stop_time!r} is no whole number of steps of {args.step!r} s")
    with zipfile.ZipFile(args.package) as archive:
        archive.extractall(scratch / "package")
    fmus = {c.name: scratch / "package" / c.source for c in system.components}
    descriptions = {name: _description(path) for name, path in fmus.items()}
    if args.engine == "libcosim" and any(d.fmiVersion != "2.0" for d in descriptions.values()):
        raise UsageError("libcosim runs FMI 2.0 FMUs only; this package holds others")
    if args.engine == "model-exchange":
        lacking = [f"{name} ({fmus[name].name})" for name, d in descriptions.items() if d.modelExchange is None]
        if lacking:
            raise UsageError(f"model-exchange needs every FMU's Model Exchange interface; {', '.join(lacking)} "
                             f"{'has' if len(lacking) == 1 else 'have'} none (the Python FMUs are co-simulation "
                             "only: take the native package)")
    changes = parameter_changes(args.set, system, descriptions)
    package = args.package
    if changes:
        package = ssp_package.with_parameters(args.package, changes, scratch / args.package.name)
        system = ssp_package.read(package)
    check_start_values(engine_instances(ssp=package))
    models = {name: d.modelName for name, d in descriptions.items()}
    reason = step_limit_error(system, models, args.step) if args.engine in JACOBI_ENGINES else None
    if reason is not None:
        raise UsageError(reason)
    outputs, headers = output_columns(system, descriptions)
    # model-exchange: --step is the rows' interval already
    every = 1 if args.engine == "model-exchange" and args.output_interval is None else steps_per_row(
        args.output_interval, args.step)
    if out.suffix.lower() == ".parquet":
        optional("pyarrow", "sweep", "driveline-fmus system --out NAME.parquet")
    rows = run_engine(args.engine, package, system, fmus, outputs, stop_time, args.step, progress_printer(stop_time),
                      args.rtol)
    start = 0 if rows[0, 0] == 0.0 else every - 1  # from the row at t = 0 (libcosim's first: t_1)
    kept = rows[start::every]
    if (len(rows) - 1 - start) % every:
        kept = np.vstack([kept, rows[-1:]])
    return write_rows(out, ["time [s]", *headers], kept)


def steps_per_row(interval: float | None, step: float) -> int:
    """How many steps ``--output-interval`` spans (the default: the fewest reaching :data:`OUTPUT_INTERVAL`)."""
    if interval is None:
        return max(1, math.ceil(OUTPUT_INTERVAL / step * (1.0 - 1e-9)))
    count = interval / step if math.isfinite(interval) and interval > 0.0 else 0.0
    if count < 1.0 - 1e-9 or abs(count - round(count)) > 1e-9 * count:
        raise UsageError(f"--output-interval {interval!r}: need a whole number of steps of {step!r} s")
    return int(round(count))


def write_rows(out: Path, header: list[str], rows: np.ndarray) -> Path:
    """``rows`` under ``header`` to CSV, or to Parquet for a ``.parquet`` file (one column per header)."""
    if out.suffix.lower() != ".parquet":
        return write_csv(out, header, rows.tolist())
    import pyarrow
    import pyarrow.parquet

    pyarrow.parquet.write_table(pyarrow.table({name: rows[:, i] for i, name in enumerate(header)}), out)
    return out


def main(argv: list[str] | None = None) -> None:
    args = _arguments(argv)
    try:
        with tempfile.TemporaryDirectory(prefix="driveline-system-") as scratch:
            out = run(args, Path(scratch))
    except StartValuesRefused as refusal:
        raise refused(sys.argv[0], str(refusal)) from None
    except (UsageError, PackageError) as error:
        print(f"{sys.argv[0]}: error: {error}", file=sys.stderr)
        sys.exit(2)
    except StepRefused as error:
        sys.exit(f"{sys.argv[0]}: the run stopped: {error}")
    print(out)


if __name__ == "__main__":
    main()
