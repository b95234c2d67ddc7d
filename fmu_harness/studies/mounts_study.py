"""Main-job study of the PowertrainMounts FMU: the modal table of its default layout
(``powertrain_modes.csv``) and the kinetic-energy decoupling table as a figure for a report
(``powertrain_decoupling.png``), both read from the FMU's outputs at initialisation."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from driveline.mounts.rigid_body import COORDINATES  # noqa: E402
from driveline.mounts.spec import AXES, SPEC  # noqa: E402

from ..runs.runner import FmuInstance  # noqa: E402
from ..runs.result_table import column, write_csv  # noqa: E402

MODES = range(1, 7)
SHARES = tuple(f"share_{j}_{name}" for j in MODES for name in COORDINATES)
FREQUENCIES = tuple(f"f_mode_{j}" for j in MODES)
AXIS = tuple(f"torque_roll_axis_{axis}" for axis in AXES)


def modal_table(fmu: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frequencies [Hz] (6), shares (6 x 6, a row per mode) and torque roll axis (3) of the FMU's
    start values, as it outputs them after initialisation."""
    with FmuInstance(fmu) as instance:
        instance.initialize()
        values = instance.get(FREQUENCIES + SHARES + AXIS)
    return np.array(values[:6]), np.array(values[6:42]).reshape(6, 6), np.array(values[42:])


def figure(frequencies: np.ndarray, shares: np.ndarray, axis: np.ndarray, path: Path) -> Path:
    """The decoupling table as a shaded grid, each cell's share in per cent."""
    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    ax.imshow(np.clip(shares, 0.0, 1.0), cmap="Blues", vmin=0.0, vmax=1.0)
    for j in range(6):
        for k in range(6):
            ax.text(k, j, f"{100.0 * shares[j, k]:.1f}", ha="center", va="center",
                    color="white" if shares[j, k] > 0.6 else "black", fontsize=9)
    ax.set_xticks(range(6), COORDINATES)
    ax.set_yticks(range(6), [f"mode {j + 1}: {f:.2f} Hz" for j, f in enumerate(frequencies)])
    ax.set_xlabel("coordinate (vehicle axes, ISO 8855)")
    ax.set_title("Kinetic-energy decoupling of the powertrain's rigid-body modes [%]\n"
                 f"default layout; torque roll axis ({axis[0]:.3f}, {axis[1]:.3f}, {axis[2]:.3f})", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path


def write(fmu: Path, out: Path) -> list[Path]:
    """``powertrain_modes.csv`` (a row per mode: frequency, dominant coordinate and share, the six
    shares) and ``powertrain_decoupling.png`` into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    frequencies, shares, axis = modal_table(fmu)
    header = ["mode [1]", column(SPEC, "f_mode_1").replace("f_mode_1", "f_mode"), "dominant",
              "dominant_share [1]", *(f"share_{name} [1]" for name in COORDINATES)]
    rows = [(j + 1, float(frequencies[j]), COORDINATES[int(np.argmax(shares[j]))], float(np.max(shares[j])),
             *(float(v) for v in shares[j])) for j in range(6)]
    return [write_csv(out / "powertrain_modes.csv", header, rows),
            figure(frequencies, shares, axis, out / "powertrain_decoupling.png")]
