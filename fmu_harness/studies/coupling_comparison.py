"""Side-by-side comparison of the coupling FMUs, and the two-joint Cardan shaft.

* :func:`speed_fluctuation_table` runs TripodCoupling (plain, single and double roller), CardanJoint
  and UniversalReducer at the same input speed over a sweep of bend angles and measures the output-speed fluctuation
  (peak-to-peak / mean over one input turn) and its dominant order.
* :func:`cardan_shaft` co-simulates two CardanJoint instances in one process, the first one's
  output speed feeding the second one's input, to show phasing cancel or double the fluctuation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..runs.runner import FmuInstance, simulate
from .figures import figure, save
from ..runs.result_table import write_csv

SPEED = 1500.0 * math.pi / 30.0  # rad/s
SAMPLES_PER_TURN = 360
NO_ORDER_BELOW = 1e-9  # relative fluctuation under which no order is named


@dataclass(frozen=True)
class Coupling:
    """How one coupling FMU takes the bend angle."""

    name: str
    angle_input: str
    to_input: float  # offset: input = offset + sign * beta
    sign: float
    parameters: dict[str, float]
    fmu: str = ""  # the FMU's model name, when not the name


TRIPOD = {"kinematics": 1, "beta_max": math.radians(60.0)}
COUPLINGS = (
    Coupling("TripodCoupling", "beta", 0.0, 1.0, TRIPOD),
    # The roller tripods (tripod_type 1, 2) with friction: the plain tripod's closure, so its output speed
    Coupling("TripodCoupling single roller", "beta", 0.0, 1.0, {**TRIPOD, "tripod_type": 1, "mu": 0.05},
             "TripodCoupling"),
    Coupling("TripodCoupling double roller", "beta", 0.0, 1.0, {**TRIPOD, "tripod_type": 2, "mu": 0.05},
             "TripodCoupling"),
    Coupling("CardanJoint", "beta", 0.0, 1.0, {"beta_max": math.radians(80.0)}),
    # The reducer's intersection angle is 180 deg for in-line shafts.
    Coupling("UniversalReducer", "intersection_angle", math.pi, -1.0,
             {"intersection_angle_min": math.radians(10.0), "intersection_angle_max": math.radians(179.0)}),
)


def fluctuation_and_order(omega_out: np.ndarray) -> tuple[float, int | None]:
    """(max - min) / mean of a speed sampled uniformly over one input turn, and its dominant order
    (None under :data:`NO_ORDER_BELOW`, written 0 in the CSV file: a constant speed)."""
    mean = float(np.mean(omega_out))
    fluctuation = float((omega_out.max() - omega_out.min()) / mean)
    if fluctuation < NO_ORDER_BELOW:
        return fluctuation, None
    spectrum = np.abs(np.fft.rfft(omega_out - mean))
    return fluctuation, int(np.argmax(spectrum))


def one_turn(models: Path, coupling: Coupling, beta: float) -> np.ndarray:
    period = 2 * math.pi / SPEED
    result = simulate(
        models / f"{coupling.fmu or coupling.name}.fmu", period, period / SAMPLES_PER_TURN,
        inputs={"omega_in": SPEED, coupling.angle_input: coupling.to_input + coupling.sign * beta},
        start_values=coupling.parameters, outputs=["omega_out"],
    )
    return result["omega_out"][:-1]


def speed_fluctuation_table(models: Path, betas_deg: list[float]) -> list[dict[str, object]]:
    rows = []
    for beta_deg in betas_deg:
        for coupling in COUPLINGS:
            fluctuation, order = fluctuation_and_order(one_turn(models, coupling, math.radians(beta_deg)))
            rows.append({"coupling": coupling.name, "beta_deg": beta_deg, "fluctuation": fluctuation, "order": order})
    return rows


def write(models: Path, out: Path, betas_deg: list[float] | None = None) -> list[Path]:
    """Write the comparison table (CSV and markdown) and its plot; return the files."""
    betas_deg = betas_deg or [5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0]
    rows = speed_fluctuation_table(models, betas_deg)
    out.mkdir(parents=True, exist_ok=True)
    table = write_csv(out / "coupling_comparison.csv", ("beta [deg]", "coupling", "fluctuation [1]", "order [1]"),
                      ((r["beta_deg"], r["coupling"], r["fluctuation"], r["order"] or 0) for r in rows))
    markdown = out / "coupling_comparison.md"
    lines = ["| beta [deg] | " + " | ".join(c.name for c in COUPLINGS) + " |", "|---" * (len(COUPLINGS) + 1) + "|"]
    for beta_deg in betas_deg:
        cells = [
            f"{row['fluctuation']:.3e} ({'order ' + str(row['order']) if row['order'] else 'none'})"
            for row in rows if row["beta_deg"] == beta_deg
        ]
        lines.append(f"| {beta_deg:g} | " + " | ".join(cells) + " |")
    markdown.write_text("Output-speed fluctuation (max - min) / mean over one input turn, dominant order:\n\n" + "\n".join(lines) + "\n")
    return [table, markdown, save(comparison_figure(rows, betas_deg), out / "coupling_comparison.png")]


def comparison_figure(rows: list[dict[str, object]], betas_deg: list[float]) -> Figure:
    """The fluctuation against beta on a log scale; a coupling whose fluctuation stays under
    NO_ORDER_BELOW (the reducer's constant ratio gives 0) is named in the axes instead, at its
    largest value: a log scale has no 0; one with another's values (the roller tripods, on the
    plain tripod's closure) is named in that one's label, ``TripodCoupling = ...``, not drawn over it."""
    fig, ax = figure(figsize=(7, 4))
    drawn = []
    for k, coupling in enumerate(COUPLINGS):
        values = [row["fluctuation"] for row in rows if row["coupling"] == coupling.name]
        twin = next((line for line, seen in drawn if seen == values), None)
        if twin is not None:
            twin.set_label(f"{twin.get_label()} = {coupling.name}")
        elif max(values) >= NO_ORDER_BELOW:
            drawn.append((ax.semilogy(betas_deg, values, "o-", color=f"C{k}", label=coupling.name)[0], values))
        else:
            ax.text(0.98, 0.04 + 0.07 * len(ax.texts), f"{coupling.name}: {max(values):.2g} at every bend angle (constant speed "
                    "ratio), no point on a log scale", transform=ax.transAxes, ha="right", va="bottom", fontsize=8)
    ax.set_xlabel("bend angle beta [deg]")
    ax.set_ylabel("output-speed fluctuation (max - min) / mean")
    ax.set_title(f"Coupling comparison at {SPEED * 30 / math.pi:.0f} rpm")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig


def cardan_shaft(models: Path, beta: float, second_phase: float, step_size: float, turns: float = 1.0) -> np.ndarray:
    """Two CardanJoint instances in series (Gauss-Seidel: the first joint's output speed after
    each step is the second joint's input for the next step). Returns time, the input speed, the
    intermediate speed and the output speed."""
    path = models / "CardanJoint.fmu"
    with FmuInstance(path, "joint1") as first, FmuInstance(path, "joint2") as second:
        first.initialize({"omega_in": SPEED, "beta": beta, "phase": 0.0})
        second.initialize({"omega_in": first.get(["omega_out"])[0], "beta": beta, "phase": second_phase})
        rows = [(0.0, SPEED, *first.get(["omega_out"]), *second.get(["omega_out"]))]
        for _ in range(int(round(turns * 2 * math.pi / SPEED / step_size))):
            first.step(step_size)
            second.step(step_size)
            middle = first.get(["omega_out"])[0]
            second.set({"omega_in": middle})
            rows.append((first.time, SPEED, middle, *second.get(["omega_out"])))
    return np.array(rows, dtype=[("time", float), ("omega_in", float), ("omega_mid", float), ("omega_out", float)])
