"""The main job's figures show what their titles claim, measured on the matplotlib figures the
studies return (``support.figure_checks``): no curve drawn under others, overlapping markers
nested, every sample inside its axes, no log axis over a zero, no legend repeated, no empty panel,
no text beyond the canvas or crossed by a line, only colour-blind-safe colours; and, figure by
figure, that each case the title names is drawn. The checks themselves are shown to catch the
defects they were written for, on figures drawn here."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from fmu_harness import shudder_map  # noqa: E402
from fmu_harness.packaging import native  # noqa: E402
from fmu_harness.runs import system  # noqa: E402
from fmu_harness.studies import coupling_comparison, critical_speed_study, launch_study, tripod_study  # noqa: E402
from fmu_harness.studies.figures import by_scale  # noqa: E402
from support import figure_checks  # noqa: E402


def assert_clean(fig, name: str = "") -> None:
    assert figure_checks.hidden_curves(fig) == [], name
    assert figure_checks.stacked_markers(fig) == [], name
    assert figure_checks.beyond_limits(fig) == [], name
    assert figure_checks.log_over_zero(fig) == [], name
    assert figure_checks.repeated_legends(fig) == [], name
    assert figure_checks.empty_axes(fig) == [], name
    assert figure_checks.texts_outside_canvas(fig) == [], name
    assert figure_checks.texts_on_lines(fig) == [], name
    assert figure_checks.unsafe_colours(fig) == [], name


@pytest.fixture(scope="module")
def tripod_figures(native_dir):
    figures = tripod_study.figures(tripod_study.run(native.fmu_path(native_dir, "TripodCoupling")))
    yield figures
    for fig in figures.values():
        plt.close(fig)


def drawn_labels(fig) -> list[str]:
    return [line.get_label() for ax in fig.axes if ax.get_visible() for line in ax.get_lines()]


def test_every_tripod_figure_shows_each_curve(tripod_figures):
    assert len(tripod_figures) == 10
    for name, fig in tripod_figures.items():
        assert_clean(fig, name)


def test_every_bend_angle_is_drawn_in_the_seed_figures(tripod_figures):
    """Figs 5, 10, 12, 13 draw each bend angle once per row of panels, under one legend."""
    names = ["tripod_fig05_deviation.png", *(f"tripod_fig{n}_{c}.png" for n, c, _ in tripod_study.SEED_FIGURES)]
    for name in names:
        fig = tripod_figures[name]
        rows = 1 if name.startswith("tripod_fig05") else 2
        expected = sorted(f"beta = {beta} deg" for beta in tripod_study.BETAS_DEG) * rows
        assert sorted(drawn_labels(fig)) == sorted(expected), name
        assert figure_checks.legend_count(fig) == 1, name


def test_turn_figure_draws_each_reaction_at_each_load_for_three_bend_angles(tripod_figures):
    fig = tripod_figures["tripod_reactions_turn.png"]
    titles = {ax.get_title(): ax for ax in fig.axes}
    for column in tripod_study.REACTIONS:
        for load in tripod_study.LOADS:
            ax = titles[f"{column}, T_load = {load:.0f} N.m"]
            assert sorted(line.get_label() for line in ax.get_lines()) == [
                f"beta = {beta} deg" for beta in tripod_study.TURN_BETAS]


def test_joints_figure_draws_each_joint_with_the_plain_tripod_above_the_rollers(tripod_figures):
    """The three joints against beta (300 N.m) and against the load (12 deg); from 4 deg up the plain tripod's
    axial force lies above both roller tripods', both roller tripods' grow with beta, every one with the load."""
    left, right = tripod_figures["tripod_joints_axial_force.png"].axes
    for ax in (left, right):
        assert sorted(line.get_label() for line in ax.get_lines()) == sorted(tripod_study.JOINTS.values())
    lines = {line.get_label(): line.get_ydata() for line in left.get_lines()}
    from_4 = np.array(tripod_study.ROLLER_BETAS) >= 4
    plain, single, double = (lines[name] for name in ("plain tripod", "single roller", "double roller"))
    assert np.all(plain[from_4] > single[from_4]) and np.all(plain[from_4] > double[from_4])
    assert np.all(np.diff(single) > 0) and np.all(np.diff(double) > 0)
    for line in right.get_lines():
        assert np.all(np.diff(line.get_ydata()) > 0)


def test_seed_means_are_drawn_around_the_force_balance_at_no_load(tripod_figures):
    """The seed's mean Ry_in (0) coincides with the force balance's at 0 N.m: a larger ring."""
    ax = next(ax for ax in tripod_figures["tripod_reactions_vs_beta.png"].axes if ax.get_title().startswith("Mean Ry_in"))
    lines = {line.get_label(): line for line in ax.get_lines()}
    seed, unloaded = lines["seed's eq 34: mean 0 at every load"], lines["force balance, T = 0 N.m"]
    np.testing.assert_allclose(seed.get_ydata(), unloaded.get_ydata(), atol=1e-9)
    assert seed.get_markerfacecolor() == "none" and seed.get_markersize() > unloaded.get_markersize()


def test_coupling_comparison_names_a_zero_fluctuation_instead_of_plotting_it(fmi2_dir):
    betas = [5.0, 25.0, 45.0]
    rows = coupling_comparison.speed_fluctuation_table(fmi2_dir, betas)
    fig = coupling_comparison.comparison_figure(rows, betas)
    assert_clean(fig)
    (ax,) = fig.axes
    plotted = {name: list(line.get_ydata()) for line in ax.get_lines() for name in line.get_label().split(" = ")}
    for coupling in coupling_comparison.COUPLINGS:
        values = [row["fluctuation"] for row in rows if row["coupling"] == coupling.name]
        if max(values) == 0.0:
            assert any(text.get_text().startswith(f"{coupling.name}: 0 at every") for text in ax.texts)
            assert coupling.name not in plotted
        else:
            assert plotted[coupling.name] == values
    # the roller tripods turn on the plain tripod's closure: named in its line's label, not drawn over it
    assert sorted(line.get_label() for line in ax.get_lines()) == [
        "CardanJoint", "TripodCoupling = TripodCoupling single roller = TripodCoupling double roller"]
    plt.close(fig)


def test_campbell_diagram_nests_the_backward_crossings_inside_the_critical_speeds(native_dir):
    fmu = native.fmu_path(native_dir, "CriticalSpeeds")
    criticals = critical_speed_study.critical_speeds(fmu)
    result = critical_speed_study.ramp(
        fmu, critical_speed_study.ramp_speeds(critical_speed_study.BEYOND * max(criticals), criticals))
    fig = critical_speed_study.campbell_figure(result, critical_speed_study.branches(result), criticals)
    assert_clean(fig)
    (ax,) = fig.axes
    marks = [line for line in ax.get_lines() if len(line.get_xdata()) == 1]
    critical = [line for line in marks if line.get_label().startswith("_critical speed 1x")]
    backward_1x = [line for line in marks if line.get_label().startswith("_backward 1x")]
    assert len(critical) == 3 and len(backward_1x) == 3
    for ring, square in zip(critical, backward_1x):
        # each backward 1x crossing lies within 3 % of a critical speed (2.1 % at the first), drawn over its ring
        assert square.get_xdata()[0] == pytest.approx(ring.get_xdata()[0], rel=0.03)
        assert square.get_zorder() > ring.get_zorder()
    plt.close(fig)


@pytest.fixture(scope="module")
def launch_figures(fmi2_dir, native_dir):
    """The launch study's figures on a quick launch of the study's set-up (its phase, the housings held):
    140 N.m for 4 s (0.3 s of CPU), through three mount modes' crossings."""
    package = system.write_ssp(system.vehicle_launch(), fmi2_dir, native_dir)
    launch = launch_study.run(package, torque=140.0, stop_time=4.0, changes=launch_study.CHANGES)
    peaks, speeds, amplitudes = launch_study.third_order_peaks(launch)
    figures = {"speed_torque": launch_study.speed_torque_figure(launch),
               "axial_force": launch_study.axial_force_figure(launch),
               "orders": launch_study.orders_figure(launch, peaks, speeds, amplitudes)}
    yield figures, peaks
    for fig in figures.values():
        plt.close(fig)


def test_the_launch_figures_show_each_curve_and_what_their_titles_name(launch_figures):
    """Speed and both halfshaft torques; both joints' axial force with its third order; the
    spectrogram with orders 1 and 3, every mode's line, each crossing ring with its peak inside or
    beside it, each crossed mode's normalised third order."""
    figures, peaks = launch_figures
    for name, fig in figures.items():
        assert_clean(fig, name)
    assert drawn_labels(figures["speed_torque"]) == ["vehicle speed", "left halfshaft", "right halfshaft"]
    assert drawn_labels(figures["axial_force"]) == ["left joint", "right joint"] * 2
    top, bottom = figures["orders"].axes[:2]
    labels = [line.get_label() for line in top.get_lines()]
    assert labels[:2] == ["order 1", "order 3"] and labels.count("_mode 1") == 1
    assert sum(label.startswith("_mode ") for label in labels) == 6
    reached = [p for p in peaks if p.measured is not None]
    assert len(reached) >= 3
    rings = top.get_lines()[labels.index("3 x f_shaft = f_mode")]
    np.testing.assert_allclose(rings.get_xdata(), [p.crossing for p in reached])
    assert [line.get_label().split(":")[0] for line in bottom.get_lines() if not line.get_label().startswith("_")] == [
        f"mode {p.mode} ({p.coordinate})" for p in reached]


@pytest.fixture(scope="module")
def housing_figure(fmi2_dir, native_dir):
    """The housing-motion figure of four quick launches (140 N.m for 4 s at the study's step, 7.7 s of CPU in
    all): the right joint in phase and 60 deg ahead, the housings held and moving."""
    package = system.write_ssp(system.vehicle_launch(), fmi2_dir, native_dir)
    tracks = {}
    for phase in (0.0, 60.0):
        for moving in (False, True):
            launch = launch_study.run(package, torque=140.0, stop_time=4.0, changes={
                "joint_right": {"phi_in_start": np.radians(phase)}, "mounts": {"housing_motion": int(moving)}})
            tracks[phase, moving] = launch_study.housing_tracks(launch.time, launch.shaft_angle, launch.values)
    fig = launch_study.housing_motion_figure(tracks, "a subtitle")
    yield fig
    plt.close(fig)


def test_the_housing_figure_draws_each_launch_and_the_shudder_the_housings_take_away(housing_figure):
    """Each panel draws the four launches once under one legend; on the lateral panel the 60 deg launch
    with the housings held peaks 5 times or more above the in-phase one and 2 times or more above the
    same launch with the housings moving (docs/vehicle_launch.md: 15 and 7.7 times at 2e-4 s)."""
    assert_clean(housing_figure)
    assert figure_checks.legend_count(housing_figure) == 1
    labels = sorted(f"right joint {phase} deg ahead, housings {state}" for phase in ("0", "60")
                    for state in ("held", "moving"))
    for ax in housing_figure.axes:
        assert sorted(line.get_label() for line in ax.get_lines()) == labels, ax.get_title()
    peak = {line.get_label(): max(line.get_ydata()) for line in housing_figure.axes[0].get_lines()}
    assert peak["right joint 60 deg ahead, housings held"] > 5.0 * peak["right joint 0 deg ahead, housings held"]
    assert peak["right joint 60 deg ahead, housings held"] > 2.0 * peak["right joint 60 deg ahead, housings moving"]


def deviations(*panels: tuple[float, ...]) -> plt.Figure:
    """Sinusoids of the given amplitudes, one axes per tuple, drawn in that order (fig. 5's before)."""
    fig, axes = plt.subplots(1, len(panels), squeeze=False)
    phi = np.linspace(0.0, 2 * np.pi, 360)
    for ax, amplitudes in zip(axes[0], panels):
        for amplitude in amplitudes:
            ax.plot(phi, amplitude * np.sin(3 * phi), label=f"{amplitude:g}")
    return fig


def test_the_checks_catch_what_the_old_figures_drew():
    """The defects of the figures before: a 0.015 curve on an 11 scale under the larger one (fig
    5), equal markers stacked (the seed's mean 0), a 0 plotted as 1e-16 on a log axis (the
    reducer), a legend repeated (figs 10, 12, 13), data beyond the axes."""
    hidden = deviations((0.015, 0.12, 0.4, 11.0))  # beta = 5, 10, 15, 45 deg in fig. 5 [arcmin]
    assert figure_checks.hidden_curves(hidden) == [": 0.015"]
    # spread over panels by the studies' rule: each seen
    amplitudes = (0.015, 0.12, 0.4, 11.0)
    split = deviations(*(tuple(group) for group in by_scale({a: a for a in amplitudes})))
    assert len(split.axes) == 3 and figure_checks.hidden_curves(split) == []
    fig, (left, right) = plt.subplots(1, 2)
    left.plot([1, 2, 3], [0, 0, 0], "s", label="force balance")
    left.plot([1, 2, 3], [0, 0, 0], "x", label="seed")
    right.semilogy([1, 2, 3], [1e-2, 1e-1, 1.0], "o-", label="tripod")
    right.semilogy([1, 2, 3], [1e-16] * 3, "o-", label="reducer")
    left.legend()
    right.legend(handles=left.get_lines())
    right.set_xlim(1, 2)
    assert len(figure_checks.stacked_markers(fig)) == 3
    assert figure_checks.log_over_zero(fig) == [": reducer"]
    assert figure_checks.repeated_legends(fig) == [["force balance", "seed"]]
    assert figure_checks.beyond_limits(fig) == [": tripod", ": reducer"]
    for figure in (hidden, split, fig):
        plt.close(figure)


def test_the_checks_catch_what_a_report_cannot_show():
    """The defects an NVH engineer met in the figures before: an empty panel left over (figs 12, 13), a
    mode's label struck through by the next mode's line, an axis label cut at the canvas's edge (the
    shudder map of two values), red against green (the launch's halfshafts)."""
    fig, (drawn, empty) = plt.subplots(1, 2, figsize=(6, 3))
    drawn.plot([0, 1], [8.45, 8.45], color="#56B4E9", label="mode 3")
    drawn.plot([0, 1], [9.11, 9.11], color="tab:red", label="mode 4")
    drawn.annotate("mode 3 (x) 8.45 Hz", (0.0, 8.45), xytext=(3, 2), textcoords="offset points", fontsize=7)
    drawn.set_ylim(0.0, 25.0)  # as the spectrogram: the two lines 0.66 Hz, a few pixels, apart
    drawn.set_xlabel("a label\n" * 12)  # pushed below the canvas
    assert figure_checks.empty_axes(fig) == ["axes 1"]
    assert figure_checks.texts_on_lines(fig) == [": mode 3 (x) 8.45 Hz"]
    assert figure_checks.texts_outside_canvas(fig) == ["axes"]
    assert figure_checks.unsafe_colours(fig) == [": mode 4 in tab:red"]
    plt.close(fig)


def drawn_map(tmp_path, joints: tuple[int, ...]):
    """The shudder map's figure, kept open, of a table of ``map --count 2`` (two bend angles, two torques, two
    friction coefficients, the joints in phase) for each of the ``joints`` types."""
    pa = pytest.importorskip("pyarrow")
    from fmu_harness.runs.sweep import with_units

    rows = [{shudder_map.JOINT: joint, shudder_map.BETA: beta, shudder_map.TORQUE: torque, shudder_map.MU: mu,
             shudder_map.PHASE: 0.0, "status": "ok", **{peak: (1.0 + beta + torque / 100.0 + mu) / (1 + joint)
                                                         for peak in shudder_map.PEAKS}}
            for joint in joints for beta in shudder_map.BETA_RANGE for torque in shudder_map.TORQUE_RANGE
            for mu in shudder_map.MU_RANGE]
    units = {shudder_map.JOINT: "1", shudder_map.BETA: "rad", shudder_map.TORQUE: "N.m", shudder_map.MU: "1",
             shudder_map.PHASE: "rad", **dict.fromkeys(shudder_map.PEAKS, "rad/s2")}
    with pytest.MonkeyPatch.context() as patch:  # the figure kept open instead of saved and closed
        kept = []
        patch.setattr("fmu_harness.studies.figures.save", lambda fig, path: kept.append(fig) or path)
        shudder_map.draw(with_units(pa.Table.from_pylist(rows), units), tmp_path / "map.png")
    (fig,) = kept
    return fig


@pytest.mark.parametrize("joints", [(0,), (0, 1, 2)], ids=["plain", "three types"])
def test_the_shudder_map_of_two_values_per_axis_stays_within_its_grid(joints, tmp_path):
    """``map --count 2``: each panel's axes span the grid (5 to 20 deg, 20 to 100 % of the motor's peak), every
    label on the canvas, no panel empty; with several joint types a row of two panels per type, each titled
    with its type, a colour bar per type."""
    fig = drawn_map(tmp_path, joints)
    assert figure_checks.texts_outside_canvas(fig) == [] and figure_checks.empty_axes(fig) == []
    panels = [axes for axes in fig.axes if axes.get_label() != "<colorbar>"]
    assert len(panels) == 2 * len(joints) and len(fig.axes) - len(panels) == len(joints)
    for panel in panels:
        assert panel.get_xlim() == pytest.approx((5.0, 20.0)) and panel.get_ylim() == pytest.approx((20.0, 100.0))
    if len(joints) > 1:
        assert [panel.get_title().split(",")[0] for panel in panels] == [
            "plain", "plain", "single", "single", "double", "double"]
    plt.close(fig)
