"""Vectorised physics core vs stepping the TripodCoupling FMU for the same points.

``python -m benchmarks.vectorised``: a grid of bend angles x one input turn, evaluated
(a) by ``coupling_outputs`` on whole arrays and (b) by stepping the FMU through fmpy's
low-level API, one run per bend angle. Prints both times, the ratio, and the largest
difference between the two results.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from benchmarks import report
from benchmarks.timing import best_of
from driveline.tripod.outputs import coupling_outputs
from fmu_harness.runs.runner import FmuInstance
from fmu_harness.console import summary

OMEGA, T_LOAD, R, L, M = 2000 * math.pi / 30, 100.0, 0.026, 0.700, 0.2
BETAS = np.radians(np.linspace(1.0, 45.0, 10))
STEPS = 1000  # per turn


def stepped(fmu_path: Path, kinematics: int) -> np.ndarray:
    h = 2 * math.pi / OMEGA / STEPS
    rows = []
    with FmuInstance(fmu_path) as fmu:
        fmu.initialize({"kinematics": kinematics})
        references = [fmu.variables[n].valueReference for n in ("omega_in", "beta", "T_load")]
        outputs = [fmu.variables[n].valueReference for n in ("phi_out", "omega_out", "Rz_out")]
        for beta in BETAS:
            fmu.reset()
            fmu.initialize({"kinematics": kinematics, "omega_in": OMEGA, "beta": beta, "T_load": T_LOAD})
            for k in range(STEPS):
                fmu.fmu.setReal(references, [OMEGA, beta, T_LOAD])
                fmu.fmu.doStep(k * h, h)
                rows.append(fmu.fmu.getReal(outputs))
    return np.array(rows)


def vectorised(kinematics: int) -> np.ndarray:
    h = 2 * math.pi / OMEGA / STEPS
    phi = OMEGA * h * np.arange(1, STEPS + 1)
    phi_grid, beta_grid = np.meshgrid(phi, BETAS)
    values, _ = coupling_outputs(phi_grid.ravel(), beta_grid.ravel(), OMEGA, T_LOAD, R, L, M, kinematics)
    return np.column_stack([values["phi_out"], values["omega_out"], values["Rz_out"]])


def main() -> None:
    arguments = report.parser(summary(__doc__))
    arguments.add_argument("models", nargs="?", type=Path, default=Path("models"), help="folder of the FMI 2.0 FMUs")
    args = arguments.parse_args()
    measurement = report.Measurement()
    fmu = args.models / "TripodCoupling.fmu"
    lines = ["| kinematics | FMU stepping [s] | vectorised core [s] | ratio | max difference |",
             "|---|---|---|---|---|"]
    for kinematics, label in ((0, "closed form"), (1, "exact")):
        fmu_time = best_of(lambda: stepped(fmu, kinematics), repeats=2)
        array_time = best_of(lambda: vectorised(kinematics), repeats=5)
        difference = np.abs(stepped(fmu, kinematics) - vectorised(kinematics)).max()
        ratio = fmu_time / array_time
        lines.append(f"| {label} | {fmu_time:.3f} | {array_time:.4f} | {ratio:.0f}x | {difference:.1e} |")
    report.publish("benchmark-vectorised", measurement.stamp(
        f"TripodCoupling, {len(BETAS) * STEPS} points ({len(BETAS)} bend angles x {STEPS} steps of one turn), "
        "wall time, FMU best of 2, core best of 5"), "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
