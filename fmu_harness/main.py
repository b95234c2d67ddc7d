"""The main job: simulate the project's FMUs through fmpy and write results and figures.

Usage: ``python -m fmu_harness.main [--models models] [--out results]`` after
``python build_fmu.py``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from . import coupling_comparison, critical_speed_study, tripod_study


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs")
    parser.add_argument("--out", type=Path, default=Path("results"), help="folder for CSV files and figures")
    args = parser.parse_args(argv)
    written = tripod_study.write(args.models / "TripodCoupling.fmu", args.out)
    written += coupling_comparison.write(args.models, args.out)
    written += critical_speed_study.write(args.models / "CriticalSpeeds.fmu", args.out)
    for path in written:
        print(path)


if __name__ == "__main__":
    main()
