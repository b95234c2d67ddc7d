"""Main-job study of the TripodCoupling FMU through fmpy: the seed's figures 5, 6, 10, 12 and 13
(the reactions as the seed prints them beside the force balance), the reactions over one turn
for several bend angles and two loads, and their mean and 3rd-order parts against the bend angle.

:func:`run` simulates, :func:`figures` draws (every figure returned open, for a test to measure),
:func:`write` writes the CSV file and saves the figures. Curves whose sizes differ by more than
:data:`.figures.WITHIN` go to panels of their own scale."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from driveline.tripod import closed_form
from driveline.tripod.exact import exact_pose
from driveline.tripod.spec import DOUBLE_ROLLER, PLAIN_TRIPOD, SINGLE_ROLLER, SPEC

from ..runs.runner import simulate
from ..runs import result_table
from .figures import BLUE, GREEN, VERMILLION, blank, by_scale, figure, ordered, save, span

SPEED = 2000.0 * math.pi / 30.0  # rad/s, the seed's 2000 rpm
BETAS_DEG = (5, 10, 15, 20, 25, 30, 35, 40, 45)
STEPS_PER_TURN = 360
ARCMIN = math.pi / (180 * 60)
LOADS = (0.0, 500.0)  # N.m
REACTIONS = ("Rx_in", "Ry_in", "Mx_in", "My_in", "T_in", "Rz_out", "Rx_out", "Ry_out")
COLUMNS = ("time", "phi_in", "phi_out", "delta_phi", "omega_out", "omega_spin", "F_pin", "rho", "theta",
           "a_plunger_sum", "F_arm1", "F_plunger1") + REACTIONS
SEED = {"Rz_out": "eq 30", "Rx_in": "eq 33", "Ry_in": "eq 34"}
SEED_FIGURES = (("10", "Rz_out", "R_z''"), ("12", "Rx_in", "R_x'"), ("13", "Ry_in", "R_y'"))
TURN_BETAS = (15, 30, 45)
FRICTION = (0.02, 0.05, 0.1)
FRICTION_BETAS = tuple(range(5, 46, 5))
FRICTION_LOADS = (250.0, 500.0)
FRICTION_MU = 0.05  # the friction coefficient of the figure against beta
#: How each reaction's curves are told apart: one colour per bend angle, the smallest drawn last.
BETA_COLOURS = dict(zip(BETAS_DEG, ordered(len(BETAS_DEG))))  # dark to light as beta grows
#: The joints of the roller tripods' figure (tripod_type), the bend angles and loads it runs, its friction
JOINTS = {PLAIN_TRIPOD: "plain tripod", SINGLE_ROLLER: "single roller", DOUBLE_ROLLER: "double roller"}
ROLLER_BETAS = (2, 4, 8, 12, 16, 20)
ROLLER_LOADS = (100.0, 300.0, 500.0)
JOINTS_LOAD, JOINTS_BETA = 300.0, 12  # the figure's load against the angle, and angle against the load
#: The CSV's ``reactions`` column: which reactions a row holds, a label rather than a number.
REACTIONS_COLUMN = "reactions"


@dataclass(frozen=True)
class TripodRuns:
    """One turn per case: ``loaded[beta, T_load]`` and ``seed[beta]`` (the seed's reactions at
    500 N.m) with every output of :data:`COLUMNS`, ``friction[beta, T_load, mu]`` the friction runs,
    ``joints[tripod_type, beta, T_load]`` the three joints with friction FRICTION_MU."""

    loaded: dict[tuple[float, float], np.ndarray]
    seed: dict[float, np.ndarray]
    friction: dict[tuple[float, float, float], np.ndarray]
    joints: dict[tuple[int, float, float], np.ndarray]


def run_turns(fmu: Path, beta_deg: float, kinematics: int, T_load: float = 500.0, seed_reactions: int = 0) -> np.ndarray:
    """One input-shaft turn at 2000 rpm and constant beta, sampled every degree."""
    period = 2 * math.pi / SPEED
    return simulate(
        fmu, period, period / STEPS_PER_TURN,
        inputs={"omega_in": SPEED, "beta": math.radians(beta_deg), "T_load": T_load},
        start_values={"kinematics": kinematics, "beta_max": math.radians(45.0), "seed_reactions": seed_reactions},
        outputs=COLUMNS[1:],
    )[:-1]


def friction_turn(fmu: Path, beta_deg: float, T_load: float, mu: float, tripod_type: int = PLAIN_TRIPOD) -> np.ndarray:
    """One turn with friction ``mu`` in the sliding pairs (rolling resistance at its default in a roller tripod)."""
    period = 2 * math.pi / SPEED
    return simulate(fmu, period, period / STEPS_PER_TURN,
                    inputs={"omega_in": SPEED, "beta": math.radians(beta_deg), "T_load": T_load},
                    start_values={"kinematics": 1, "mu": mu, "tripod_type": tripod_type},
                    outputs=("phi_in", "Rz_in", "P_friction", "omega_spin"))[:-1]


def run(fmu: Path) -> TripodRuns:
    """Every run the study's table and figures need."""
    friction_cases = {(beta, 500.0, mu) for beta in TURN_BETAS for mu in FRICTION}
    friction_cases |= {(beta, load, FRICTION_MU) for beta in FRICTION_BETAS for load in FRICTION_LOADS}
    return TripodRuns(
        loaded={(beta, load): run_turns(fmu, beta, 1, load) for beta in BETAS_DEG for load in LOADS},
        seed={beta: run_turns(fmu, beta, 1, seed_reactions=1) for beta in BETAS_DEG},
        friction={case: friction_turn(fmu, *case) for case in sorted(friction_cases)},
        joints={(joint, beta, load): friction_turn(fmu, beta, load, FRICTION_MU, joint)
                for joint in JOINTS for beta in ROLLER_BETAS for load in ROLLER_LOADS},
    )


def order_amplitude(values: np.ndarray, order: int = 3) -> float:
    """Amplitude of one order of one turn's samples."""
    return 2.0 * abs(np.fft.rfft(values)[order]) / len(values)


def write(fmu: Path, out: Path) -> list[Path]:
    """Run the study, write the CSV and the figures into ``out``; return the files written."""
    out.mkdir(parents=True, exist_ok=True)
    runs = run(fmu)
    rows = [(beta, load, "force balance", *row) for (beta, load), result in runs.loaded.items()
            for row in result.tolist()]
    rows += [(beta, LOADS[-1], "seed", *row) for beta, result in runs.seed.items() for row in result.tolist()]
    header = ("beta [deg]", result_table.column(SPEC, "T_load"), REACTIONS_COLUMN, "time [s]",
              *(result_table.column(SPEC, n) for n in COLUMNS[1:]))
    files = [result_table.write_csv(out / "tripod_coupling.csv", header, rows)]
    return files + [save(fig, out / name) for name, fig in figures(runs).items()]


def figures(runs: TripodRuns) -> dict[str, Figure]:
    """The study's figures by file name."""
    loaded = {beta: runs.loaded[beta, LOADS[-1]] for beta in BETAS_DEG}
    found = {"tripod_fig05_deviation.png": deviation_figure(loaded)}
    for number, column, symbol in SEED_FIGURES:
        found[f"tripod_fig{number}_{column}.png"] = seed_figure(runs.seed, loaded, number, column, symbol)
    found["tripod_reactions_turn.png"] = turn_figure(runs.loaded)
    found["tripod_reactions_vs_beta.png"] = beta_figure(runs.loaded, runs.seed)
    found["tripod_friction_axial_force.png"] = friction_turn_figure(runs.friction)
    found["tripod_friction_vs_beta.png"] = friction_beta_figure(runs.friction)
    found["tripod_joints_axial_force.png"] = joints_figure(runs.joints)
    found["tripod_fig06_peak_deviation.png"] = peak_deviation_figure(loaded)
    return found


def _angle_axis(ax: Axes, ylabel: str, title: str) -> None:
    ax.set_xlabel("input angle phi_in [deg]")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.set_xlim(0, 360)
    ax.grid(True, alpha=0.3)


def _beta_curves(ax: Axes, results: dict[float, np.ndarray], values, betas: list) -> None:
    """One curve per bend angle of ``betas``, coloured by :data:`BETA_COLOURS`, the largest first
    so that a smaller curve is drawn over a larger one."""
    for beta in sorted(betas, key=lambda b: -np.abs(values(results[b])).max()):
        ax.plot(np.degrees(results[beta]["phi_in"]), values(results[beta]), color=BETA_COLOURS[beta],
                label=f"beta = {beta} deg")


def _beta_legend(fig: Figure, betas, loc: str = "lower center") -> None:
    """One legend for the whole figure: the colour of each bend angle."""
    handles = [Line2D([], [], color=BETA_COLOURS[beta], label=f"beta = {beta} deg") for beta in betas]
    fig.legend(handles=handles, loc=loc, ncol=len(handles), fontsize=8)


def _panels_by_scale(axes_row, results: dict[float, np.ndarray], values, ylabel: str, title: str) -> None:
    """The bend angles of ``results`` spread over ``axes_row``, one scale per panel; panels left over
    are hidden."""
    groups = by_scale({beta: float(np.abs(values(result)).max()) for beta, result in results.items()})
    for ax, betas in zip(axes_row, groups):
        _beta_curves(ax, results, values, betas)
        _angle_axis(ax, ylabel, f"{title}, beta = {span(betas)}")
    for ax in axes_row[len(groups):]:
        ax.set_visible(False)


def deviation_figure(loaded: dict[float, np.ndarray]) -> Figure:
    """Seed fig. 5: phi_out - phi_in over one turn; the deviation grows with beta^3, so the bend
    angles are spread over panels of their own scale."""
    values = lambda result: result["delta_phi"] / ARCMIN  # noqa: E731
    panels = len(by_scale({beta: np.abs(values(r)).max() for beta, r in loaded.items()}))
    fig, axes = figure(1, panels, figsize=(4.2 * panels, 4.4), squeeze=False)
    _panels_by_scale(axes[0], loaded, values, "phi_out - phi_in [arcmin]", "exact kinematics")
    fig.suptitle("Angle deviation (seed fig. 5), 2000 rpm, r = 26 mm, l = 700 mm; one scale per panel "
                 "(the deviation grows with beta^3)", fontsize=10)
    _beta_legend(fig, BETAS_DEG)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    return fig


def seed_figure(seed: dict[float, np.ndarray], loaded: dict[float, np.ndarray], number: str, column: str,
                symbol: str) -> Figure:
    """Seed fig. ``number``: the seed's equation as printed (top row) and the force balance (bottom
    row) over one turn, each row's bend angles spread over panels of their own scale."""
    values = lambda result: result[column]  # noqa: E731
    rows = [(seed, f"seed's {SEED[column]} as printed (seed fig. {number})"),
            (loaded, f"force balance, T_load = {LOADS[-1]:.0f} N.m")]
    panels = [len(by_scale({b: np.abs(values(r)).max() for b, r in results.items()})) for results, _ in rows]
    fig = blank(figsize=(4.2 * max(panels), 8.4), layout="constrained")
    for subfigure, count, (results, title) in zip(fig.subfigures(len(rows), 1), panels, rows):
        # each row as many panels as its scales need, spread over the whole width: no empty panel
        _panels_by_scale(subfigure.subplots(1, count, squeeze=False)[0], results, values, f"{symbol} [N]", title)
    fig.suptitle(f"{symbol}: 2000 rpm, r = 26 mm, l = 700 mm, m = 0.2 kg, exact kinematics; one scale per panel",
                 fontsize=10)
    _beta_legend(fig, BETAS_DEG, "outside lower center")
    return fig


def turn_figure(runs: dict[tuple[float, float], np.ndarray]) -> Figure:
    """Every bearing reaction over one turn for three bend angles, one panel per load (the
    unloaded reactions are a few hundredths of the loaded ones)."""
    fig, axes = figure(4, 4, figsize=(16, 12), sharex=True)
    for k, column in enumerate(REACTIONS):
        for j, load in enumerate(LOADS):
            ax = axes[k // 2, 2 * (k % 2) + j]
            _beta_curves(ax, {beta: runs[beta, load] for beta in TURN_BETAS}, lambda r: r[column], TURN_BETAS)
            unit = "N.m" if column in ("Mx_in", "My_in", "T_in") else "N"
            _angle_axis(ax, f"{column} [{unit}]", f"{column}, T_load = {load:.0f} N.m")
            if k < len(REACTIONS) - 2:
                ax.set_xlabel("")
    _beta_legend(fig, TURN_BETAS)
    fig.suptitle("Bearing reactions over one turn (force balance, exact kinematics), 2000 rpm, "
                 "r = 26 mm, l = 700 mm, m = 0.2 kg", fontsize=11)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    return fig


def beta_figure(runs: dict[tuple[float, float], np.ndarray], seed: dict[float, np.ndarray]) -> Figure:
    """Mean input-bearing forces and the 3rd-order amplitudes against beta, force balance beside the
    seed. Values that coincide are drawn as a ring around a dot, so that both are seen."""
    fig = figure(figsize=(15, 9))[0]
    fig.clear()
    grid = fig.add_gridspec(2, 6)
    ry, rx = fig.add_subplot(grid[0, :3]), fig.add_subplot(grid[0, 3:])
    amplitudes = [fig.add_subplot(grid[1, 2 * k:2 * k + 2]) for k in range(3)]
    betas = np.array(BETAS_DEG, dtype=float)
    line = np.linspace(0.0, 45.0, 91)
    ry.plot(line, -LOADS[-1] * np.tan(np.radians(line) / 2) / 0.7, "k-", lw=0.8,
            label=f"-T tan(beta/2) / l, T = {LOADS[-1]:.0f} N.m")
    ry.plot(betas, [runs[beta, LOADS[-1]]["Ry_in"].mean() for beta in BETAS_DEG], "o", color=BLUE,
            label=f"force balance, T = {LOADS[-1]:.0f} N.m")
    ry.plot(betas, [runs[beta, 0.0]["Ry_in"].mean() for beta in BETAS_DEG], "s", ms=5, color=BLUE,
            label="force balance, T = 0 N.m")
    ry.plot(betas, [seed[beta]["Ry_in"].mean() for beta in BETAS_DEG], "o", ms=12, mfc="none", mec="0.3", mew=1.5,
            label="seed's eq 34: mean 0 at every load")
    ry.set_title("Mean Ry_in: the force balance carries the load, the seed's eq 34 does not")
    rx.plot(betas, [runs[beta, 0.0]["Rx_in"].mean() for beta in BETAS_DEG], "s", ms=11, mfc="none",
            color=GREEN, label="force balance, T = 0 N.m")
    rx.plot(betas, [runs[beta, LOADS[-1]]["Rx_in"].mean() for beta in BETAS_DEG], "o-", ms=5, color=GREEN,
            label=f"force balance, T = {LOADS[-1]:.0f} N.m")
    rx.plot(betas[[0, -1]], (0.0, 0.0), ":", color="0.3", label="seed's eq 33: mean 0 at every load")
    rx.set_title("Mean Rx_in: the same at both loads")
    for ax in (ry, rx):
        ax.set_ylabel("mean force [N]")
    for ax, column, color in zip(amplitudes, ("Rx_in", "Ry_in", "Rz_out"), (GREEN, BLUE, VERMILLION)):
        for load, marker in zip(LOADS, ("s", "o")):
            amplitude = [order_amplitude(runs[beta, load][column]) for beta in BETAS_DEG]
            ax.semilogy(betas, amplitude, marker + "-", color=color, label=f"force balance, T = {load:.0f} N.m")
        order = 6 if column == "Ry_in" else 3  # eq 34 has no 3rd order
        seed_values = [order_amplitude(seed[beta][column], order) for beta in BETAS_DEG]
        ax.semilogy(betas, seed_values, "--", color="0.3",
                    label=f"seed's {SEED[column]}" + (" (its 6th order)" if order == 6 else ""))
        ax.set_title(f"{column}: 3rd-order amplitude")
        ax.set_ylabel("amplitude [N]")
    for ax in (ry, rx, *amplitudes):
        ax.set_xlabel("bend angle beta [deg]")
        ax.grid(True, alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.suptitle("Force balance against the seed, 2000 rpm, r = 26 mm, l = 700 mm, m = 0.2 kg", fontsize=10)
    fig.tight_layout()
    return fig


def peak_deviation_figure(loaded: dict[float, np.ndarray]) -> Figure:
    """Seed fig. 6: the peak deviation against beta, exact (lines, and the FMU's), eq 18 as marks
    on the lines; below, eq 18's relative error, too small to see above."""
    fig, (top, bottom) = figure(2, 1, figsize=(7, 7), sharex=True, gridspec_kw={"height_ratios": (3, 2)})
    beta_grid = np.radians(np.linspace(1.0, 45.0, 89))
    marks = np.radians((32.5, 37.5, 42.5))  # where the three ratios' curves lie apart, between the FMU's
    phi = np.linspace(0.0, 2 * math.pi / 3, 241)
    for ratio in (0.02, 26 / 700, 0.06):
        r, l = 0.026, 0.026 / ratio
        peak_exact = np.array([np.abs(exact_pose(phi, b, r, l).phi_out - phi).max() for b in beta_grid])
        line, = top.plot(np.degrees(beta_grid), peak_exact / ARCMIN, label=f"exact, r/l = {ratio:.3f}")
        top.plot(np.degrees(marks), closed_form.deviation_amplitude(marks, r, l) / ARCMIN, "x", ms=7,
                 color=line.get_color(), label=f"eq 18, r/l = {ratio:.3f}")
        error = np.abs(closed_form.deviation_amplitude(beta_grid, r, l) - peak_exact) / peak_exact
        bottom.semilogy(np.degrees(beta_grid), error, color=line.get_color(), label=f"r/l = {ratio:.3f}")
    fmu_peaks = [np.abs(result["delta_phi"]).max() / ARCMIN for result in loaded.values()]
    top.plot(BETAS_DEG, fmu_peaks, "ko", ms=5, label="FMU (exact), r/l = 0.037")
    top.set_ylabel("peak |phi_out - phi_in| [arcmin]")
    top.set_title("Peak angle deviation vs bend angle (seed fig. 6)")
    bottom.set_ylabel("|eq 18 - exact| / exact")
    bottom.set_title("eq 18 against the exact kinematics (the same to 0.1 % above)", fontsize=9)
    bottom.set_xlabel("bend angle beta [deg]")
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def friction_turn_figure(friction: dict[tuple[float, float, float], np.ndarray]) -> Figure:
    """Generated axial force over one turn for several mu and beta at 500 N.m."""
    fig, ax = figure(figsize=(8, 5.4))
    for beta in TURN_BETAS:
        for mu, style in zip(FRICTION, (":", "--", "-")):
            result = friction[beta, 500.0, mu]
            ax.plot(np.degrees(result["phi_in"]), -result["Rz_in"], style, color=BETA_COLOURS[beta],
                    label=f"beta = {beta} deg, mu = {mu}")
    _angle_axis(ax, "generated axial force -Rz_in [N]",
                "Generated axial force on the input housing, T_load = 500 N.m, 2000 rpm")
    ax.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    fig.tight_layout()
    return fig


def friction_beta_figure(friction: dict[tuple[float, float, float], np.ndarray]) -> Figure:
    """The axial force's 3rd-order amplitude and the mean efficiency against beta at two loads."""
    fig, (left, right) = figure(1, 2, figsize=(12, 4.6))
    for load, marker in zip(FRICTION_LOADS, ("s", "o")):
        turns = [friction[beta, load, FRICTION_MU] for beta in FRICTION_BETAS]
        left.plot(FRICTION_BETAS, [order_amplitude(-result["Rz_in"]) for result in turns], marker + "-",
                  label=f"T_load = {load:.0f} N.m")
        efficiency = [np.mean(load * r["omega_spin"]) / np.mean(load * r["omega_spin"] + r["P_friction"]) for r in turns]
        # The efficiencies at the two loads differ by less than 2e-4: a ring around each dot.
        ring = load == FRICTION_LOADS[0]
        style = {"marker": "o", "ms": 11, "mfc": "none", "ls": "none"} if ring else {"marker": "o"}
        right.plot(FRICTION_BETAS, efficiency, color=f"C{FRICTION_LOADS.index(load)}",
                   label=f"T_load = {load:.0f} N.m" + (" (ring)" if ring else " (dot)"), **style)
    left.set_ylabel("3rd-order amplitude of -Rz_in [N]")
    left.set_title("Generated axial force", fontsize=9)
    right.set_ylabel("mean efficiency [-]")
    right.set_title("Mean efficiency: the same at both loads to 2e-4", fontsize=9)
    for ax in (left, right):
        ax.set_xlabel("bend angle beta [deg]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"Friction mu = {FRICTION_MU} in both sliding pairs, 2000 rpm, r = 26 mm, l = 700 mm, m = 0.2 kg",
                 fontsize=10)
    fig.tight_layout()
    return fig


def joints_figure(joints: dict[tuple[int, float, float], np.ndarray]) -> Figure:
    """The generated axial force's 3rd-order amplitude of the plain tripod and the two roller tripods against
    the bend angle at 300 N.m and against the load at 12 deg, one curve per joint (more loads or angles in one
    panel would put the plain tripod's curves on the single roller's)."""
    fig, (left, right) = figure(1, 2, figsize=(13, 5.2))
    for joint, name in JOINTS.items():
        colour = f"C{joint}"
        amplitude = [order_amplitude(-joints[joint, beta, JOINTS_LOAD]["Rz_in"]) for beta in ROLLER_BETAS]
        left.semilogy(ROLLER_BETAS, amplitude, "o-", color=colour, label=name)
        amplitude = [order_amplitude(-joints[joint, JOINTS_BETA, load]["Rz_in"]) for load in ROLLER_LOADS]
        right.semilogy(ROLLER_LOADS, amplitude, "s-", color=colour, label=name)
    left.set_xlabel("bend angle beta [deg]")
    left.set_title(f"against the bend angle, T_load = {JOINTS_LOAD:.0f} N.m", fontsize=9)
    right.set_xlabel("load torque T_load [N.m]")
    right.set_title(f"against the load, beta = {JOINTS_BETA} deg", fontsize=9)
    for ax in (left, right):
        ax.set_ylabel("3rd-order amplitude of -Rz_in [N]")
        ax.grid(True, alpha=0.3, which="both")
    left.legend(fontsize=8)  # one legend: the joints' colours are the same in both panels
    fig.suptitle(f"Generated axial force of the three joints (tripod_type 0, 1, 2): mu = {FRICTION_MU}, default "
                 "mu_roll, 2000 rpm, r = 26 mm, l = 700 mm, m = 0.2 kg", fontsize=10)
    fig.tight_layout()
    return fig
