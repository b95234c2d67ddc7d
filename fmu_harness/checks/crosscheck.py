"""Reference results in the FMI Cross-Check layout, next to every built FMU.

Usage: ``python -m fmu_harness.checks.crosscheck [--models models]`` (``python build_fmu.py`` runs it).
For each ``<Model>.fmu`` (Python FMUs: FMI 2.0 in ``models/``, FMI 3.0 in ``models/fmi3/``; native
ones in ``models/native/`` and ``models/native/fmi3/``) it writes

* ``<Model>_ref.csv``: time and at most ten outputs of the model's standard run
  (:mod:`fmu_harness.runs.scenario`), header names quoted as in the model description;
* ``<Model>_in.csv``: the input table (breakpoints, interpolated linearly), if the model has inputs;
* ``<Model>_ref.opt``: StartTime, StopTime, StepSize and RelTol of the run.

:func:`rerun` simulates an FMU from these files alone with fmpy's ``simulate_fmu``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from fmpy import read_model_description, simulate_fmu
from fmpy.util import read_csv

from driveline.catalog import MODELS

from ..runs.runner import FmuInstance
from ..runs.scenario import scenario, standard_run
from ..console import summary

REL_TOL = 1e-9


def _write_csv(path: Path, names: list[str], rows: np.ndarray) -> None:
    with path.open("w", newline="") as stream:
        stream.write(",".join(f'"{name}"' for name in names) + "\n")
        for row in rows:
            stream.write(",".join(repr(float(value)) for value in row) + "\n")


def _read_opt(path: Path) -> dict[str, float]:
    return {key.strip(): float(value) for key, value in (line.split(",") for line in path.read_text().splitlines() if line)}


def write(fmu: Path) -> list[Path]:
    """Write the reference files of ``fmu`` next to it; returns their paths."""
    name = read_model_description(str(fmu)).modelName
    case = scenario(MODELS[name].spec)
    with FmuInstance(fmu) as instance:
        result = standard_run(instance, case.outputs)
    reference = fmu.with_name(f"{name}_ref.csv")
    _write_csv(reference, ["time", *case.outputs], result.view((float, len(result.dtype))))
    options = fmu.with_name(f"{name}_ref.opt")
    options.write_text(
        f"StartTime, 0.0\nStopTime, {case.stop_time!r}\nStepSize, {case.step_size!r}\nRelTol, {REL_TOL!r}\n"
    )
    written = [reference, options]
    if case.inputs:
        inputs = fmu.with_name(f"{name}_in.csv")
        _write_csv(inputs, ["time", *case.inputs], np.column_stack([case.breakpoints, *case.inputs.values()]))
        written.append(inputs)
    return written


def rerun(fmu: Path) -> tuple[np.ndarray, np.ndarray]:
    """Simulate ``fmu`` with fmpy from its ``_in.csv`` and ``_ref.opt``; returns (reference, result)."""
    name = read_model_description(str(fmu)).modelName
    reference = read_csv(fmu.with_name(f"{name}_ref.csv"))
    options = _read_opt(fmu.with_name(f"{name}_ref.opt"))
    inputs = fmu.with_name(f"{name}_in.csv")
    result = simulate_fmu(
        str(fmu),
        start_time=options["StartTime"],
        stop_time=options["StopTime"],
        step_size=options["StepSize"],
        output_interval=options["StepSize"],
        input=read_csv(inputs) if inputs.exists() else None,
        output=list(reference.dtype.names[1:]),
    )
    return reference, result


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs")
    args = parser.parse_args(argv)
    for pattern in ("*.fmu", "fmi3/*.fmu", "native/*.fmu", "native/fmi3/*.fmu"):
        for fmu in sorted(args.models.glob(pattern)):
            for path in write(fmu):
                print(path)


if __name__ == "__main__":
    main()
