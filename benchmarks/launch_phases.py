"""The launch's third-order shudder at each relative phase of the joints, with and without the housings'
motion in the joints (docs/vehicle_launch.md, "The halfshafts' geometry on a moving powertrain").

Usage: ``python -m benchmarks.launch_phases [--models models] [--update-docs]`` after ``python build_fmu.py``: the native
package's launch (140 N.m, 4 s, the project's master in Gauss-Seidel order at 2e-4 s) with the right joint
started 0, 30, 60 and 90 deg ahead, once with ``mounts.housing_motion`` 1 (the package's) and once 0 (the
housings held): the peak third-order amplitude (the left halfshaft's angle, Hann window of two revolutions)
of the powertrain's lateral, yaw and pitch accelerations and of mode 1's share, the halfshafts' excursions
(bend, bend-plane angle, plunge) and the CPU per launch, as a Markdown table under its stamp. With ``--figure PATH``
(``--update-docs``: docs/launch_housing_orders.png) also the order tracks of those accelerations over the left
halfshaft's speed, in phase and at 60 deg, with the housings held and moving
(:func:`fmu_harness.studies.launch_study.housing_motion_figure`).
"""

from __future__ import annotations

import math
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

from fmu_harness.doc_pages.sections import DOCS
from fmu_harness.runs import ssp_package
from fmu_harness.runs.system import LAUNCH_ORDER, run_jacobi
from fmu_harness.studies import launch_study, order_tracking
from fmu_harness.studies.figures import save

from benchmarks import report

PHASES = (0.0, 30.0, 60.0, 90.0)  # the right joint's phi_in_start [deg]
TORQUE, STOP, STEP = 140.0, 4.0, 2e-4
RESPONSES = ("mounts.y_ddot", "mounts.yaw_ddot", "mounts.pitch_ddot")
EXCURSIONS = tuple(f"mounts.{name}_{side}" for side in ("left", "right") for name in ("beta", "psi", "plunge"))
FIGURE_PHASES = (0.0, 60.0)  # the figure's launches: in phase and the worst phase
FIGURE = DOCS / "launch_housing_orders.png"  # where --update-docs writes the figure


def launch(package: Path, phase: float, moving: int) -> tuple[dict[str, np.ndarray], float]:
    """The outputs of one launch and its CPU time [s] (the master's run alone)."""
    system = ssp_package.read(package)
    changes = {"motor": {"T_level": TORQUE}, "joint_right": {"phi_in_start": math.radians(phase)},
               "mounts": {"housing_motion": moving}}
    parameters = {c.name: {**c.parameters, **changes.get(c.name, {})} for c in system.components}
    outputs = [launch_study.SHAFT, *(f"mounts.{n}_ddot" for n in launch_study.COORDINATES), *EXCURSIONS]
    with tempfile.TemporaryDirectory(prefix="driveline-phases-") as scratch:
        with zipfile.ZipFile(package) as archive:
            archive.extractall(scratch)
        fmus = {c.name: Path(scratch) / c.source for c in system.components}
        start = time.process_time()
        rows = run_jacobi(fmus, parameters, system.connections, STOP, STEP, outputs, order=LAUNCH_ORDER, initial=True)
        cpu = time.process_time() - start
    return {"t": rows[:, 0], **{name: rows[:, k + 1] for k, name in enumerate(outputs)}}, cpu


def peaks(found: dict[str, np.ndarray]) -> list[float]:
    """Third-order peaks of RESPONSES and of mode 1's share."""
    shaft = found[launch_study.SHAFT]
    accelerations = np.column_stack([found[f"mounts.{n}_ddot"] for n in launch_study.COORDINATES])
    body, modes = launch_study.powertrain_modes()
    mode_1 = launch_study.modal_accelerations(body, modes, accelerations)[:, 0]
    return [order_tracking.third_order_peak(found["t"], shaft, signal)[0]
            for signal in (*(found[name] for name in RESPONSES), mode_1)]


def table(models: Path) -> tuple[str, dict[tuple[float, bool], dict[str, tuple[np.ndarray, np.ndarray]]]]:
    """The Markdown table, and the order tracks of the figure's launches by (phase [deg], housings moving)."""
    package = models / "native" / "VehicleLaunch.ssp"
    drawn = {}
    lines = ["| right joint's phase | housings | lateral `y_ddot` [m/s2] | yaw `yaw_ddot` [rad/s2] | pitch `pitch_ddot` "
             "[rad/s2] | mode 1 [m/s2] | bend left, right [deg] | plane angle left, right [deg] | plunge left, "
             "right [mm] | CPU per launch [s] |", "|---" * 10 + "|"]
    for phase in PHASES:
        for moving in (0, 1):
            found, cpu = launch(package, phase, moving)
            span = {name: (found[name].min(), found[name].max()) for name in EXCURSIONS}
            shown = [", ".join(f"{scale * span[f'mounts.{name}_{side}'][0]:.2f} to "
                               f"{scale * span[f'mounts.{name}_{side}'][1]:.2f}" for side in ("left", "right"))
                     for name, scale in (("beta", 180 / math.pi), ("psi", 180 / math.pi), ("plunge", 1e3))]
            lines.append(f"| {phase:.0f} deg | {'moving' if moving else 'held'} | "
                         + " | ".join(f"{value:.3g}" for value in peaks(found)) + " | " + " | ".join(shown)
                         + f" | {cpu:.2f} |")
            print(lines[-1], flush=True)
            if phase in FIGURE_PHASES:
                drawn[phase, bool(moving)] = launch_study.housing_tracks(found["t"], found[launch_study.SHAFT],
                                                                         found)
    return "\n".join(lines), drawn


def main(argv: list[str] | None = None) -> None:
    parser = report.parser(__doc__.splitlines()[0])
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs")
    parser.add_argument("--figure", type=Path,
                        help=f"also draw the order tracks into this PNG file (--update-docs: {FIGURE})")
    args = parser.parse_args(argv)
    if not (args.models / "native" / "VehicleLaunch.ssp").is_file():
        parser.error(f"no {args.models / 'native' / 'VehicleLaunch.ssp'}: run python build_fmu.py first")
    measurement = report.Measurement()
    found, drawn = table(args.models)
    report.publish("benchmark-launch-phases", measurement.stamp(
        "the native VehicleLaunch.ssp, 140 N.m for 4 s, the project's master in Gauss-Seidel order at 2e-4 s; "
        "CPU by time.process_time"), found, args.update_docs)
    for path in {args.figure, FIGURE if args.update_docs else None} - {None}:
        subtitle = (f"The native VehicleLaunch.ssp's launch, 140 N.m for 4 s (measured {measurement.date:%Y-%m-%d}):\n"
                    "the right joint in phase or 60 deg ahead, the housings held (solid) or moving (dashed)")
        print(f"figure: {save(launch_study.housing_motion_figure(drawn, subtitle), path)}")


if __name__ == "__main__":
    main()
