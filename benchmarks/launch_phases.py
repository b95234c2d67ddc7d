"""The launch's third-order shudder at each relative phase of the joints, with and without the housings'
motion in the joints (docs/vehicle_launch.md, "The halfshafts' geometry on a moving powertrain").

Usage: ``python -m benchmarks.launch_phases [--models models] [--update-docs]`` after ``python build_fmu.py``: the native
package's launch (140 N.m, 4 s, the project's master in Gauss-Seidel order at 2e-4 s) with the right joint
started 0, 30, 60 and 90 deg ahead, once with ``mounts.housing_motion`` 1 (the package's) and once 0 (the
housings held): the peak third-order amplitude (the left halfshaft's angle, Hann window of two revolutions)
of the powertrain's lateral, yaw and pitch accelerations and of mode 1's share, the halfshafts' excursions
(bend, bend-plane angle, plunge) and the CPU per launch, as a Markdown table under its stamp.
"""

from __future__ import annotations

import math
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

from fmu_harness.runs import ssp_package
from fmu_harness.runs.system import LAUNCH_ORDER, run_jacobi
from fmu_harness.studies import launch_study, order_tracking

from benchmarks import report

PHASES = (0.0, 30.0, 60.0, 90.0)  # the right joint's phi_in_start [deg]
TORQUE, STOP, STEP = 140.0, 4.0, 2e-4
RESPONSES = ("mounts.y_ddot", "mounts.yaw_ddot", "mounts.pitch_ddot")
EXCURSIONS = tuple(f"mounts.{name}_{side}" for side in ("left", "right") for name in ("beta", "psi", "plunge"))


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


def table(models: Path) -> str:
    package = models / "native" / "VehicleLaunch.ssp"
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
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = report.parser(__doc__.splitlines()[0])
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs")
    args = parser.parse_args(argv)
    measurement = report.Measurement()
    found = table(args.models)
    report.publish("benchmark-launch-phases", measurement.stamp(
        "the native VehicleLaunch.ssp, 140 N.m for 4 s, the project's master in Gauss-Seidel order at 2e-4 s; "
        "CPU by time.process_time"), found, args.update_docs)


if __name__ == "__main__":
    main()
