"""Two TripodCoupling FMUs wired into a PowertrainMounts FMU as docs/powertrain_mounts.md says, and
Newton-Euler checked on the outputs alone: at every step's end the mount forces, the joints' loads
on the powertrain (built here from TripodCoupling's outputs and the joint frames of the
parameters) and the weight add up to m times the acceleration of the centre of gravity, their
moments about it to J times the angular acceleration. The forces are summed here, not assembled
into matrices, so the check shares no code with the model's stiffness, damping or input map."""

from __future__ import annotations

import numpy as np

from driveline.mounts.layout import load_layout, shipped_layout
from driveline.mounts.rigid_body import COORDINATES
from driveline.mounts.spec import AXES, REACTIONS, SIDES, SPEC

STEPS, H, G = 200, 5e-4, 9.81
#: The left joint drives its wheel forwards; the right one, its Z' pointing to its own wheel (-y),
#: turns and is loaded negatively about it (docs/powertrain_mounts.md).
JOINTS = {"left": {"omega_in": 60.0, "T_load": 400.0, "beta": 0.15},
          "right": {"omega_in": -60.0, "T_load": -400.0, "beta": 0.25}}


def _frame(side: str) -> np.ndarray:
    """Columns X', Y', Z' of the joint from the parameters' start values."""
    shaft = np.array([SPEC[f"shaft_{a}_{side}"].start for a in AXES], dtype=float)
    bend = np.array([SPEC[f"bend_{a}_{side}"].start for a in AXES], dtype=float)
    z = shaft / np.linalg.norm(shaft)
    x = bend - (bend @ z) * z
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _residual(layout, outputs: dict[str, float], reactions: dict[str, np.ndarray]) -> np.ndarray:
    """Newton-Euler residual (force [N], moment [N m]) of the powertrain at one instant."""
    centre = layout.centre_of_gravity
    force = np.array([0.0, 0.0, -layout.mass * G])
    moment = np.zeros(3)
    for i, mount in enumerate(layout.mounts, 1):
        f = np.array([outputs[f"F_{a}_mount{i}"] for a in AXES])
        force += f
        moment += np.cross(mount.position - centre, f)
    for side in SIDES:
        frame = _frame(side)
        centre_joint = np.array([SPEC[f"{a}_joint_{side}"].start for a in AXES])
        f, m = -(frame @ reactions[side][:3]), -(frame @ reactions[side][3:])
        force += f
        moment += np.cross(centre_joint - centre, f) + m
    acceleration = np.array([outputs[f"{name}_ddot"] for name in COORDINATES])
    return np.concatenate([force - layout.mass * acceleration[:3], moment - layout.inertia @ acceleration[3:]])


def test_two_tripod_couplings_shake_the_powertrain_by_newtons_laws(family, fmi):
    """Residual below 1e-9 of the loads (mount forces some 1e3 N, the joints' torques 400 N m)."""
    layout = load_layout(shipped_layout(SPEC["layout"].start))
    names = [f"F_{a}_mount{i}" for i in range(1, len(layout.mounts) + 1) for a in AXES] + \
        [f"{name}_ddot" for name in COORDINATES]
    with family.open("TripodCoupling", fmi, "left") as left, family.open("TripodCoupling", fmi, "right") as right, \
            family.open("PowertrainMounts", fmi) as mounts:
        joints = {"left": left, "right": right}
        for side, joint in joints.items():
            joint.initialize(JOINTS[side])
        reactions = {side: np.array(joint.get(REACTIONS), dtype=float) for side, joint in joints.items()}
        inputs = [f"{name}_{side}" for side in SIDES for name in REACTIONS]
        mounts.initialize(dict(zip(inputs, np.concatenate([reactions[s] for s in SIDES]).tolist())))
        outputs = dict(zip(names, mounts.get(names)))  # at rest in the static equilibrium
        worst, pitch = float(np.max(np.abs(_residual(layout, outputs, reactions))) / 1e3), []
        for _ in range(STEPS):
            for joint in joints.values():
                joint.step(H)
            mounts.step(H)  # under the reactions held from the step's start
            outputs = dict(zip(names, mounts.get(names)))
            worst = max(worst, float(np.max(np.abs(_residual(layout, outputs, reactions))) / 1e3))
            pitch.append(mounts.get(["pitch"])[0])
            reactions = {side: np.array(joint.get(REACTIONS), dtype=float) for side, joint in joints.items()}
            mounts.set(dict(zip(inputs, np.concatenate([reactions[s] for s in SIDES]).tolist())))
    assert worst < 1e-9
    # both drive-torque reactions, -T_in about each joint's Z', turn the powertrain the same way
    # about -y: a negative pitch (the torque roll axis lies close to y for this layout)
    assert max(pitch) < 0.0
