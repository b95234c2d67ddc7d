"""Interoperability matrix: every built FMU (Python and native, FMI 2.0 and 3.0) in every importer.

Usage: ``python -m fmu_harness.checks.interop [--models models] [--update docs/interoperability.md]``
after ``python build_fmu.py``. Prints the matrix as markdown; with ``--update`` it also rewrites
that page's ``interop`` section (:mod:`fmu_harness.doc_pages.sections`). The native FMUs are those
under ``models/native/`` (:mod:`fmu_harness.packaging.native`).

The packages built as one FMU (``native/VehicleLaunch.fmu``, ``native/Driveline.fmu``: FMU Manipulation Toolbox's
container, :mod:`fmu_harness.runs.container`) are rows too, family ``container``: an engine runs
:data:`CONTAINER_RUN` of the package as bound, compared with fmpy's run of the same container.

Importers: ``fmpy validate``, ``fmutool -input X.fmu -check`` (FMU Manipulation Toolbox),
fmpy's Model Exchange (:func:`_fmpy_model_exchange`), and two co-simulation engines, libcosimpy
and ecospy, that run the model's standard scenario
(:mod:`fmu_harness.runs.scenario`): a run passes if every compared output stays within
:data:`TOLERANCE` times the output's largest magnitude of the fmpy run of the model's Python FMU
(same FMI version) at t_1 ... t_N, for a native FMU too: the equivalence a host relies on when
it swaps one for the other. Each engine run is a subprocess of its own, so an importer that
crashes fails one cell only.
"""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
import sys
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Literal

import numpy as np
from fmpy import read_model_description, simulate_fmu
from fmpy.model_description import ModelDescription
from fmpy.validation import validate_fmu

from driveline.catalog import MODELS
from driveline.mounts.spec import SHARED_LAYOUT

from ..console import Progress, summary
from ..doc_pages.sections import replace_section, section
from ..packaging import fmu_path, native
from ..runs import container
from ..runs.runner import FmuInstance
from ..runs.scenario import scenario, standard_run
from ..runs.start_values import StartValuesRefused
from . import importers
from .worker import answer, answer_in, check_parser

TOLERANCE = 1e-9
#: Model Exchange against co-simulation: CVODE's relative tolerance, and the largest relative deviation
#: passed (its global error: the source's phase, the one state that is no straight line, stays below 1e-7)
MODEL_EXCHANGE_TOLERANCE, MODEL_EXCHANGE_PASS = 1e-8, 1e-6
PYTHON_CO_SIMULATION_ONLY = ("co-simulation only: pythonfmu 0.7 (FMI 2.0) has no Model Exchange; the FMI 3.0 "
                             "adapter does not use pythonfmu3's")
RESULT = "interop result: "
Status = Literal["pass", "fail", "unsupported", "unavailable"]
Family = Literal["Python", "native", "container"]
CONTAINERS = ("Driveline", "VehicleLaunch")
"""The packages the build also writes as one FMU (:func:`fmu_harness.runs.system.write_container`)."""
CONTAINER_RUN = 200
"""Steps of a container's engine run at its own step (20 ms of the launch, 0.2 s of the driveline)."""
CONTAINER_CO_SIMULATION_ONLY = "co-simulation only: the container steps its components' co-simulation"


@dataclass(frozen=True)
class Outcome:
    status: Status
    reason: str = ""
    deviation: float | None = None


@dataclass(frozen=True)
class Importer:
    """One column of the matrix: how to check an FMU (given the Python FMU its runs are compared
    with), which FMI versions it takes, and why not others."""

    name: str
    package: str
    versions: tuple[str, ...]
    check: Callable[[Path, Path], Outcome]
    unsupported: str = ""
    #: Why an FMU without Model Exchange is unsupported, for an importer that runs that interface ("": any FMU)
    model_exchange_only: str = ""


@dataclass(frozen=True)
class Fmu:
    """One row of the matrix: a built FMU, its family and the Python FMU of the same model and
    FMI version whose fmpy run the engines' runs must match."""

    family: Family
    path: Path
    reference: Path


def _fmpy_validate(fmu: Path) -> Outcome:
    problems = validate_fmu(str(fmu))
    return Outcome("fail", "; ".join(problems)) if problems else Outcome("pass")


def _fmutool_check(fmu: Path) -> Outcome:
    executable = Path(sys.executable).with_name("fmutool")
    command = [str(executable if executable.exists() else shutil.which("fmutool") or "fmutool"), "-input", str(fmu), "-check"]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    if done.returncode:
        errors = [line for line in done.stdout.splitlines() + done.stderr.splitlines() if "ERROR" in line]
        return Outcome("fail", "; ".join(errors) or f"exit code {done.returncode}")
    return Outcome("pass")


#: Start values of the Model Exchange check where co-simulation steps exactly only with them: PowertrainMounts'
#: linear layout (matrix exponential); on its rubber default co-simulation's implicit midpoint rule errs by
#: O(h^2) itself, and at rest both interfaces give rounding alone (its convergence: the project's tests)
MODEL_EXCHANGE_START = {"PowertrainMounts": {"layout": SHARED_LAYOUT}}


def _fmpy_model_exchange(fmu: Path) -> Outcome:
    """The default experiment through fmpy in Model Exchange (CVODE) against its co-simulation run of
    the same FMU, at the co-simulation's output points."""
    description = read_model_description(str(fmu))
    step = MODELS[description.modelName].spec.default_experiment.step_size
    runs = [simulate_fmu(str(fmu), fmi_type=interface, step_size=step, output_interval=10 * step,
                         relative_tolerance=MODEL_EXCHANGE_TOLERANCE,
                         start_values=MODEL_EXCHANGE_START.get(description.modelName, {}))
            for interface in ("CoSimulation", "ModelExchange")]
    outputs = [v.name for v in MODELS[description.modelName].spec.of("output") if v.type == "Real"]
    deviation = max(float(np.abs(runs[1][n] - runs[0][n]).max() / (np.abs(runs[0][n]).max() or 1.0))
                    for n in outputs)
    if deviation <= MODEL_EXCHANGE_PASS:
        return Outcome("pass", deviation=deviation)
    return Outcome("fail", f"largest relative deviation from co-simulation {deviation:.3g} > {MODEL_EXCHANGE_PASS:g}",
                   deviation)


def _engine(name: str) -> Callable[[Path, Path], Outcome]:
    """Run the scenario in engine ``name`` in a subprocess (see :func:`simulate_in`)."""

    def check(fmu: Path, reference: Path) -> Outcome:
        command = [sys.executable, "-m", "fmu_harness.checks.interop", "--worker", name, str(fmu), str(reference)]
        done = subprocess.run(command, capture_output=True, text=True, timeout=300, cwd=Path(__file__).parents[1])
        if done.returncode:
            last = (done.stderr.strip().splitlines() or [""])[-1]
            return Outcome("fail", f"{name} exited with {done.returncode}: {last}")
        result = answer_in(done.stdout, RESULT)
        if result is None:
            return Outcome("fail", f"{name} gave no result: {done.stdout.strip()[-200:]}")
        return Outcome(**result)

    return check


IMPORTERS = (
    Importer("fmpy validate", "fmpy", ("2.0", "3.0"), lambda fmu, reference: _fmpy_validate(fmu)),
    Importer("fmutool -check", "fmu_manipulation_toolbox", ("2.0", "3.0"), lambda fmu, reference: _fmutool_check(fmu)),
    Importer("fmpy Model Exchange", "fmpy", ("2.0", "3.0"), lambda fmu, reference: _fmpy_model_exchange(fmu),
             model_exchange_only=PYTHON_CO_SIMULATION_ONLY),
    Importer("libcosimpy", "libcosimpy", ("2.0",), _engine("libcosimpy"),
             "libcosim loads FMI 1.0 and 2.0 only: it logs 'Unsupported FMI version' and libcosimpy "
             "0.0.6 then crashes the host (segmentation fault)"),
    Importer("ecospy", "ecospy", ("2.0", "3.0"), _engine("ecospy")),
)
SESSIONS = {"libcosimpy": importers.cosim_session, "ecospy": importers.ecos_session}


def simulate_in(engine: str, fmu: Path, reference: Path | None = None) -> Outcome:
    """The model's standard scenario in ``engine`` against fmpy's run of ``reference`` (default:
    ``fmu`` itself; runs inside the worker)."""
    description = read_model_description(str(fmu))
    if description.modelName not in MODELS:
        return _container_in(engine, fmu, description)
    name = description.modelName
    case = scenario(MODELS[name].spec)
    with FmuInstance(reference or fmu) as instance:
        expected = standard_run(instance, case.outputs)

    def inputs(time: float) -> dict[str, float]:
        return {f"m.{k}": v for k, v in case.input_values(time).items()}

    try:
        session = SESSIONS[engine](case.step_size, fmus={"m": fmu}, start_values=inputs(0.0))
    except StartValuesRefused as refused:
        return Outcome("fail", f"refused before {engine} started: {refused}")
    try:
        result = importers.record(session, case.steps, case.step_size, [f"m.{n}" for n in case.outputs], inputs)
    finally:
        session.close()
    # a state's nominal is the magnitude it is judged at (a solver's absolute tolerance is its relative one times
    # the nominal): PowertrainMounts' rest on progressive mounts, a Newton root, leaves its states at rounding
    # (some 1e-18 m against nominals of 1e-3 m), which the engines' runs need not repeat digit for digit
    nominals = {v.name: float(v.nominal) for v in description.modelVariables if v.nominal is not None}
    deviation = max(
        float(np.abs(result[:, i + 1] - expected[n][1:]).max()
              / (max(np.abs(expected[n]).max(), nominals.get(n, 0.0)) or 1.0))
        for i, n in enumerate(case.outputs)
    )
    if deviation <= TOLERANCE:
        return Outcome("pass", deviation=deviation)
    return Outcome("fail", f"largest relative deviation from the fmpy run {deviation:.3g} > {TOLERANCE:g}", deviation)


def _container_in(engine: str, fmu: Path, description: ModelDescription) -> Outcome:
    """:data:`CONTAINER_RUN` steps of the container ``fmu`` as bound in ``engine`` against fmpy's run of it, every
    Real output compared (runs inside the worker)."""
    step = float(description.defaultExperiment.stepSize)
    outputs = [v.name for v in description.modelVariables if v.causality == "output" and v.type in ("Real", "Float64")]
    expected = container.run(fmu, {}, CONTAINER_RUN * step, step, outputs)[:, 1:]
    session = SESSIONS[engine](step, fmus={"m": fmu})
    try:
        found = importers.record(session, CONTAINER_RUN, step, [f"m.{n}" for n in outputs])[:, 1:]
    finally:
        session.close()
    scale = np.abs(expected).max(axis=0)
    deviation = float((np.abs(found - expected).max(axis=0) / np.where(scale > 0.0, scale, 1.0)).max())
    if deviation <= TOLERANCE:
        return Outcome("pass", deviation=deviation)
    return Outcome("fail", f"largest relative deviation from the fmpy run {deviation:.3g} > {TOLERANCE:g}", deviation)


def outcome(importer: Importer, fmu: Path, reference: Path | None = None) -> Outcome:
    """``fmu`` in ``importer``, engine runs compared with fmpy's run of ``reference`` (default: ``fmu``)."""
    description = read_model_description(str(fmu))
    if description.fmiVersion not in importer.versions:
        return Outcome("unsupported", importer.unsupported)
    if importer.model_exchange_only and description.modelExchange is None and description.modelName not in MODELS:
        return Outcome("unsupported", CONTAINER_CO_SIMULATION_ONLY)
    if importer.model_exchange_only and description.modelExchange is None:
        return Outcome("unsupported", MODELS[description.modelName].co_simulation_only
                       if description.generationTool == native.GENERATION_TOOL else importer.model_exchange_only)
    if importlib.util.find_spec(importer.package) is None:
        return Outcome("unavailable", f"{importer.package} is not installed (pip install '.[interop]')")
    try:
        return importer.check(fmu, reference or fmu)
    except (OSError, subprocess.SubprocessError) as error:
        return Outcome("fail", f"{type(error).__name__}: {error}")


def fmus(models: Path, natives: Path | None = None) -> list[Fmu]:
    """The catalog's built FMUs, per model the Python ones in ``models`` (FMI 2.0) and
    ``models/fmi3`` (FMI 3.0), then the native ones in ``native/`` and ``native/fmi3/`` below
    ``natives`` (default: ``models``); a native FMU counts when its Python reference is built; then the
    :data:`CONTAINERS` built there, each its own reference."""
    found = []
    for name in MODELS:
        references = {fmi: fmu_path(models, name, fmi) for fmi in ("2", "3")}
        found += [Fmu("Python", path, path) for path in references.values()]
        found += [Fmu("native", native.fmu_path(natives or models, name, fmi), path) for fmi, path in references.items()]
    for name in CONTAINERS:
        found += [Fmu("container", path, path) for path in (native.fmu_path(natives or models, name, fmi)
                                                            for fmi in ("2", "3"))]
    return [fmu for fmu in found if fmu.path.exists() and fmu.reference.exists()]


Table = dict[tuple[str, Family, str], dict[str, Outcome]]


def matrix(models: Path, natives: Path | None = None, show_progress: bool = False) -> Table:
    """``{(model, family, FMI version): {importer: outcome}}`` for every FMU of :func:`fmus`;
    ``show_progress``: each FMU and importer on standard error."""
    table: Table = {}
    found = fmus(models, natives)
    with Progress("importer matrix", len(found) * len(IMPORTERS), enabled=show_progress) as shown:
        for fmu in found:
            description = read_model_description(str(fmu.path))
            row = table[description.modelName, fmu.family, description.fmiVersion] = {}
            for importer in IMPORTERS:
                row[importer.name] = outcome(importer, fmu.path, fmu.reference)
                shown.advance(f"{description.modelName} {fmu.family} FMI {description.fmiVersion} in {importer.name}")
    return table


def markdown(table: Table) -> str:
    """The matrix with one footnote per distinct reason."""
    notes: list[str] = []

    def cell(result: Outcome) -> str:
        if not result.reason:
            return result.status
        if result.reason not in notes:
            notes.append(result.reason)
        return f"{result.status} [{notes.index(result.reason) + 1}]"

    lines = [
        "| FMU | family | FMI | " + " | ".join(i.name for i in IMPORTERS) + " |",
        "|---|---|---|" + "---|" * len(IMPORTERS),
    ]
    for (name, family, version), row in table.items():
        lines.append(f"| `{name}` | {family} | {version} | " + " | ".join(cell(row[i.name]) for i in IMPORTERS) + " |")
    lines += [""] + [f"[{n}] {reason}" for n, reason in enumerate(notes, start=1)]
    return "\n".join(lines).rstrip()


def main(argv: list[str] | None = None) -> None:
    parser = check_parser(summary(__doc__), "matrix section", ("ENGINE", "FMU", "REFERENCE"))
    args = parser.parse_args(argv)
    if args.worker:
        engine, fmu, reference = args.worker
        answer(RESULT, asdict(simulate_in(engine, Path(fmu), Path(reference))))
    if not fmus(args.models):
        parser.error(f"no built FMU in {args.models} (`driveline-fmus build` builds them; --models names another folder)")
    if args.update:
        try:
            section(args.update, "interop")
        except (OSError, ValueError) as error:
            parser.error(f"--update {args.update}: {error}")
    table = matrix(args.models, show_progress=True)
    text = markdown(table)
    print(text)
    for (name, family, version), row in table.items():
        for importer, result in row.items():
            if result.deviation is not None:
                print(f"{name} {family} FMI {version} {importer}: largest relative deviation {result.deviation:.3g}", file=sys.stderr)
    if args.update:
        replace_section(args.update, "interop", text)


if __name__ == "__main__":
    main()
