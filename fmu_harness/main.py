"""The main job: simulate the project's FMUs through fmpy and write results and figures.

Usage: ``driveline-fmus run [--models models] [--out results]`` (or ``python -m fmu_harness.main``)
after ``driveline-fmus build``. The studies run the native FMUs (``models/native/``); the Python FMUs
are compared with them in a process of their own (:mod:`fmu_harness.checks.python_fmu_check`), so that
the pythonfmu wrapper's exit-time defect cannot end the main job.
"""

from __future__ import annotations

from pathlib import Path

from .checks import python_fmu_check
from .console import CommandParser, Progress, summary
from .packaging import native
from .runs import system
from .studies import coupling_comparison, critical_speed_study, launch_study, mounts_study, tripod_study


def simulate(models: Path, out: Path) -> list[Path]:
    """Run every study on the native FMUs below ``models``, then the Python FMUs' check; the files written."""
    fmus = {name: native.fmu_path(models, name) for name in ("TripodCoupling", "CardanJoint", "UniversalReducer",
                                                             "CriticalSpeeds", "PowertrainMounts")}
    launch = system.ssp_path(system.vehicle_launch(), models, models)  # native/VehicleLaunch.ssp
    missing = [str(path) for path in (*fmus.values(), launch) if not path.exists()]
    if missing:
        raise SystemExit(f"driveline-fmus run: no native FMU {', '.join(missing)}: build the FMUs first with "
                         f"`driveline-fmus build{'' if models == Path('models') else f' --dest {models}'}` "
                         "(zig, which compiles the native ones, comes with the package)")
    studies = {
        "tripod coupling": lambda: tripod_study.write(fmus["TripodCoupling"], out),
        "coupling comparison": lambda: coupling_comparison.write(fmus["CardanJoint"].parent, out),
        "critical speeds": lambda: critical_speed_study.write(fmus["CriticalSpeeds"], out),
        "powertrain mounts": lambda: mounts_study.write(fmus["PowertrainMounts"], out),
        "launch shudder": lambda: launch_study.write(launch, out),
        "Python FMUs against native": lambda: python_fmu_check.run(models, models, out),
    }
    written = []
    with Progress("main job", len(studies)) as shown:
        for name, study in studies.items():
            shown.start(name)
            written += study()
            shown.advance(f"{name} done")
    return written


def main(argv: list[str] | None = None) -> None:
    parser = CommandParser(description=summary(__doc__))
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs")
    parser.add_argument("--out", type=Path, default=Path("results"), help="folder for CSV files and figures")
    args = parser.parse_args(argv)
    for path in simulate(args.models, args.out):
        print(path)


if __name__ == "__main__":
    main()
