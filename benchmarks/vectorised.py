"""Vectorised physics core vs stepping the TripodCoupling FMU for the same points.

``python -m benchmarks.vectorised``: a grid of bend angles x one input turn, evaluated
(a) by ``coupling_outputs`` on whole arrays and (b) by stepping the FMU through fmpy's
low-level API, one run per bend angle. Prints both times, the ratio, and the largest
difference between the two results.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from benchmarks.timing import best_of, machine
from driveline.tripod.outputs import coupling_outputs
from fmu_harness.runs.runner import FmuInstance

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


def main(models: Path = Path("models")) -> list[tuple[str, float, float, float, float]]:
    rows = []
    for kinematics, label in ((0, "closed form"), (1, "exact")):
        fmu_time = best_of(lambda: stepped(models / "TripodCoupling.fmu", kinematics), repeats=2)
        array_time = best_of(lambda: vectorised(kinematics), repeats=5)
        difference = np.abs(stepped(models / "TripodCoupling.fmu", kinematics) - vectorised(kinematics)).max()
        rows.append((label, fmu_time, array_time, fmu_time / array_time, difference))
    points = len(BETAS) * STEPS
    print(f"TripodCoupling, {points} points ({len(BETAS)} bend angles x {STEPS} per turn); {machine()}")
    print("| kinematics | FMU stepping [s] | vectorised core [s] | ratio | max difference |")
    print("|---|---|---|---|---|")
    for label, fmu_time, array_time, ratio, difference in rows:
        print(f"| {label} | {fmu_time:.3f} | {array_time:.4f} | {ratio:.0f}x | {difference:.1e} |")
    return rows


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("models"))
