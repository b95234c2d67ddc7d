"""Main-job study of launch shudder on the native ``VehicleLaunch.ssp``: a slow launch from standstill to
30 km/h, over which three times the halfshaft frequency sweeps through five of the powertrain's six
mount modes; the run (``vehicle_launch.csv``), the third-order peaks against the mode crossings
(``launch_shudder_peaks.csv``) and three figures.

The launch: the package's joints and mounts, the motor's torque ramped to ``TORQUE`` (a gentle
take-off: the shaft accelerates by about 0.7 rad/s2, so that each resonance is passed slowly enough
for its peak to stay near its crossing; docs/vehicle_launch.md, "Shudder"), the right joint started
``PHASE`` ahead of the left (in phase their third orders cancel on the lateral and yaw modes; a quarter
turn apart they are in quadrature, 270 deg, and no mode's forcing cancels), the joints' housings held at
their design position (``mounts.housing_motion`` 0: moving, the grooves' friction on the housing's own
speed damps the mount modes and takes their resonance peaks away, so no crossing is left to check; that
launch is docs/vehicle_launch.md's "The powertrain's motion in the joints"), run by the project's master
in Gauss-Seidel order at 0.8 ms, its stable limit, where a 40 s launch costs about 4 s of CPU.

The powertrain's response is split into its modes with the core's mass-normalised mode shapes of the
package's mounts (``driveline.mounts``: the default layout, on rubber, linearised about the weight's
equilibrium, its operating point at the package's ``T_mean`` 0): mode j's share of the accelerations at the
centre of gravity, ``phi_j phi_j^T M q''``, read in its dominant coordinate. Each mode's third order over the halfshaft
speed (:mod:`.order_tracking`) peaks near its crossing, later by the sweep: the single-mode reference
(:func:`swept_peak`) gives where a mode of that frequency and damping passed at the launch's own speed
history peaks.
"""

from __future__ import annotations

import math
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from scipy.signal import lsim

from driveline.catalog import MODELS
from driveline.mounts.model import PowertrainMountsModel
from driveline.mounts.rigid_body import COORDINATES, Modes, RigidBody
from driveline.mounts.spec import DEFAULT_LAYOUT
from driveline.vehicle.dynamics import GRAVITY

from ..runs import ssp_package
from ..runs.system import LAUNCH_ORDER, run_jacobi
from . import order_tracking
from .figures import BLUE, ORANGE, PALETTE, SKY, VERMILLION, YELLOW, clear_of_lines, figure, save
from ..runs.result_table import write_csv

TORQUE = 20.0  # motor torque after the ramp [N.m]
PHASE = math.radians(90.0)
"""The right joint's ``phi_in_start`` in the main job's launch [rad], the left's 0: the joints' third orders in
quadrature, so every mode is forced (docs/vehicle_launch.md, "The main job's launch")."""
CHANGES = {"joint_right": {"phi_in_start": PHASE}, "mounts": {"housing_motion": 0}}
"""The study's launch against the package's: the right joint at ``PHASE``, the housings held at their design
position (moving, the grooves' friction on the housing's speed damps the mount modes' peaks)."""
STOP_TIME = 40.0  # [s]
STEP = 8e-4  # Gauss-Seidel's longest stable step (docs/vehicle_launch.md) [s]
EVERY = 4  # the CSV file holds every 4th communication point (3.2 ms)
LAYOUT = DEFAULT_LAYOUT  # the package's mounts' layout: PowertrainMounts' default
KMH = 3.6
SHAFT = "joint_left.phi_out"  # the left halfshaft's angle, whose orders the study tracks
RESPONSE = "mounts.pitch_ddot"  # the spectrogram's signal: the coordinate that responds most
#: (component.variable, CSV name) of vehicle_launch.csv, after the time.
COLUMNS = (("drive.v_x", "v_x"), ("motor.T_motor", "T_motor"),
           ("drive.T_load_left", "T_load_left"), ("drive.T_load_right", "T_load_right"),
           ("drive.omega_in_left", "omega_in_left"), ("drive.omega_in_right", "omega_in_right"),
           ("joint_left.phi_out", "phi_out_left"), ("joint_right.phi_out", "phi_out_right"),
           ("joint_left.Rz_in", "Rz_in_left"), ("joint_right.Rz_in", "Rz_in_right"),
           *((f"mounts.{name}_ddot", f"{name}_ddot") for name in COORDINATES))
FREQUENCIES = tuple(f"mounts.f_mode_{j}" for j in range(1, 7))
WINDOW_MARGIN = 0.25  # a peak belongs to a crossing within this fraction of its speed (a fast sweep: 22 %)
SPECTRUM_TOP = 25.0  # the spectrogram's highest frequency [Hz]


@dataclass(frozen=True)
class Launch:
    """The run: times [s] and each output of :data:`COLUMNS` and :data:`FREQUENCIES` by its name."""

    time: np.ndarray
    values: dict[str, np.ndarray]

    @property
    def shaft_angle(self) -> np.ndarray:
        return self.values[SHAFT]

    @property
    def mode_frequencies(self) -> np.ndarray:
        """The FMU's natural frequencies [Hz] (constant over the run)."""
        return np.array([self.values[name][-1] for name in FREQUENCIES])

    def accelerations(self) -> np.ndarray:
        """The powertrain's accelerations at its centre of gravity (samples x 6, COORDINATES)."""
        return np.column_stack([self.values[f"mounts.{name}_ddot"] for name in COORDINATES])


def run(package: Path, torque: float = TORQUE, stop_time: float = STOP_TIME, step: float = STEP,
        changes: dict[str, dict[str, float]] | None = None) -> Launch:
    """The package's launch with the motor's torque ``torque`` and the parameters ``changes``
    ({component: {name: value}}), in the project's master in :data:`LAUNCH_ORDER`."""
    system = ssp_package.read(package)
    extra = {"motor": {"T_level": torque}} | (changes or {})
    parameters = {c.name: {**c.parameters, **extra.get(c.name, {})} for c in system.components}
    outputs = [name for name, _ in COLUMNS] + list(FREQUENCIES)
    with tempfile.TemporaryDirectory(prefix="driveline-launch-") as scratch:
        with zipfile.ZipFile(package) as archive:
            archive.extractall(scratch)
        fmus = {c.name: Path(scratch) / c.source for c in system.components}
        rows = run_jacobi(fmus, parameters, system.connections, stop_time, step, outputs, order=LAUNCH_ORDER,
                          initial=True)
    return Launch(rows[:, 0], {name: rows[:, k + 1] for k, name in enumerate(outputs)})


def powertrain_modes(layout: str = LAYOUT) -> tuple[RigidBody, Modes]:
    """The package's powertrain and its modes, as its ``PowertrainMounts`` outputs them: ``layout`` at the
    package's ``g``, linearised about the operating point of ``T_mean`` 0 (the branches' storage stiffness at
    each mode's frequency, the stops' tangent rates; ``damping_ratios``: equation (4) of
    docs/powertrain_mounts.md)."""
    model = PowertrainMountsModel()
    model.layout, model.g = layout, GRAVITY
    errors = model.initialize(0.0)
    if errors:
        raise ValueError(errors[0])
    system = model._system
    return system.body, system.operating_modes(system.static_sag(model.g, model.T_mean))


def modal_accelerations(body: RigidBody, found: Modes, accelerations: np.ndarray) -> np.ndarray:
    """Mode j's share of ``accelerations`` (samples x 6) in its dominant coordinate (samples x 6):
    ``phi_dj (phi_j^T M q'')``; the six shares of a coordinate sum to its acceleration."""
    participation = accelerations @ (body.mass @ found.shapes)
    return participation * found.shapes[found.dominant, np.arange(6)]


def crossing_speeds(frequencies: np.ndarray, order: int = order_tracking.SHUDDER_ORDER) -> np.ndarray:
    """Halfshaft speeds [rad/s] at which ``order`` times the shaft's frequency meets each frequency [Hz]."""
    return 2.0 * np.pi * np.asarray(frequencies) / order


def swept_peak(time: np.ndarray, shaft_angle: np.ndarray, frequency: float, damping: float) -> float:
    """Halfshaft speed [rad/s] at which the third order of the acceleration of one mode (natural
    ``frequency`` [Hz], damping ratio ``damping``) forced by ``cos 3 phi(t)`` over the launch's own
    angle history peaks: the crossing delayed by the sweep, the reference for the peaks."""
    omega = 2.0 * np.pi * frequency
    force = np.cos(order_tracking.SHUDDER_ORDER * shaft_angle)
    system = (np.array([[0.0, 1.0], [-omega**2, -2.0 * damping * omega]]), np.array([[0.0], [1.0]]),
              np.array([[-omega**2, -2.0 * damping * omega]]), np.array([[1.0]]))
    _, response, _ = lsim(system, force, time, interp=True)
    speeds, amplitude = order_tracking.order_track(time, shaft_angle, response, order_tracking.SHUDDER_ORDER)
    (found,) = order_tracking.peaks_near(speeds, amplitude, crossing_speeds([frequency]), WINDOW_MARGIN)
    return np.nan if found is None else found[1]


@dataclass(frozen=True)
class Peak:
    """One mode's crossing and its measured third-order peak (None if the launch does not reach it)."""

    mode: int
    frequency: float  # [Hz]
    coordinate: str
    damping: float
    crossing: float  # [rad/s]
    measured: tuple[float, float] | None  # (amplitude, speed [rad/s])
    swept: float  # the single-mode reference's peak speed [rad/s], nan without a peak

    @property
    def difference(self) -> float:
        """Measured peak speed against the crossing [%]."""
        return np.nan if self.measured is None else 100.0 * (self.measured[1] / self.crossing - 1.0)


def third_order_peaks(launch: Launch) -> tuple[list[Peak], np.ndarray, np.ndarray]:
    """Each mode's peak, the order tracking's speeds [rad/s] and each mode's third-order amplitude
    there (modes x speeds, the unit of its dominant coordinate's acceleration)."""
    body, found = powertrain_modes()
    damping = found.damping_ratios
    shares = modal_accelerations(body, found, launch.accelerations())
    tracks = [order_tracking.order_track(launch.time, launch.shaft_angle, shares[:, j], 3) for j in range(6)]
    speeds = tracks[0][0]
    amplitudes = np.array([amplitude for _, amplitude in tracks])
    frequencies = launch.mode_frequencies
    crossings = crossing_speeds(frequencies)
    peaks = []
    for j in range(6):
        reached = speeds.size > 0 and crossings[j] < speeds[-1]
        (measured,) = order_tracking.peaks_near(speeds, amplitudes[j], crossings[j:j + 1], WINDOW_MARGIN)
        swept = swept_peak(launch.time, launch.shaft_angle, frequencies[j], damping[j]) if reached else np.nan
        peaks.append(Peak(j + 1, float(frequencies[j]), COORDINATES[found.dominant[j]], float(damping[j]),
                          float(crossings[j]), measured if reached else None, swept))
    return peaks, speeds, amplitudes


PEAK_COLUMNS = ("mode [1]", "f_mode [Hz]", "dominant", "damping_ratio [1]", "crossing_speed [rad/s]", "crossing",
                "peak_speed [rad/s]", "difference [%]", "swept_peak_speed [rad/s]", "peak_amplitude [m/s2 or rad/s2]")
"""launch_shudder_peaks.csv: ``crossing`` says whether the launch reaches the mode's crossing; where it
does not, the peak's columns hold the launch's end (its last tracked speed and the amplitude there)."""


def peak_row(peak: Peak, end_speed: float, end_amplitude: float) -> tuple:
    """A row of :data:`PEAK_COLUMNS`: ``end_speed`` [rad/s] and ``end_amplitude``, the order tracking's last
    speed and the mode's amplitude there, stand for a peak the launch does not reach."""
    if peak.measured is not None:
        return (peak.mode, peak.frequency, peak.coordinate, peak.damping, peak.crossing, "reached",
                peak.measured[1], peak.difference, peak.swept, peak.measured[0])
    return (peak.mode, peak.frequency, peak.coordinate, peak.damping, peak.crossing,
            f"not reached: the launch ends at {end_speed:.1f} rad/s", end_speed,
            100.0 * (end_speed / peak.crossing - 1.0), end_speed, end_amplitude)


#: The sizes [pt] of the modes' peak rings on the orders figure's lower panel, each at least 2.5 pt (3.5 px) from
#: the others' and from the crossings' 10 pt (4.2 px at the figures' 120 dpi), so that rings that overlap nest
PEAK_RINGS = (20.5, 18.0, 15.5, 13.0, 6.5, 4.0)
TAKE_OFF = 2.0  # the torque panel's span [s]: the ramp and the halfshafts' wind-up, then the torques hold


def speed_torque_figure(launch: Launch) -> Figure:
    """Vehicle speed over the launch; both halfshaft torques over the take-off, where they change."""
    fig, (speed, torque) = figure(2, 1, figsize=(8, 6.4))
    speed.plot(launch.time, launch.values["drive.v_x"] * KMH, color=BLUE, label="vehicle speed")
    speed.set_ylabel("vehicle speed [km/h]")
    speed.set_xlabel("time [s]")
    speed.set_xlim(launch.time[0], launch.time[-1])
    speed.set_title(f"Launch, motor torque ramped to {TORQUE:g} N.m, right joint "
                    f"{math.degrees(PHASE):.0f} deg ahead: vehicle speed", fontsize=10)
    early = launch.time <= min(TAKE_OFF, launch.time[-1])
    for side, color, style in (("left", BLUE, "-"), ("right", ORANGE, "--")):
        torque.plot(launch.time[early], launch.values[f"drive.T_load_{side}"][early], style, color=color, lw=1.0,
                    label=f"{side} halfshaft")
    torque.set_xlim(launch.time[0], launch.time[early][-1])
    torque.set_title(f"Halfshaft torques over the first {launch.time[early][-1]:.3g} s (held after), each in its "
                     "joint's frame: the right one turns negatively", fontsize=9)
    torque.set_ylabel("T_load [N.m]")
    torque.set_xlabel("time [s]")
    torque.legend(loc="center right")
    for ax in (speed, torque):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def axial_force_figure(launch: Launch) -> Figure:
    """Both joints' generated axial force -Rz_in: its third-order amplitude over the halfshaft speed, and
    its shape over the launch's last turn."""
    fig, (orders, turn) = figure(2, 1, figsize=(8, 6.4))
    omega = order_tracking.shaft_speed(launch.time, launch.shaft_angle)
    top = 0.0
    for side, color, style in (("left", BLUE, "-"), ("right", ORANGE, "--")):
        force = -launch.values[f"joint_{side}.Rz_in"]
        speeds, amplitude = order_tracking.order_track(launch.time, launch.shaft_angle, force, 3)
        orders.plot(speeds, amplitude, style, color=color, lw=1.4, label=f"{side} joint")
        top = max(top, amplitude.max())
        angle = np.abs(launch.values[f"joint_{side}.phi_out"])
        last = angle >= angle[-1] - 2.0 * np.pi
        turn.plot(np.degrees(angle[last] - angle[last][0]), force[last], style, color=color, lw=1.2,
                  label=f"{side} joint")
    orders.set_xlim(speeds[0], speeds[-1])
    orders.set_ylim(0.0, 1.15 * top)
    orders.set_xlabel("left halfshaft speed [rad/s] (the right one turns as fast, negatively)")
    orders.set_ylabel("third-order amplitude [N]")
    orders.set_title("Generated axial force -Rz_in, third order (friction's sign follows the sliding: 4/pi of "
                     "its peak)", fontsize=9)
    turn.set_xlim(0.0, 360.0)
    turn.set_xlabel("shaft angle over the launch's last turn [deg]")
    turn.set_ylabel("-Rz_in [N]")
    turn.set_title(f"Its shape over the last turn, at {omega[-1]:.1f} rad/s", fontsize=9)
    orders.legend(loc="lower right", fontsize=8)  # one legend: both panels draw the joints alike
    for ax in (orders, turn):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def orders_figure(launch: Launch, peaks: list[Peak], speeds: np.ndarray, amplitudes: np.ndarray) -> Figure:
    """The powertrain's pitch acceleration as a spectrogram over the halfshaft speed with the 1st and
    3rd order lines, the mount modes and the crossings and peaks marked; below, each mode's share's
    third-order amplitude over the same speeds, scaled to its peak."""
    fig, (top, bottom) = figure(2, 1, figsize=(9, 9), sharex=True, height_ratios=(3, 2), layout="constrained")
    shaft, frequencies, spectrum = order_tracking.spectrogram(launch.time, launch.shaft_angle, launch.values[RESPONSE],
                                                              window=2.0, hop=0.2)
    shown = frequencies <= SPECTRUM_TOP
    mesh = top.pcolormesh(shaft, frequencies[shown], spectrum[shown], shading="nearest", cmap="magma")
    fig.colorbar(mesh, ax=(top, bottom), label="pitch acceleration amplitude [rad/s2] (spectrogram)", pad=0.01,
                 shrink=0.6, anchor=(0.0, 1.0))
    left, right = speeds[0], speeds[-1]
    line = np.array([left, right])
    for order, style in ((1, ":"), (3, "--")):
        top.plot(line, order * line / (2.0 * np.pi), style, color="white", lw=1.2, label=f"order {order}")
    top.set_facecolor("black")  # where no window is centred, as where the spectrum is 0
    top.set_ylabel("frequency [Hz]")
    top.set_title("Powertrain pitch acceleration at its centre of gravity over the halfshaft speed:\n"
                  "orders 1 and 3, mount modes, their crossings with the 3rd order and the measured peaks",
                  fontsize=10)
    top.set_xlim(left, right)
    top.set_ylim(0.0, SPECTRUM_TOP)
    fig.canvas.draw()
    for peak in peaks:  # each mode's label on its line's height, at the end the order lines leave clear
        label = top.annotate(f"mode {peak.mode} ({peak.coordinate}) {peak.frequency:.2f} Hz", (left, peak.frequency),
                             xytext=(3, 0), textcoords="offset points", color=SKY, fontsize=7, va="center")
        box = clear_of_lines(top, label, [{"xy": (left, peak.frequency), "xyann": (3, 0), "ha": "left"},
                                          {"xy": (right, peak.frequency), "xyann": (-3, 0), "ha": "right"}])
        span = [box.x1, right] if label.get_horizontalalignment() == "left" else [left, box.x0]
        top.plot(span, [peak.frequency] * 2, color=SKY, lw=0.7, ls="-.", label=f"_mode {peak.mode}")
    reached = [peak for peak in peaks if peak.measured is not None]
    ring = {"ls": "none", "marker": "o", "ms": 13, "mfc": "none", "mec": SKY, "mew": 1.6}
    dot = {"ls": "none", "marker": "o", "ms": 5, "color": YELLOW, "zorder": 4}
    top.plot([p.crossing for p in reached], [p.frequency for p in reached], **ring, label="3 x f_shaft = f_mode")
    top.plot([p.measured[1] for p in reached], [3.0 * p.measured[1] / (2.0 * np.pi) for p in reached], **dot,
             label="measured third-order peak")
    top.legend(loc="upper left", fontsize=8)
    inside = (speeds >= left) & (speeds <= right)
    colors = PALETTE[:6]
    for peak, amplitude in zip(peaks, amplitudes):
        if peak.measured is None:
            continue
        color = colors[peak.mode - 1]
        bottom.plot(speeds[inside], amplitude[inside] / peak.measured[0], color=color, lw=1.2,
                    label=f"mode {peak.mode} ({peak.coordinate}): {peak.difference:+.1f} %")
        bottom.plot(peak.crossing, np.interp(peak.crossing, speeds, amplitude) / peak.measured[0],
                    **(ring | {"mec": color, "ms": 10}), label=f"_crossing {peak.mode}")
        bottom.plot(peak.measured[1], 1.0, **(ring | {"mec": color, "ms": PEAK_RINGS[peak.mode - 1], "zorder": 4}),
                    label=f"_peak {peak.mode}")
    bottom.set_ylim(0.0, 1.1)
    bottom.set_xlabel("left halfshaft speed [rad/s]")
    bottom.set_ylabel("third-order amplitude / its peak [1]")
    bottom.set_title("Each mount mode's share of the powertrain's acceleration, third order: crossing (ring of one "
                     "size), peak\n(a ring of the mode's size: peaks close in speed nest), the peak's speed against "
                     "the crossing's", fontsize=10)
    bottom.legend(loc="upper left", fontsize=8)
    bottom.grid(alpha=0.3)
    return fig


#: The housing-motion figure's panels: (output, what it is, unit), the powertrain's accelerations at its centre
#: of gravity that the shudder shows in
HOUSING_PANELS = (("mounts.y_ddot", "lateral acceleration y_ddot", "m/s2"),
                  ("mounts.yaw_ddot", "yaw acceleration yaw_ddot", "rad/s2"),
                  ("mounts.pitch_ddot", "pitch acceleration pitch_ddot", "rad/s2"))
#: How each launch is drawn: the housings held solid, moving dashed (drawn over the held ones, whose curves show
#: between the dashes where the two coincide, as in phase on rubber); a colour for each launch
HOUSING_STYLE = {False: ("-", "housings held"), True: ("--", "housings moving")}
LAUNCH_COLOURS = {(0.0, False): ORANGE, (0.0, True): SKY, (60.0, False): VERMILLION, (60.0, True): BLUE}


def housing_tracks(time: np.ndarray, shaft_angle: np.ndarray,
                   values: dict[str, np.ndarray]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The third-order tracks (speeds [rad/s], amplitudes) of the housing-motion figure's accelerations
    (``values`` by output name) over the shaft's speed."""
    return {name: order_tracking.order_track(time, shaft_angle, values[name], order_tracking.SHUDDER_ORDER)
            for name, _, _ in HOUSING_PANELS}


def housing_motion_figure(tracks: dict[tuple[float, bool], dict[str, tuple[np.ndarray, np.ndarray]]],
                          subtitle: str = "") -> Figure:
    """The third-order amplitude of the powertrain's lateral, yaw and pitch accelerations over the left
    halfshaft's speed, a panel each, for the launches ``tracks`` holds: by (the right joint's phase [deg], the
    housings moving), each output's order track (speeds [rad/s], amplitudes). A log scale, so that the launches
    whose peaks lie 70 times apart show side by side."""
    fig, axes = figure(len(HOUSING_PANELS), 1, figsize=(8, 9.6), sharex=True, layout="constrained")
    for ax, (name, what, unit) in zip(axes, HOUSING_PANELS):
        low, high = np.inf, 0.0
        for (phase, moving), found in sorted(tracks.items(), key=lambda item: (item[0][1], -item[0][0])):
            speeds, amplitude = found[name]
            style, housings = HOUSING_STYLE[moving]
            shown = amplitude > 0.0
            ax.plot(speeds[shown], amplitude[shown], style, color=LAUNCH_COLOURS.get((phase, moving), YELLOW), lw=1.3,
                    label=f"right joint {phase:g} deg ahead, {housings}")
            low, high = min(low, amplitude[shown].min()), max(high, amplitude[shown].max())
        ax.set_yscale("log")
        ax.set_ylim(0.7 * low, 2.0 * high)
        ax.set_ylabel(f"third order [{unit}]")
        ax.set_title(f"Powertrain {what} at its centre of gravity, third order", fontsize=10)
        ax.grid(alpha=0.3, which="both")
    speeds = np.concatenate([found[HOUSING_PANELS[0][0]][0] for found in tracks.values()])
    axes[-1].set_xlim(speeds.min(), speeds.max())
    axes[-1].set_xlabel("left halfshaft speed [rad/s]")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncols=2, fontsize=8)
    if subtitle:
        fig.suptitle(subtitle, fontsize=9)
    return fig


def write(package: Path, out: Path) -> list[Path]:
    """Run the launch, write ``vehicle_launch.csv``, ``launch_shudder_peaks.csv`` and the three
    figures into ``out``; return the files written."""
    out.mkdir(parents=True, exist_ok=True)
    launch = run(package, changes=CHANGES)
    units = {name: MODELS[model].spec[variable].unit
             for name, model, variable in _column_models(package)}
    header = ["time [s]", *(f"{csv_name} [{units[name]}]" for name, csv_name in COLUMNS)]
    kept = slice(0, None, EVERY)  # from t = 0
    table = np.column_stack([launch.time[kept], *(launch.values[name][kept] for name, _ in COLUMNS)])
    run_csv = write_csv(out / "vehicle_launch.csv", header, table.tolist())
    peaks, speeds, amplitudes = third_order_peaks(launch)
    peaks_csv = write_csv(out / "launch_shudder_peaks.csv", PEAK_COLUMNS,
                          (peak_row(p, speeds[-1], amplitudes[p.mode - 1][-1]) for p in peaks))
    return [run_csv, peaks_csv,
            save(speed_torque_figure(launch), out / "launch_speed_torque.png"),
            save(axial_force_figure(launch), out / "launch_axial_force.png"),
            save(orders_figure(launch, peaks, speeds, amplitudes), out / "launch_shudder_orders.png")]


def _column_models(package: Path) -> list[tuple[str, str, str]]:
    """(component.variable, model, variable) of each column of :data:`COLUMNS`."""
    models = {c.name: Path(c.source).stem for c in ssp_package.read(package).components}
    return [(name, models[name.split(".")[0]], name.split(".")[1]) for name, _ in COLUMNS]
