"""The main job's cross-check of the Python FMUs against the native ones, in a process of its own.

Usage: ``python -m fmu_harness.checks.python_fmu_check [--models models] [--native models] [--out results]
[NAME ...]``; the main job runs it as a subprocess (:func:`run`). Each model's (default: every
catalog model's) FMI 2.0 Python FMU in ``--models`` and its native FMU below ``--native`` run the
standard scenario (:mod:`fmu_harness.runs.scenario`); ``python_fmus.md`` in ``--out`` lists the largest
difference of any output, relative to that output's largest magnitude.

Why a process of its own: a process that has loaded a pythonfmu FMI 2.0 FMU reads and writes freed
memory when it exits (wrapper defect 10, docs/robustness.md): the wrapper's ``__cxa_atexit``
handler destroys its interpreter state, then its library destructor decrements the reference count
inside the freed block. When glibc has put that block on a doubly linked free list the decrement
corrupts the list, and the exit aborts. This process therefore ends with ``os._exit`` once its
file is written (no exit handlers, no library destructors), and :func:`run` still reports a
check that ended by a signal instead of failing the main job.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from driveline.catalog import MODELS

from ..packaging import native
from ..runs.runner import FmuInstance
from ..runs.scenario import standard_run
from ..console import summary

REPORT = "python_fmus.md"


def largest_deviation(models: Path, natives: Path, name: str) -> float:
    """Largest difference between the Python and native FMU's standard runs, relative to each
    output's largest magnitude."""
    runs = []
    for path in (models / f"{name}.fmu", native.fmu_path(natives, name)):
        with FmuInstance(path) as instance:
            runs.append(standard_run(instance))
    python, c = runs
    return max(float(np.abs(python[n] - c[n]).max() / (np.abs(python[n]).max() or 1.0)) for n in python.dtype.names)


def write(models: Path, natives: Path, out: Path, names: Sequence[str] = tuple(MODELS)) -> Path:
    """Compare each of ``names`` that has both FMUs; write the table into ``out``."""
    names = [n for n in names if (models / f"{n}.fmu").exists() and native.fmu_path(natives, n).exists()]
    lines = ["Python FMUs (FMI 2.0) against the native FMUs, standard scenario: largest difference of any output,",
             "relative to that output's largest magnitude.", "", "| model | largest relative difference |",
             "|---|---|"]
    lines += [f"| {name} | {largest_deviation(models, natives, name):.2e} |" for name in names]
    out.mkdir(parents=True, exist_ok=True)
    report = out / REPORT
    report.write_text("\n".join(lines) + "\n")
    return report


def command(models: Path, natives: Path, out: Path, names: Sequence[str] = ()) -> list[str]:
    """The command line of the check's process."""
    return [sys.executable, "-m", __name__, "--models", str(models), "--native", str(natives), "--out", str(out),
            *names]


def run(models: Path, natives: Path, out: Path, names: Sequence[str] = ()) -> list[Path]:
    """Run the check in a subprocess; the files it wrote, or none, with a note on stderr, if it failed."""
    done = subprocess.run(command(models, natives, out, names), capture_output=True, text=True)
    written = [Path(line) for line in done.stdout.splitlines() if line.strip()]
    if done.returncode != 0:
        how = f"signal {-done.returncode}" if done.returncode < 0 else f"exit status {done.returncode}"
        print(f"python FMU check ended with {how} after writing {len(written)} file(s):\n{done.stderr[-2000:]}",
              file=sys.stderr)
    return written


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("names", nargs="*", help="models to compare (default: all)")
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of the FMI 2.0 Python FMUs")
    parser.add_argument("--native", type=Path, help="folder whose native/ holds the native FMUs (default: --models)")
    parser.add_argument("--out", type=Path, default=Path("results"), help="folder for the report")
    args = parser.parse_args(argv)
    print(write(args.models, args.native or args.models, args.out, args.names or tuple(MODELS)), flush=True)
    sys.stderr.flush()
    os._exit(0)  # skip the wrapper's exit-time use of freed memory (module docstring)


if __name__ == "__main__":
    main()
