"""Interoperability matrix: every built FMU (FMI 2.0 and 3.0) in every importer.

Usage: ``python -m fmu_harness.interop [--models models] [--update docs/interoperability.md]``
after ``python build_fmu.py``. Prints the matrix as markdown; with ``--update`` it also rewrites
that page's ``interop`` section (:mod:`fmu_harness.doc_sections`).

Importers: ``fmpy validate``, ``fmutool -input X.fmu -check`` (FMU Manipulation Toolbox),
and two co-simulation engines, libcosimpy and ecospy, that run the model's standard scenario
(:mod:`fmu_harness.scenario`): a run passes if every compared output stays within
:data:`TOLERANCE` times the output's largest magnitude of the fmpy run at t_1 ... t_N. Each
engine run is a subprocess of its own, so an importer that crashes fails one cell only.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import shutil
import subprocess
import sys
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Literal

import numpy as np
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from driveline.catalog import MODELS

from . import importers
from .doc_sections import replace_section
from .runner import FmuInstance
from .scenario import scenario, standard_run

TOLERANCE = 1e-9
RESULT = "interop result: "
Status = Literal["pass", "fail", "unsupported", "unavailable"]


@dataclass(frozen=True)
class Outcome:
    status: Status
    reason: str = ""
    deviation: float | None = None


@dataclass(frozen=True)
class Importer:
    """One column of the matrix: how to check an FMU, which FMI versions it takes, and why not others."""

    name: str
    package: str
    versions: tuple[str, ...]
    check: Callable[[Path], Outcome]
    unsupported: str = ""


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


def _engine(name: str) -> Callable[[Path], Outcome]:
    """Run the scenario in engine ``name`` in a subprocess (see :func:`simulate_in`)."""

    def check(fmu: Path) -> Outcome:
        command = [sys.executable, "-m", "fmu_harness.interop", "--worker", name, str(fmu)]
        done = subprocess.run(command, capture_output=True, text=True, timeout=300, cwd=Path(__file__).parents[1])
        if done.returncode:
            last = (done.stderr.strip().splitlines() or [""])[-1]
            return Outcome("fail", f"{name} exited with {done.returncode}: {last}")
        # the engines' own messages may reach the pipe after the result: find its line
        result = next((line for line in done.stdout.splitlines() if line.startswith(RESULT)), None)
        if result is None:
            return Outcome("fail", f"{name} gave no result: {done.stdout.strip()[-200:]}")
        return Outcome(**json.loads(result.removeprefix(RESULT)))

    return check


IMPORTERS = (
    Importer("fmpy validate", "fmpy", ("2.0", "3.0"), _fmpy_validate),
    Importer("fmutool -check", "fmu_manipulation_toolbox", ("2.0", "3.0"), _fmutool_check),
    Importer("libcosimpy", "libcosimpy", ("2.0",), _engine("libcosimpy"),
             "libcosim loads FMI 1.0 and 2.0 only: it logs 'Unsupported FMI version' and libcosimpy "
             "0.0.6 then crashes the host (segmentation fault)"),
    Importer("ecospy", "ecospy", ("2.0", "3.0"), _engine("ecospy")),
)
SESSIONS = {"libcosimpy": importers.cosim_session, "ecospy": importers.ecos_session}


def simulate_in(engine: str, fmu: Path) -> Outcome:
    """The model's standard scenario in ``engine`` against fmpy (runs inside the worker)."""
    name = read_model_description(str(fmu)).modelName
    case = scenario(MODELS[name].spec)
    with FmuInstance(fmu) as instance:
        reference = standard_run(instance, case.outputs)

    def inputs(time: float) -> dict[str, float]:
        return {f"m.{k}": v for k, v in case.input_values(time).items()}

    session = SESSIONS[engine](case.step_size, fmus={"m": fmu}, start_values=inputs(0.0))
    try:
        result = importers.record(session, case.steps, case.step_size, [f"m.{n}" for n in case.outputs], inputs)
    finally:
        session.close()
    deviation = max(
        float(np.abs(result[:, i + 1] - reference[n][1:]).max() / (np.abs(reference[n]).max() or 1.0))
        for i, n in enumerate(case.outputs)
    )
    if deviation <= TOLERANCE:
        return Outcome("pass", deviation=deviation)
    return Outcome("fail", f"largest relative deviation from fmpy {deviation:.3g} > {TOLERANCE:g}", deviation)


def outcome(importer: Importer, fmu: Path) -> Outcome:
    version = read_model_description(str(fmu)).fmiVersion
    if version not in importer.versions:
        return Outcome("unsupported", importer.unsupported)
    if importlib.util.find_spec(importer.package) is None:
        return Outcome("unavailable", f"{importer.package} is not installed (pip install '.[interop]')")
    try:
        return importer.check(fmu)
    except (OSError, subprocess.SubprocessError) as error:
        return Outcome("fail", f"{type(error).__name__}: {error}")


def fmus(models: Path) -> list[Path]:
    """The catalog's FMUs in ``models`` (FMI 2.0) and ``models/fmi3`` (FMI 3.0)."""
    return [path for name in MODELS for path in (models / f"{name}.fmu", models / "fmi3" / f"{name}.fmu") if path.exists()]


def matrix(models: Path) -> dict[tuple[str, str], dict[str, Outcome]]:
    """``{(model, FMI version): {importer: outcome}}`` for every FMU in ``models``."""
    table = {}
    for fmu in fmus(models):
        description = read_model_description(str(fmu))
        table[description.modelName, description.fmiVersion] = {i.name: outcome(i, fmu) for i in IMPORTERS}
    return table


def markdown(table: dict[tuple[str, str], dict[str, Outcome]]) -> str:
    """The matrix with one footnote per distinct reason."""
    notes: list[str] = []

    def cell(result: Outcome) -> str:
        if not result.reason:
            return result.status
        if result.reason not in notes:
            notes.append(result.reason)
        return f"{result.status} [{notes.index(result.reason) + 1}]"

    lines = [
        "| FMU | FMI | " + " | ".join(i.name for i in IMPORTERS) + " |",
        "|---|---|" + "---|" * len(IMPORTERS),
    ]
    for (name, version), row in table.items():
        lines.append(f"| `{name}` | {version} | " + " | ".join(cell(row[i.name]) for i in IMPORTERS) + " |")
    lines += [""] + [f"[{n}] {reason}" for n, reason in enumerate(notes, start=1)]
    return "\n".join(lines).rstrip()


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs")
    parser.add_argument("--update", type=Path, metavar="PAGE", help="markdown page whose matrix section to regenerate")
    parser.add_argument("--worker", nargs=2, metavar=("ENGINE", "FMU"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        print(RESULT + json.dumps(asdict(simulate_in(args.worker[0], Path(args.worker[1])))), flush=True)
        return
    table = matrix(args.models)
    text = markdown(table)
    print(text)
    for (name, version), row in table.items():
        for importer, result in row.items():
            if result.deviation is not None:
                print(f"{name} FMI {version} {importer}: largest relative deviation {result.deviation:.3g}", file=sys.stderr)
    if args.update:
        replace_section(args.update, "interop", text)


if __name__ == "__main__":
    main()
