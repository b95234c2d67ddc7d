"""Main-job study of the CriticalSpeeds FMU: a speed ramp, the Campbell diagram, a table of critical speeds."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .runner import simulate  # noqa: E402

RPM = 30.0 / math.pi
ORDERS = (2, 3)  # Cardan joints; the tripod coupling excites the 3rd (docs/tripod_coupling.md)
WHIRL = ("whirl_forward_1", "whirl_forward_2", "whirl_backward_1", "whirl_backward_2")


def ramp(fmu: Path, omega_max: float = 1500.0, seconds: float = 1.0, steps: int = 300) -> np.ndarray:
    """The FMU on a speed ramp from 0 to ``omega_max``."""
    return simulate(fmu, seconds, seconds / steps, inputs={"omega": lambda t: omega_max * t / seconds},
                    start_values={"omega_max": omega_max})


def write(fmu: Path, out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    result = ramp(fmu)
    speed = result["time"][1:] * 1500.0 - 1500.0 / 300  # input held over each step
    speed = np.concatenate([[0.0], speed])
    criticals = [result[f"omega_crit_{k}"][-1] for k in (1, 2, 3)]
    table = out / "critical_speeds.csv"
    with table.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(("mode", "critical speed [rad/s]", "critical speed [rpm]"))
        writer.writerows((k, f"{w:.6g}", f"{w * RPM:.6g}") for k, w in enumerate(criticals, start=1))
    ramp_csv = out / "critical_speeds_ramp.csv"
    with ramp_csv.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(("omega",) + result.dtype.names[1:])
        writer.writerows(zip(speed, *(result[name] for name in result.dtype.names[1:])))

    fig, ax = plt.subplots(figsize=(7, 5))
    styles = {"whirl_forward": ("tab:blue", "forward whirl"), "whirl_backward": ("tab:orange", "backward whirl")}
    for name in WHIRL:
        color, label = styles[name.rsplit("_", 1)[0]]
        ax.plot(speed * RPM, result[name] * RPM, color=color, label=label if name.endswith("_1") else None)
    top = max(result[name].max() for name in WHIRL) * RPM * 1.05
    for order in (1, *ORDERS):
        ax.plot([0, top / order], [0, top], "k-" if order == 1 else "k:", lw=0.8)
        ax.annotate(f"{order}x", (min(top / order, speed[-1] * RPM), min(top, order * speed[-1] * RPM)), fontsize=8)
    for k, w in enumerate(criticals, start=1):
        if w <= speed[-1]:
            ax.plot(w * RPM, w * RPM, "rv", label="critical speed" if k == 1 else None)
    ax.set_xlim(0, speed[-1] * RPM)
    ax.set_ylim(0, top)
    ax.set_xlabel("shaft speed [rpm]")
    ax.set_ylabel("whirl frequency [rpm]")
    ax.set_title("Campbell diagram, one-piece propshaft (CriticalSpeeds FMU)\n"
                 "critical speeds " + ", ".join(f"{w * RPM:.0f}" for w in criticals) + " rpm")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    figure = out / "campbell_diagram.png"
    fig.savefig(figure, dpi=120)
    plt.close(fig)
    return [table, ramp_csv, figure]
