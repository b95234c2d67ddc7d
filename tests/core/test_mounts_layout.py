"""PowertrainMounts' layout files: the shipped default, and refusals naming the key (the file rules
themselves, shared with CriticalSpeeds, are driveline/layout_files.py's)."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from driveline.layout_files import MAX_FILE_BYTES
from driveline.mounts.layout import MAX_MOUNTS, load_layout, loads_layout, shipped_layout
from driveline.mounts.model import PowertrainMountsModel

HEADER = "mass = 200.0\ncentre_of_gravity = [0.0, 0.0, 0.3]\ninertia = [11.0, 8.0, 10.0, 0.3, 1.0, 0.4]\n"
MOUNT = "[[mounts]]\nposition = [0.2, 0.3, 0.5]\nstiffness = [1e5, 1e5, 2e5]\n"


def test_the_default_layout_reads_with_its_loss_factors_converted():
    """c = eta k / (2 pi f_eta): the engine mount's 0.15 at 10 Hz."""
    layout = load_layout(shipped_layout("transverse_fwd_powertrain"))
    assert layout.mass == 200.0 and len(layout.mounts) == 3
    engine = layout.mounts[0]
    assert engine.label == "engine mount"
    assert np.allclose(engine.damping, 0.15 * engine.stiffness / (2.0 * math.pi * 10.0), rtol=1e-15)
    assert layout.inertia[0, 1] == -0.3 and layout.inertia[0, 2] == -1.0 and layout.inertia[1, 2] == -0.4
    assert not engine.progressive and len(engine.branches) == 0


def test_the_rubber_layout_reads_with_its_rubber_and_stops():
    """Rubber damping (four branch weights a mount, no viscous damper), a snubber on every mount."""
    layout = load_layout(shipped_layout("transverse_fwd_powertrain_rubber"))
    assert layout.mass == 200.0 and len(layout.mounts) == 3
    assert [m.label for m in layout.mounts] == ["engine mount", "transmission mount", "roll restrictor"]
    for mount in layout.mounts:
        assert mount.progressive and len(mount.branches) == 4 and not np.any(mount.damping)
    assert layout.inertia[0, 1] == -0.3 and layout.inertia[0, 2] == -1.0 and layout.inertia[1, 2] == -0.4


@pytest.mark.parametrize("text, fragment", [
    (HEADER + MOUNT.replace("[1e5, 1e5, 2e5]", "[1e5, -1e5, 2e5]"), "mounts[0].stiffness[1] must be >= 0"),
    (HEADER + MOUNT + "damping = [1.0, -2.0, 3.0]\n", "mounts[0].damping[1] must be >= 0"),
    (HEADER + MOUNT + "loss_factor = 0.1\n", "mounts[0].loss_factor needs the top-level key 'loss_factor_frequency'"),
    (HEADER + MOUNT + "loss_factor = 0.1\ndamping = [1, 2, 3]\n", "give either 'damping' or 'loss_factor'"),
    (HEADER + MOUNT + "orientation = [[1, 0, 0], [0, 1, 0], [0, 0, -1]]\n", "mounts[0].orientation is not a rotation"),
    (HEADER + MOUNT + "orientation = [[1, 0, 0], [0, 1.001, 0], [0, 0, 1]]\n", "mounts[0].orientation is not a rotation"),
    (HEADER + MOUNT + "stiffnes = [1, 2, 3]\n", "mounts[0]: unknown key 'stiffnes'"),
    (HEADER + "[[mounts]]\nposition = [0, 0, 0]\n", "mounts[0]: missing key 'stiffness'"),
    (HEADER.replace("200.0", "-1.0") + MOUNT, "mass must be > 0"),
    (HEADER.replace("[11.0, 8.0, 10.0, 0.3, 1.0, 0.4]", "[1.0, 1.0, 1.0, 2.0, 0.0, 0.0]") + MOUNT,
     "is not positive definite"),
    (HEADER.replace("[11.0, 8.0, 10.0, 0.3, 1.0, 0.4]", "[1.0, 1.0, 1.0]") + MOUNT, "inertia must be an array of 6"),
    (HEADER, "at least one [[mounts]] table is required"),
    (HEADER + MOUNT * (MAX_MOUNTS + 1), f"{MAX_MOUNTS + 1} [[mounts]] tables are more than the {MAX_MOUNTS} accepted"),
    (HEADER + MOUNT.replace("[0.2, 0.3, 0.5]", '"here"'), "mounts[0].position must be an array of 3 numbers"),
    (HEADER + MOUNT.replace("2e5]", "nan]"), "mounts[0].stiffness[2] must be finite"),
])
def test_a_bad_layout_is_refused_naming_the_key(text, fragment):
    with pytest.raises(ValueError) as caught:
        loads_layout(text, "layout.toml")
    assert fragment in str(caught.value)


def _initialize(**parameters) -> list[str]:
    model = PowertrainMountsModel()
    for name, value in parameters.items():
        setattr(model, name, value)
    return model.initialize(0.0)


def test_the_model_refuses_what_the_layout_or_the_placement_cannot_give(tmp_path):
    line = tmp_path / "line.toml"
    line.write_text(HEADER + "".join(MOUNT.replace("[0.2, 0.3, 0.5]", f"[{x}, 0.0, 0.0]") for x in (0.1, 0.2, 0.3)))
    assert "leave a rigid-body motion unrestrained" in _initialize(layout=str(line))[0]
    large = tmp_path / "large.toml"
    large.write_text("#" * (MAX_FILE_BYTES + 1))
    assert f"is larger than {MAX_FILE_BYTES} bytes" in _initialize(layout=str(large))[0]
    if hasattr(os, "mkfifo"):
        os.mkfifo(tmp_path / "fifo.toml")
        assert "is not a regular file" in _initialize(layout=str(tmp_path / "fifo.toml"))[0]
    assert "no shipped layout named 'nosuch'" in _initialize(layout="nosuch")[0]
    assert "bend-plane direction of the left joint is parallel" in _initialize(bend_z_left=0.0, bend_y_left=1.0)[0]
    assert "halfshaft direction of the right joint has no length" in _initialize(shaft_y_right=0.0)[0]
    assert "motor axis" in _initialize(motor_axis_y=0.0)[0]
    # finite components whose squared length overflows: refused, not turned into a zero direction
    assert "the motor axis (motor_axis_x, motor_axis_y, motor_axis_z) is too long (its length overflows)" in \
        _initialize(motor_axis_x=1e300)[0]
    assert "halfshaft direction of the left joint is too long" in _initialize(shaft_z_left=1e300)[0]
    assert "bend-plane direction of the right joint is too long" in _initialize(bend_x_right=1e300)[0]
    assert _initialize() == []
