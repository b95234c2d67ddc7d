"""Main-job study of the CriticalSpeeds FMU: a speed ramp past its third critical speed, a table of
the critical speeds, and the Campbell diagram with the order lines and every crossing marked.

The FMU outputs the first two forward and backward whirl frequencies; the diagram adds the third
mode's from the rotor core (``driveline.rotor``, the FMU's reference), so that every critical speed
it names lies on a drawn branch.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from driveline.rotor.campbell import whirl_branches
from driveline.rotor.model import SHAFT_PARAMETERS, build_driveline
from driveline.rotor.spec import SPEC

from ..runs.runner import FmuInstance
from .figures import BLUE, ORANGE, VERMILLION, clear_of_lines, figure, save
from ..runs.result_table import column, write_csv

RPM = 30.0 / math.pi
ORDERS = (1, 2, 3)  # unbalance; Cardan joints; the tripod coupling (docs/tripod_coupling.md)
CRITICALS = ("omega_crit_1", "omega_crit_2", "omega_crit_3")
MODES = 2  # whirl pairs the FMU outputs
BEYOND = 1.1  # the ramp ends this far beyond the highest critical speed
STEPS = 300
#: Relative detunings sampled on both sides of each critical speed besides the ramp's equal steps:
#: the unbalance response's peak at the first critical is 0.4 % wide at half its height.
DETUNINGS = np.geomspace(1e-5, 0.03, 30)
SENSES = {"forward": (BLUE, "-", "o"), "backward": (ORANGE, "--", "s")}  # colour, line, marker
#: Crossing marks, nested where they meet: a backward crossing's filled square on top, inside a
#: forward crossing's ring or a critical speed's larger red ring (the backward 1x crossings lie
#: within 3 % of the critical speeds).
MARKS = {"critical": {"marker": "o", "ms": 12, "mfc": "none", "mec": VERMILLION, "mew": 2.0, "zorder": 5},
         "forward": {"marker": "o", "ms": 8, "mfc": "none", "mec": BLUE, "mew": 1.4, "zorder": 6},
         "backward": {"marker": "s", "ms": 5, "mfc": ORANGE, "mec": ORANGE, "zorder": 7}}


def critical_speeds(fmu: Path) -> tuple[float, ...]:
    """The FMU's critical speeds [rad/s] at its start values."""
    with FmuInstance(fmu) as instance:
        instance.initialize()
        return tuple(instance.get(CRITICALS))


def ramp_speeds(omega_max: float, criticals: tuple[float, ...], steps: int = STEPS) -> np.ndarray:
    """The ramp's speeds: ``steps`` equal steps from 0 to ``omega_max``, and around each critical
    speed the speeds ``omega_crit (1 +- DETUNINGS)`` and the critical speed itself, closer the
    nearer they lie, so that a resonance peak is recorded at its height."""
    near = np.concatenate([c * (1.0 + np.concatenate([-DETUNINGS, [0.0], DETUNINGS])) for c in criticals])
    return np.unique(np.concatenate([np.linspace(0.0, omega_max, steps + 1), near[(near > 0) & (near < omega_max)]]))


def ramp(fmu: Path, speeds: np.ndarray, seconds: float = 1.0) -> np.ndarray:
    """The FMU on a speed ramp through ``speeds`` (rising from 0) at a constant rate, reaching the
    last over ``seconds``: each step's input is the ramp's value at the step's end, so each row's
    outputs belong to its own time and speed."""
    names = [v.name for v in SPEC.of("output")]
    times = seconds * speeds / speeds[-1]
    with FmuInstance(fmu) as instance:
        instance.initialize({"omega_in_max": float(speeds[-1]), "omega_in": float(speeds[0])})
        read, write = instance.reader(names), instance.writer(["omega_in"])
        rows = [(times[0], speeds[0], *read())]
        for k in range(1, len(speeds)):
            write([speeds[k]])
            instance.step(times[k] - times[k - 1])
            rows.append((times[k], speeds[k], *read()))
    return np.array(rows, dtype=[(n, float) for n in ("time", "omega_in", *names)])


def crossings(spins: np.ndarray, whirl: np.ndarray, order: int) -> list[float]:
    """Speeds [rad/s] where ``order * spin`` meets the branch ``whirl(spins)`` (linear between samples)."""
    gap = order * spins - whirl
    found = [float(spins[i]) for i in np.flatnonzero(gap[1:] == 0.0) + 1]  # a sample on the branch (the ramp
    for i in np.flatnonzero(np.sign(gap[:-1]) * np.sign(gap[1:]) < 0):  # samples each critical speed)
        fraction = gap[i] / (gap[i] - gap[i + 1])
        found.append(float(spins[i] + fraction * (spins[i + 1] - spins[i])))
    return sorted(found)


def branches(result: np.ndarray) -> dict[tuple[str, int], np.ndarray]:
    """Whirl branches [rad/s] over the ramp's speeds by (sense, mode): modes 1-2 from the FMU,
    mode 3 from the rotor core at the FMU's start values."""
    found = {(sense, mode): result[f"whirl_{sense}_{mode}"] for sense in SENSES for mode in range(1, MODES + 1)}
    shaft = {name: SPEC[name].start for name in SHAFT_PARAMETERS}
    core = whirl_branches(build_driveline("", shaft), result["omega_in"], MODES + 1)
    found["forward", MODES + 1] = core.forward[:, MODES]
    found["backward", MODES + 1] = core.backward[:, MODES]
    return found


def write(fmu: Path, out: Path) -> list[Path]:
    """Run the study, write the two CSV files and the figure into ``out``; return the files written."""
    out.mkdir(parents=True, exist_ok=True)
    criticals = critical_speeds(fmu)
    result = ramp(fmu, ramp_speeds(BEYOND * max(criticals), criticals))
    table = write_csv(out / "critical_speeds.csv",
                      ("mode [1]", "critical speed [rad/s]", "critical speed [rpm]"),
                      ((k, float(f"{w:.6g}"), float(f"{w * RPM:.6g}")) for k, w in enumerate(criticals, start=1)))
    names = result.dtype.names
    ramp_csv = write_csv(out / "critical_speeds_ramp.csv", ("time [s]", *(column(SPEC, n) for n in names[1:])),
                         result.tolist())
    diagram = save(campbell_figure(result, branches(result), criticals), out / "campbell_diagram.png")
    return [table, ramp_csv, diagram]


def campbell_figure(result: np.ndarray, whirl: dict[tuple[str, int], np.ndarray],
                    criticals: tuple[float, ...]) -> Figure:
    """Whirl branches against shaft speed, the order lines labelled inside the axes, every crossing
    marked with its speed; the 1x forward crossings (the critical speeds) in red."""
    spins = result["omega_in"]
    x_top = spins[-1] * RPM
    y_top = 1.08 * max(np.nanmax(values) for values in whirl.values()) * RPM
    fig, ax = figure(figsize=(9, 7))
    for (sense, mode), values in whirl.items():
        color, style, _ = SENSES[sense]
        from_fmu = mode <= MODES
        label = {1: f"{sense} whirl, modes 1-{MODES} (FMU)", MODES + 1: f"{sense} whirl, mode {mode} (rotor core)"}
        ax.plot(spins * RPM, values * RPM, style, color=color, lw=1.6 if from_fmu else 1.1,
                alpha=1.0 if from_fmu else 0.75, label=label.get(mode, f"_{sense} whirl, mode {mode}"))
    labels = []
    for (sense, mode), values in whirl.items():
        color = SENSES[sense][0]
        for order in ORDERS:
            for speed in crossings(spins, values, order):
                critical = order == 1 and sense == "forward"
                ax.plot(speed * RPM, order * speed * RPM, ls="none", **MARKS["critical" if critical else sense],
                        label=f"_{'critical speed' if critical else sense} {order}x, mode {mode}")  # not in the legend
                labels.append((ax.annotate(f"{speed * RPM:.0f}", (speed * RPM, order * speed * RPM),
                                           xytext=(0, 0), textcoords="offset points", ha="center", va="center",
                                           fontsize=7.5, color=VERMILLION if critical else color,
                                           fontweight="bold" if critical else "normal"), sense))
    for mark, label in (("critical", "critical speed (1x, forward) [rpm]"), ("forward", "order resonance, forward [rpm]"),
                        ("backward", "order resonance, backward [rpm]")):
        ax.plot([], [], ls="none", **MARKS[mark], label=label)
    ax.set_xlim(0, x_top)
    ax.set_ylim(0, y_top)
    ax.set_xlabel("shaft speed [rpm]")
    ax.set_ylabel("whirl frequency [rpm]")
    ax.set_title("Campbell diagram, one-piece propshaft (CriticalSpeeds FMU)\n"
                 "critical speeds " + ", ".join(f"{w * RPM:.0f}" for w in criticals) + " rpm")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize=8, framealpha=0.95)
    fig.tight_layout()
    for order in ORDERS:  # after the layout: the labels' angles follow the lines on the page
        end = min(x_top, y_top / order)
        ax.plot([0.0, end], [0.0, order * end], color="0.35", lw=0.9, ls="-" if order == 1 else (0, (1, 1.5)))
        at = np.array([0.55 * y_top / order, 0.55 * y_top])  # between the first two modes' branches
        angle = ax.transData.transform_angles(np.array([math.degrees(math.atan(order))]), at[None, :])[0]
        ax.annotate(f"{order}x", at, xytext=(-4, 4), textcoords="offset points", fontsize=10, color="0.2",
                    ha="right", va="bottom", rotation=angle, rotation_mode="anchor")
    fig.canvas.draw()
    for label, sense in labels:  # each crossing's speed beside its mark, where no line crosses it
        below, above = (-1, 1) if sense == "forward" else (1, -1)  # forward speeds first below, backward above
        clear_of_lines(ax, label, [{"xyann": (x, y)} for y in (12 * below, 12 * above, 22 * below, 22 * above)
                                   for x in (24, -24, 40, -40)])
    return fig
