"""The native PowertrainMounts FMU refuses what the Python FMU refuses, in its words: layouts that break
the shared file rules (driveline/layout_files.py, read by CriticalSpeeds' C reader) and the mounts'
own (driveline/mounts/layout.py), joint and motor directions that give no frame, mounts that leave a
motion free, a step beyond the exponential's work limit."""

from __future__ import annotations

from pathlib import Path

import pytest

from fmu_harness.packaging import native
from fmu_harness.runs.runner import FmuInstance, StepRefused
from support.native_agreement import refusals, up_to_the_toml_reason

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
    """A step whose exponential needs more than MAX_SQUARINGS squarings, or whose matrix overflows (a step of
    1e305 s: its norm is infinite, no count of squarings): the same refusal, word for word."""
    found = []
    for path in (fmu_path(NAME, fmi), native.fmu_path(native_dir, NAME, fmi)):
        with FmuInstance(path) as fmu:
            fmu.initialize({"F_z": 100.0})
            with pytest.raises(StepRefused) as refused:
                fmu.step(step)
            found.append(refused.value.messages)
    assert len(found[0]) == 1 and reason in found[0][0] and found[0] == found[1]


def test_progressive_and_rubber_mounts_are_refused_by_name_until_ported(native_dir, fmi):
    """The rubber layout's keys (read by the Python core and FMUs) are refused by the native FMU at
    initialisation in one line naming the mount and key, not taken as linear mounts."""
    rubber = Path(__file__).parents[2] / "driveline" / "mounts" / "data" / "transverse_fwd_powertrain_rubber.toml"
    found = refusals(native.fmu_path(native_dir, NAME, fmi), {"layout": str(rubber)})
    assert len(found) == 1 and "mounts[0].dynamic_ratio: progressive and rubber mounts are taken by the Python " \
        "FMUs only" in found[0]
