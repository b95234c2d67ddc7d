"""The native PowertrainMounts FMU refuses what the Python FMU refuses, in its words: layouts that break
the shared file rules (driveline/layout_files.py, read by CriticalSpeeds' C reader) and the mounts'
own (driveline/mounts/layout.py), joint and motor directions that give no frame, mounts that leave a
motion free, a step beyond the exponential's work limit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from driveline.mounts.implicit_step import TOO_SHORT
from driveline.mounts.spec import SHARED_LAYOUT, derivative_name
from fmu_harness.packaging import native
from fmu_harness.runs.runner import FmuInstance, StepRefused
from support.native_agreement import beyond_tolerance, refusals, up_to_the_toml_reason

NAME = "PowertrainMounts"
BODY = 'mass = 200.0\ncentre_of_gravity = [0.1, 0.0, 0.2]\ninertia = [11.0, 8.0, 10.0, 0.3, 1.0, 0.4]\n'
MOUNT = '[[mounts]]\nposition = [{x}, {y}, 0.3]\nstiffness = [1.5e5, 1.0e5, 3.0e5]\n'
THREE = "".join(MOUNT.format(x=x, y=y) for x, y in ((0.2, -0.4), (0.1, 0.4), (-0.3, 0.0)))

#: Layout texts (file name -> TOML) the tests write, each refused for a reason of its own.
LAYOUTS = {
    "unknown_top": BODY + "colour = 'red'\n" + THREE,
    "missing_mass": BODY.replace("mass = 200.0\n", "") + THREE,
    "name_number": BODY + "name = 3\n" + THREE,
    "mass_zero": BODY.replace("200.0", "0") + THREE,
    "mass_string": BODY.replace("200.0", "'heavy'") + THREE,
    "inertia_five": BODY.replace("0.3, 1.0, 0.4]", "0.3, 1.0]") + THREE,
    "inertia_indefinite": BODY.replace("[11.0, 8.0, 10.0", "[1.0, 8.0, 10.0").replace("1.0, 0.4]", "5.0, 0.4]") + THREE,
    "inertia_nan": BODY.replace("11.0,", "nan,") + THREE,
    "cg_two": BODY.replace("[0.1, 0.0, 0.2]", "[0.1, 0.0]") + THREE,
    "no_mounts": BODY,
    "nine_mounts": BODY + THREE * 3,
    "mounts_not_tables": BODY + "mounts = [1, 2]\n",
    "mount_unknown": BODY + THREE + "colour = 1\n",
    "mount_no_position": BODY + "[[mounts]]\nstiffness = [1.0, 2.0, 3.0]\n",
    "negative_stiffness": BODY + THREE.replace("1.0e5", "-1.0e5", 1),
    "both_dampings": BODY + THREE + "damping = [1.0, 1.0, 1.0]\nloss_factor = 0.1\n",
    "loss_without_frequency": BODY + THREE + "loss_factor = 0.1\n",
    "negative_loss": BODY + "loss_factor_frequency = 10.0\n" + THREE + "loss_factor = -0.1\n",
    "label_number": BODY + THREE + "label = 7\n",
    "orientation_rows": BODY + THREE + "orientation = [[1, 0, 0], [0, 1, 0]]\n",
    "orientation_short_row": BODY + THREE + "orientation = [[1, 0, 0], [0, 1], [0, 0, 1]]\n",
    "orientation_mirror": BODY + THREE + "orientation = [[1, 0, 0], [0, 1, 0], [0, 0, -1]]\n",
    "orientation_sheared": BODY + THREE + "orientation = [[1, 0.1, 0], [0, 1, 0], [0, 0, 1]]\n",
    "position_text": BODY + THREE.replace("[-0.3, 0.0, 0.3]", "'here'"),
    "on_a_line": BODY + "".join(MOUNT.format(x=0.0, y=y) for y in (-0.4, 0.0, 0.4)).replace("0.3]", "0.2]"),
    "nested": BODY + "x = " + "[" * 20 + "]" * 20 + "\n" + THREE,
    "malformed": BODY + "[[mounts]\n",
    # rubber damping and snubbers (layout._branches, layout._stop, rubber.fit_error)
    "ratio_without_loss": BODY + THREE + "dynamic_ratio = 1.4\n",
    "rubber_loss_one": BODY + THREE + "loss_factor = 1\ndynamic_ratio = 1.4\n",
    "rubber_loss_zero": BODY + THREE + "loss_factor = 0.0\ndynamic_ratio = 1.4\n",
    "ratio_below_one": BODY + THREE + "loss_factor = 0.15\ndynamic_ratio = 0.9\n",
    "ratio_text": BODY + THREE + "loss_factor = 0.15\ndynamic_ratio = 'high'\n",
    "ratio_unfit": BODY + THREE + "loss_factor = 0.3\ndynamic_ratio = 1.05\n",
    "gap_alone": BODY + THREE + "gap = [0.002, 0.002, 0.002]\n",
    "stop_rate_alone": BODY + THREE + "stop_rate = [1e6, 1e6, 1e6]\n",
    "negative_gap": BODY + THREE + "gap = [0.002, -0.001, 0.002]\nstop_rate = [1e6, 1e6, 1e6]\n",
    "not_monotonic": BODY + THREE + "gap = [0.002, 0.002, 0.002]\nstop_rate = [1e6, -2e5, 1e6]\n",
    "blend_zero": BODY + THREE + "gap = [0.002, 0.002, 0.002]\nstop_rate = [1e6, 1e6, 1e6]\nstop_blend = 0\n",
    "stop_short": BODY + THREE + "gap = [0.002, 0.002]\nstop_rate = [1e6, 1e6, 1e6]\n",
}


def _cases(folder: Path) -> list[dict]:
    (folder / "folder.toml").mkdir()
    (folder / "latin1.toml").write_bytes((BODY + THREE + "label = 'caf\xe9'\n").encode("latin-1"))
    (folder / "large.toml").write_text(BODY + THREE + "#" * 70000 + "\n")
    for name, text in LAYOUTS.items():
        (folder / f"{name}.toml").write_text(text)
    return [
        *({"layout": str(folder / f"{name}.toml")} for name in [*LAYOUTS, "folder", "latin1", "large", "missing"]),
        {"layout": "no_such_layout"}, {"layout": "../../etc/passwd"},
        {"shaft_x_left": 0.0, "shaft_y_left": 0.0, "shaft_z_left": 0.0},
        {"bend_x_right": 0.0, "bend_y_right": 2.0, "bend_z_right": 0.0},
        {"motor_axis_x": 0.0, "motor_axis_y": 0.0, "motor_axis_z": 0.0},
        {"motor_axis_x": 1e300}, {"shaft_z_left": 1e300}, {"bend_x_right": 1e300, "bend_z_right": 1e300},
    ]


def test_layout_and_placement_refusals_are_the_python_fmus(native_dir, fmu_path, tmp_path, fmi):
    """Every case is refused, by both FMUs alike (up to tomllib's own words for malformed TOML)."""
    for parameters in _cases(tmp_path):
        expected = [up_to_the_toml_reason(m) for m in refusals(fmu_path(NAME, fmi), parameters)]
        found = [up_to_the_toml_reason(m) for m in refusals(native.fmu_path(native_dir, NAME, fmi), parameters)]
        assert expected and found == expected, parameters


@pytest.mark.parametrize("step, reason", [(1e12, "squarings"), (1e300, "squarings"), (1e305, "overflows")])
def test_a_step_beyond_the_work_limit_is_refused_alike(native_dir, fmu_path, fmi, step, reason):
    """On linear mounts (the exact step), a step whose exponential needs more than MAX_SQUARINGS squarings, or
    whose matrix overflows (a step of 1e305 s: its norm is infinite, no count of squarings): the same refusal,
    word for word."""
    found = []
    for path in (fmu_path(NAME, fmi), native.fmu_path(native_dir, NAME, fmi)):
        with FmuInstance(path) as fmu:
            fmu.initialize({"F_z": 100.0, "layout": SHARED_LAYOUT})
            with pytest.raises(StepRefused) as refused:
                fmu.step(step)
            found.append(refused.value.messages)
    assert len(found[0]) == 1 and reason in found[0][0] and found[0] == found[1]


@pytest.mark.parametrize("step", [1e12, 1e300, 1e305])
def test_on_the_rubber_default_a_huge_step_lands_at_the_static_equilibrium(native_dir, fmu_path, fmi, step):
    """The implicit midpoint step is A-stable and needs no exponential: however long the step, its Newton
    iteration ends at rest in the static equilibrium under the held load (100 N up: the powertrain lifts by
    0.26 mm), both families alike within the equilibrium's Newton tolerance."""
    found = []
    for path in (fmu_path(NAME, fmi), native.fmu_path(native_dir, NAME, fmi)):
        with FmuInstance(path) as fmu:
            fmu.initialize({"F_z": 100.0})
            fmu.step(step)
            found.append(np.array(fmu.get(["z", "z_dot", "z_ddot", "pitch_ddot"]), dtype=float))
    python, native_values = found
    assert 2.5e-4 < python[0] < 2.7e-4 and abs(native_values[0] - python[0]) <= 1e-12 * python[0]
    # the rate over the step is twice the lift over the step's length; the accelerations, the forces' at rest, are
    # their rounding (eps m g over the inertia: some 1e-14, the floor of support.native_agreement)
    assert np.all(np.abs([python[1], native_values[1]]) <= 1e-3 / step)
    assert np.all(np.abs(np.concatenate([python[2:], native_values[2:]])) <= 1e-12)


@pytest.mark.parametrize("step", [5e-324, 1e-300, 1e-160])
def test_on_the_rubber_default_a_step_too_short_for_its_matrices_is_refused_alike(native_dir, fmu_path, fmi, step):
    """The implicit step's Jacobian holds 2 M / h^2: below about 1e-150 s it is beyond the range of numbers, and
    the residual's terms would overflow or not by the order of their sums (numpy's and C's differ): both families
    refuse the step before, word for word, after steps that set the powertrain moving (found by the property
    test: two steps of 1/128 s, then one of 5e-324 s), and the instance steps on at an ordinary step after it."""
    found = []
    for path in (fmu_path(NAME, fmi), native.fmu_path(native_dir, NAME, fmi)):
        with FmuInstance(path) as fmu:
            fmu.initialize({"F_z": 100.0})
            fmu.step(2 ** -7)
            fmu.step(2 ** -7)
            with pytest.raises(StepRefused) as refused:
                fmu.step(step)
            fmu.step(1e-3)
            found.append((refused.value.messages, fmu.get(["z"])[0]))
    (python_messages, python_z), (native_messages, native_z) = found
    assert len(python_messages) == 1 and TOO_SHORT in python_messages[0] and native_messages == python_messages
    assert abs(native_z - python_z) <= 1e-10 * abs(python_z)


RUBBER = Path(__file__).parents[2] / "driveline" / "mounts" / "data" / "transverse_fwd_powertrain_rubber.toml"
#: A linear layout with rubber damping (Maxwell branches, stepped exactly) and one with snubbers alone
#: (stepped implicitly, no branches)
LINEAR_RUBBER = BODY + "".join(MOUNT.format(x=x, y=y) + "loss_factor = 0.12\ndynamic_ratio = 1.3\n"
                               for x, y in ((0.2, -0.4), (0.1, 0.4), (-0.3, 0.0)))
SNUBBED = BODY + "loss_factor_frequency = 10.0\n" + "".join(
    MOUNT.format(x=x, y=y) + "loss_factor = 0.1\ngap = [0.001, 0.002, 0.001]\nstop_rate = [1e6, 5e5, 2e6]\n"
    for x, y in ((0.2, -0.4), (0.1, 0.4), (-0.3, 0.0)))
#: Loads of a run that takes the snubbers well beyond their gaps: the drive torque's reaction through the
#: right joint and a lateral force, ramped over the first half (first-order hold) and held
RUN_LOADS = {"T_in_right": 600.0, "F_y": 800.0, "Rz_in_left": 300.0}
RAMP = 0.2

# The tolerances are support.native_agreement's (1e-10 of each signal's largest magnitude for the motion
# and mount forces, 1e-11 of 1 for the modes' shares, 1e-12 for the rest). On progressive mounts both cores stop
# Newton's method at a step of 1e-14 of the displacement (forces.NEWTON_STEP), so each step's state agrees to some
# 1e-14 and a lightly damped run carries that on; the branches' weights come from two non-negative least-squares
# solvers (LAPACK-free Householder QR here, scipy's) that agree to the rounding of a well-posed 81 x 4 problem, and
# the modes' fixed point stops at a relative change of 1e-13 (rigid_body.FREQUENCY_TOLERANCE).


def _ramp(value: float, rate: bool):
    return lambda t: (value / RAMP if rate else value * t / RAMP) if t < RAMP - 1e-12 else (0.0 if rate else value)


def _run(path: Path, layout: str, torque: float) -> np.ndarray:
    """The loads ramped up over RAMP with their rates (first-order hold), then held, 200 steps of 2 ms."""
    signals = {**{name: _ramp(value, False) for name, value in RUN_LOADS.items()},
               **{derivative_name(name): _ramp(value, True) for name, value in RUN_LOADS.items()}}
    with FmuInstance(path) as fmu:
        fmu.initialize({"layout": layout, "T_mean": torque})
        return fmu.run(0.4, 2e-3, signals)


@pytest.mark.parametrize("layout", ["rubber", "linear_rubber", "snubbed"])
@pytest.mark.parametrize("torque", [0.0, 1100.0])
def test_rubber_and_progressive_mounts_match_the_python_fmu(native_dir, fmu_path, tmp_path, fmi, layout, torque):
    """The rubber layout (snubbers and branches, implicit steps), linear mounts with rubber damping (exact
    steps of the state with the branches) and snubbers alone, at idle and under 1.1 kN.m: every output within
    its tolerance of the Python FMU's over a run that loads the mounts beyond their gaps."""
    path = {"rubber": RUBBER, "linear_rubber": tmp_path / "linear_rubber.toml", "snubbed": tmp_path / "snubbed.toml"}
    path["linear_rubber"].write_text(LINEAR_RUBBER)
    path["snubbed"].write_text(SNUBBED)
    reference = _run(fmu_path(NAME, fmi), str(path[layout]), torque)
    found = _run(native.fmu_path(native_dir, NAME, fmi), str(path[layout]), torque)
    assert beyond_tolerance(reference, found) == {}



def _steps(fmu: FmuInstance, h: float, count: int = 20) -> list[list[float]]:
    found = []
    for _ in range(count):
        fmu.step(h)
        found.append(fmu.get(["x", "z", "pitch", "roll_dot", "F_z_mount1", "F_x_mount3"]))
    return found


@pytest.mark.parametrize("family", ["python", "native"])
def test_a_new_step_size_or_a_restored_state_steps_as_a_fresh_instance(request, fmu_path, fmi, family):
    """The implicit step keeps what depends on the step size alone (implicit_step.StepMatrices) from one step
    to the next. On the rubber layout under the drive reaction (on its stops): 20 steps of 1 ms, the state
    saved; 20 of 0.5 ms; the saved state restored and 20 of 1 ms. A fresh instance restored to the saved
    state repeats either continuation bit for bit: its matrices built for that step size from the start."""
    path = (fmu_path(NAME, fmi) if family == "python"
            else native.fmu_path(request.getfixturevalue("native_dir"), NAME, fmi))
    start = {"layout": str(RUBBER), "T_mean": 1100.0, "T_motor": 1100.0, "F_x": 500.0, "M_y": -200.0}
    with FmuInstance(path) as fmu:
        fmu.initialize(start)
        _steps(fmu, 1e-3)
        saved, saved_time = fmu.serialize_state(fmu.get_state()), fmu.time
        halved = _steps(fmu, 5e-4)
        fmu.set_state(fmu.deserialize_state(saved))
        fmu.time = saved_time
        again = _steps(fmu, 1e-3)
    for h, expected in ((5e-4, halved), (1e-3, again)):
        with FmuInstance(path) as fresh:
            fresh.initialize(start)
            fresh.set_state(fresh.deserialize_state(saved))
            fresh.time = saved_time
            assert _steps(fresh, h) == expected
