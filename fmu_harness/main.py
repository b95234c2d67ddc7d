"""The main job: simulate the project's FMUs through fmpy and write results and figures.

Usage: ``python -m fmu_harness.main [--models models] [--out results]`` after
``python build_fmu.py``. The studies run the native FMUs (``models/native/``); the Python FMUs
are compared with them in a process of their own (:mod:`fmu_harness.checks.python_fmu_check`), so that
the pythonfmu wrapper's exit-time defect cannot end the main job.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .checks import python_fmu_check
from .packaging import native
from .studies import coupling_comparison, critical_speed_study, mounts_study, tripod_study


def simulate(models: Path, out: Path) -> list[Path]:
    """Run every study on the native FMUs below ``models``, then the Python FMUs' check; the files written."""
    fmus = {name: native.fmu_path(models, name) for name in ("TripodCoupling", "CardanJoint", "UniversalReducer",
                                                             "CriticalSpeeds", "PowertrainMounts")}
    missing = [str(path) for path in fmus.values() if not path.exists()]
    if missing:
        raise SystemExit(f"no native FMU {', '.join(missing)}: build them with `python build_fmu.py` "
                         "(it needs a C compiler, docs/native_fmus.md)")
    written = tripod_study.write(fmus["TripodCoupling"], out)
    written += coupling_comparison.write(fmus["CardanJoint"].parent, out)
    written += critical_speed_study.write(fmus["CriticalSpeeds"], out)
    written += mounts_study.write(fmus["PowertrainMounts"], out)
    return written + python_fmu_check.run(models, models, out)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs")
    parser.add_argument("--out", type=Path, default=Path("results"), help="folder for CSV files and figures")
    args = parser.parse_args(argv)
    for path in simulate(args.models, args.out):
        print(path)


if __name__ == "__main__":
    main()
