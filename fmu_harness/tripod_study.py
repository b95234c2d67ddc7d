"""Main-job study of the TripodCoupling FMU: the seed's figures 5, 6, 10, 12 and 13, re-run through fmpy."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from driveline.tripod import closed_form  # noqa: E402
from driveline.tripod.exact import exact_pose  # noqa: E402

from .runner import simulate  # noqa: E402

SPEED = 2000.0 * math.pi / 30.0  # rad/s, the seed's 2000 rpm
BETAS_DEG = (5, 10, 15, 20, 25, 30, 35, 40, 45)
STEPS_PER_TURN = 360
ARCMIN = math.pi / (180 * 60)
COLUMNS = ("time", "phi_in", "phi_out", "delta_phi", "omega_out", "T_in", "F_pin", "rho", "theta", "Rz_out", "Rx_in", "Ry_in")


def run_turns(fmu: Path, beta_deg: float, kinematics: int) -> np.ndarray:
    """One input-shaft turn at 2000 rpm and constant beta, sampled every degree."""
    period = 2 * math.pi / SPEED
    return simulate(
        fmu, period, period / STEPS_PER_TURN,
        inputs={"omega_in": SPEED, "beta": math.radians(beta_deg), "T_load": 100.0},
        start_values={"kinematics": kinematics, "beta_max": math.radians(45.0)},
        outputs=COLUMNS[1:],
    )


def _angle_axis(ax: plt.Axes, ylabel: str, title: str) -> None:
    ax.set_xlabel("input angle phi_in [deg]")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.set_xlim(0, 360)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=5, loc="upper center", bbox_to_anchor=(0.5, -0.16))


def write(fmu: Path, out: Path) -> list[Path]:
    """Run the study, write the CSV and the figures into ``out``; return the files written."""
    out.mkdir(parents=True, exist_ok=True)
    runs = {beta: run_turns(fmu, beta, kinematics=1) for beta in BETAS_DEG}
    csv_path = out / "tripod_coupling.csv"
    with csv_path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(("beta_deg",) + COLUMNS)
        for beta, result in runs.items():
            writer.writerows((beta, *row) for row in result.tolist())

    files = [csv_path]
    figures = {
        "tripod_fig05_deviation.png": ("delta_phi", 1 / ARCMIN, "phi_out - phi_in [arcmin]", "Angle deviation (seed fig. 5)"),
        "tripod_fig10_Rz_out.png": ("Rz_out", 1.0, "R_z'' [N]", "Output-bearing axial reaction, eq 30 (seed fig. 10)"),
        "tripod_fig12_Rx_in.png": ("Rx_in", 1.0, "R_x' [N]", "Input-bearing reaction, eq 33 (seed fig. 12)"),
        "tripod_fig13_Ry_in.png": ("Ry_in", 1.0, "R_y' [N]", "Input-bearing reaction, eq 34 (seed fig. 13)"),
    }
    for name, (column, scale, ylabel, title) in figures.items():
        fig, ax = plt.subplots(figsize=(7, 4.6))
        for beta, result in runs.items():
            ax.plot(np.degrees(result["phi_in"]), result[column] * scale, label=f"beta = {beta} deg")
        _angle_axis(ax, ylabel, f"{title}\n2000 rpm, r = 26 mm, l = 700 mm, m = 0.2 kg, exact kinematics")
        fig.tight_layout()
        fig.savefig(out / name, dpi=120)
        plt.close(fig)
        files.append(out / name)

    fig, ax = plt.subplots(figsize=(7, 4))
    beta_grid = np.radians(np.linspace(0.0, 45.0, 91))
    phi = np.linspace(0.0, 2 * math.pi / 3, 241)
    for ratio in (0.02, 26 / 700, 0.06):
        r, l = 0.026, 0.026 / ratio
        peak_exact = [np.abs(exact_pose(phi, b, r, l).phi_out - phi).max() for b in beta_grid]
        line, = ax.plot(np.degrees(beta_grid), np.array(peak_exact) / ARCMIN, label=f"exact, r/l = {ratio:.3f}")
        ax.plot(np.degrees(beta_grid), closed_form.deviation_amplitude(beta_grid, r, l) / ARCMIN, "--",
                color=line.get_color(), label=f"eq 18, r/l = {ratio:.3f}")
    fmu_peaks = [np.abs(result["delta_phi"]).max() / ARCMIN for result in runs.values()]
    ax.plot(BETAS_DEG, fmu_peaks, "ko", label="FMU (exact), r/l = 0.037")
    ax.set_xlabel("bend angle beta [deg]")
    ax.set_ylabel("peak |phi_out - phi_in| [arcmin]")
    ax.set_title("Peak angle deviation vs bend angle (seed fig. 6)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "tripod_fig06_peak_deviation.png", dpi=120)
    plt.close(fig)
    files.append(out / "tripod_fig06_peak_deviation.png")
    return files
