"""Main-job study of the TripodCoupling FMU through fmpy: the seed's figures 5, 6, 10, 12 and 13
(the reactions as the seed prints them beside the force balance), the reactions over one turn
for several bend angles and two loads, and their mean and 3rd-order parts against the bend angle."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from driveline.tripod import closed_form  # noqa: E402
from driveline.tripod.exact import exact_pose  # noqa: E402
from driveline.tripod.spec import SPEC  # noqa: E402

from ..runs.runner import simulate  # noqa: E402
from . import result_table  # noqa: E402

SPEED = 2000.0 * math.pi / 30.0  # rad/s, the seed's 2000 rpm
BETAS_DEG = (5, 10, 15, 20, 25, 30, 35, 40, 45)
STEPS_PER_TURN = 360
ARCMIN = math.pi / (180 * 60)
LOADS = (0.0, 500.0)  # N.m
REACTIONS = ("Rx_in", "Ry_in", "Mx_in", "My_in", "T_in", "Rz_out", "Rx_out", "Ry_out")
COLUMNS = ("time", "phi_in", "phi_out", "delta_phi", "omega_out", "omega_spin", "F_pin", "rho", "theta",
           "a_plunger_sum", "F_arm1", "F_plunger1") + REACTIONS
SEED = {"Rz_out": "eq 30", "Rx_in": "eq 33", "Ry_in": "eq 34"}


def run_turns(fmu: Path, beta_deg: float, kinematics: int, T_load: float = 500.0, seed_reactions: int = 0) -> np.ndarray:
    """One input-shaft turn at 2000 rpm and constant beta, sampled every degree."""
    period = 2 * math.pi / SPEED
    return simulate(
        fmu, period, period / STEPS_PER_TURN,
        inputs={"omega_in": SPEED, "beta": math.radians(beta_deg), "T_load": T_load},
        start_values={"kinematics": kinematics, "beta_max": math.radians(45.0), "seed_reactions": seed_reactions},
        outputs=COLUMNS[1:],
    )[:-1]


def order_amplitude(values: np.ndarray, order: int = 3) -> float:
    """Amplitude of one order of one turn's samples."""
    return 2.0 * abs(np.fft.rfft(values)[order]) / len(values)


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
    runs = {(beta, load): run_turns(fmu, beta, 1, load) for beta in BETAS_DEG for load in LOADS}
    seed = {beta: run_turns(fmu, beta, 1, seed_reactions=1) for beta in BETAS_DEG}
    rows = [(beta, load, "force balance", *row) for (beta, load), result in runs.items() for row in result.tolist()]
    rows += [(beta, LOADS[-1], "seed", *row) for beta, result in seed.items() for row in result.tolist()]
    header = ("beta [deg]", result_table.column(SPEC, "T_load"), "reactions", "time [s]",
              *(result_table.column(SPEC, n) for n in COLUMNS[1:]))
    files = [result_table.write_csv(out / "tripod_coupling.csv", header, rows)]
    loaded = {beta: runs[beta, LOADS[-1]] for beta in BETAS_DEG}
    fig, ax = plt.subplots(figsize=(7, 4.6))
    for beta, result in loaded.items():
        ax.plot(np.degrees(result["phi_in"]), result["delta_phi"] / ARCMIN, label=f"beta = {beta} deg")
    _angle_axis(ax, "phi_out - phi_in [arcmin]",
                "Angle deviation (seed fig. 5)\n2000 rpm, r = 26 mm, l = 700 mm, exact kinematics")
    files.append(_save(fig, out / "tripod_fig05_deviation.png"))

    for figure, column, symbol in (("10", "Rz_out", "R_z''"), ("12", "Rx_in", "R_x'"), ("13", "Ry_in", "R_y'")):
        fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
        for beta in BETAS_DEG:
            left.plot(np.degrees(seed[beta]["phi_in"]), seed[beta][column], label=f"beta = {beta} deg")
            right.plot(np.degrees(loaded[beta]["phi_in"]), loaded[beta][column], label=f"beta = {beta} deg")
        _angle_axis(left, f"{symbol} [N]", f"seed's {SEED[column]} as printed (seed fig. {figure})")
        _angle_axis(right, f"{symbol} [N]", f"force balance, T_load = {LOADS[-1]:.0f} N.m")
        fig.suptitle(f"{symbol}: 2000 rpm, r = 26 mm, l = 700 mm, m = 0.2 kg, exact kinematics", fontsize=10)
        files.append(_save(fig, out / f"tripod_fig{figure}_{column}.png"))

    files.append(_turn_figure(runs, out / "tripod_reactions_turn.png"))
    files.append(_beta_figure(runs, seed, out / "tripod_reactions_vs_beta.png"))
    files += friction_figures(fmu, out)

    fig, ax = plt.subplots(figsize=(7, 4))
    beta_grid = np.radians(np.linspace(0.0, 45.0, 91))
    phi = np.linspace(0.0, 2 * math.pi / 3, 241)
    for ratio in (0.02, 26 / 700, 0.06):
        r, l = 0.026, 0.026 / ratio
        peak_exact = [np.abs(exact_pose(phi, b, r, l).phi_out - phi).max() for b in beta_grid]
        line, = ax.plot(np.degrees(beta_grid), np.array(peak_exact) / ARCMIN, label=f"exact, r/l = {ratio:.3f}")
        ax.plot(np.degrees(beta_grid), closed_form.deviation_amplitude(beta_grid, r, l) / ARCMIN, "--",
                color=line.get_color(), label=f"eq 18, r/l = {ratio:.3f}")
    fmu_peaks = [np.abs(result["delta_phi"]).max() / ARCMIN for result in loaded.values()]
    ax.plot(BETAS_DEG, fmu_peaks, "ko", label="FMU (exact), r/l = 0.037")
    ax.set_xlabel("bend angle beta [deg]")
    ax.set_ylabel("peak |phi_out - phi_in| [arcmin]")
    ax.set_title("Peak angle deviation vs bend angle (seed fig. 6)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    files.append(_save(fig, out / "tripod_fig06_peak_deviation.png"))
    return files


def _save(fig: plt.Figure, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _turn_figure(runs: dict, path: Path) -> Path:
    """Every bearing reaction over one turn, for three bend angles and both loads."""
    fig, axes = plt.subplots(2, 4, figsize=(16, 7.5), sharex=True)
    for ax, column in zip(axes.flat, REACTIONS):
        for beta in (15, 30, 45):
            for load, style in zip(LOADS, ("--", "-")):
                result = runs[beta, load]
                label = f"beta = {beta} deg, T = {load:.0f} N.m"
                color = {15: "tab:blue", 30: "tab:orange", 45: "tab:red"}[beta]
                ax.plot(np.degrees(result["phi_in"]), result[column], style, color=color, label=label)
        unit = "N.m" if column in ("Mx_in", "My_in", "T_in") else "N"
        ax.set_title(column, fontsize=10)
        ax.set_ylabel(f"{column} [{unit}]")
        ax.set_xlim(0, 360)
        ax.grid(True, alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("input angle phi_in [deg]")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=6, fontsize=8)
    fig.suptitle("Bearing reactions over one turn (force balance, exact kinematics), 2000 rpm, "
                 "r = 26 mm, l = 700 mm, m = 0.2 kg", fontsize=11)
    fig.tight_layout(rect=(0, 0.06, 1, 0.96))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _beta_figure(runs: dict, seed: dict, path: Path) -> Path:
    """Mean side force and 3rd-order amplitudes against beta, force balance beside the seed."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
    betas = np.array(BETAS_DEG, dtype=float)
    grid = np.linspace(0.0, 45.0, 91)
    for load, marker in zip(LOADS, ("s", "o")):
        for column, color in (("Ry_in", "tab:blue"), ("Rx_in", "tab:green")):
            means = [runs[beta, load][column].mean() for beta in BETAS_DEG]
            left.plot(betas, means, marker + "-", color=color, label=f"{column} mean, T = {load:.0f} N.m")
    left.plot(grid, -LOADS[-1] * np.tan(np.radians(grid) / 2) / 0.7, "k:", label="-T tan(beta/2) / l")
    left.plot(betas, [seed[beta]["Ry_in"].mean() for beta in BETAS_DEG], "x", color="gray",
              label="seed's eqs 33, 34: mean 0")
    left.set_title("Mean input-bearing force")
    left.set_ylabel("mean force [N]")
    for column, color in (("Rx_in", "tab:green"), ("Ry_in", "tab:blue"), ("Rz_out", "tab:red")):
        for load, marker in zip(LOADS, ("s", "o")):
            amplitude = [order_amplitude(runs[beta, load][column]) for beta in BETAS_DEG]
            right.semilogy(betas, amplitude, marker + "-", color=color, label=f"{column}, T = {load:.0f} N.m")
        order = 6 if column == "Ry_in" else 3  # eq 34 has no 3rd order
        seed_values = [order_amplitude(seed[beta][column], order) for beta in BETAS_DEG]
        right.semilogy(betas, seed_values, "x--", color=color,
                       label=f"{column}, seed's {SEED[column]}" + (" (its 6th order)" if order == 6 else ""))
    right.set_title("3rd-order amplitude (seed's eq 34: 6th)")
    right.set_ylabel("amplitude [N]")
    for ax in (left, right):
        ax.set_xlabel("bend angle beta [deg]")
        ax.grid(True, alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.suptitle("Force balance against the seed, 2000 rpm, r = 26 mm, l = 700 mm, m = 0.2 kg", fontsize=10)
    return _save(fig, path)


FRICTION = (0.02, 0.05, 0.1)


def friction_figures(fmu: Path, out: Path) -> list[Path]:
    """Generated axial force over one turn for several mu and beta; its 3rd-order amplitude and
    the mean efficiency against beta at two loads (mu = 0.05)."""
    def run(beta: float, load: float, mu: float) -> np.ndarray:
        period = 2 * math.pi / SPEED
        return simulate(fmu, period, period / STEPS_PER_TURN,
                        inputs={"omega_in": SPEED, "beta": math.radians(beta), "T_load": load},
                        start_values={"kinematics": 1, "mu": mu},
                        outputs=("phi_in", "Rz_in", "P_friction", "omega_spin"))[:-1]

    fig, ax = plt.subplots(figsize=(8, 5.4))
    for beta, color in zip((15, 30, 45), ("tab:blue", "tab:orange", "tab:red")):
        for mu, style in zip(FRICTION, (":", "--", "-")):
            result = run(beta, 500.0, mu)
            ax.plot(np.degrees(result["phi_in"]), -result["Rz_in"], style, color=color,
                    label=f"beta = {beta} deg, mu = {mu}")
    _angle_axis(ax, "generated axial force -Rz_in [N]",
                "Generated axial force on the input housing, T_load = 500 N.m, 2000 rpm")
    ax.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    files = [_save(fig, out / "tripod_friction_axial_force.png")]

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.6))
    betas = np.arange(5, 46, 5)
    for load, marker in ((250.0, "s"), (500.0, "o")):
        runs = [run(float(beta), load, 0.05) for beta in betas]
        left.plot(betas, [order_amplitude(-result["Rz_in"]) for result in runs], marker + "-",
                  label=f"T_load = {load:.0f} N.m")
        right.plot(betas, [np.mean(load * r["omega_spin"]) / np.mean(load * r["omega_spin"] + r["P_friction"])
                           for r in runs], marker + "-", label=f"T_load = {load:.0f} N.m")
    left.set_ylabel("3rd-order amplitude of -Rz_in [N]")
    right.set_ylabel("mean efficiency [-]")
    for ax in (left, right):
        ax.set_xlabel("bend angle beta [deg]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Friction mu = 0.05 in both sliding pairs, 2000 rpm, r = 26 mm, l = 700 mm, m = 0.2 kg", fontsize=10)
    files.append(_save(fig, out / "tripod_friction_vs_beta.png"))
    return files
