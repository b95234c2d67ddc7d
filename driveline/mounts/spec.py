"""Interface of the ``PowertrainMounts`` FMU: the single source for the FMI 2.0 and 3.0 builds."""

from __future__ import annotations

import math

from ..tripod.spec import BETA_LIMIT
from ..variables import DefaultExperiment, ModelSpec, Relation, State, Variable
from .halfshafts import GEOMETRY
from .layout import MAX_MOUNTS
from .rigid_body import COORDINATES
from .rubber import BRANCHES

SIDES = ("left", "right")
AXES = ("x", "y", "z")
#: TripodCoupling's housing reactions, in the order of :func:`driveline.mounts.joints.housing_load`.
REACTIONS = ("Rx_in", "Ry_in", "Rz_in", "Mx_in", "My_in", "T_in")
LOAD_INPUTS = ("F_x", "F_y", "F_z", "M_x", "M_y", "M_z")
#: Every load input in the order of the input map: the load at the centre of gravity, the joints', the motor's.
INPUTS = LOAD_INPUTS + tuple(f"{name}_{side}" for side in SIDES for name in REACTIONS) + ("T_motor",)
#: The powertrain on linear springs and viscous dampers, the default layout before the rubber one: kept under its
#: name, so that naming it gives the earlier default's results bit for bit
SHARED_LAYOUT = "transverse_fwd_powertrain"
#: The same powertrain on rubber mounts (progressive characteristics, Maxwell branches): the default layout
RUBBER_LAYOUT = "transverse_fwd_powertrain_rubber"
DEFAULT_LAYOUT = RUBBER_LAYOUT
COORDINATE_INDEX = ", ".join(f"{i} {name}" for i, name in enumerate(COORDINATES, 1))
# What the outputs are computed from (``depends_on``): the parameters placing the loads (the
# joints' frames and centres, the motor axis), the inputs' generalised force, the motion (states)
MOTOR_AXIS = tuple(f"motor_axis_{axis}" for axis in AXES)
FRAMES = tuple(f"{kind}_{axis}_{side}" for side in SIDES for kind in ("shaft", "bend") for axis in AXES)
PLACEMENT = (*(f"{axis}_joint_{side}" for side in SIDES for axis in AXES), *FRAMES, *MOTOR_AXIS)
STATICS = ("layout", "g", "T_mean", *MOTOR_AXIS)
LOADS = ("layout", *PLACEMENT, *INPUTS)
VELOCITIES = tuple(f"{name}_dot" for name in COORDINATES)
#: The Maxwell branches' forces, Model Exchange's states after the motion's (forces.BRANCH_SLOTS, mount, then
#: axis, then branch): those of each mount, and all of them
MOUNT_BRANCHES = tuple(tuple(f"F_axis{k}_mount{i}_branch{j}" for k in range(1, 4) for j in range(1, BRANCHES + 1))
                       for i in range(1, MAX_MOUNTS + 1))
BRANCH_FORCES = tuple(name for names in MOUNT_BRANCHES for name in names)
BRANCH_RATES = tuple(f"{name}_dot" for name in BRANCH_FORCES)
MOTION = (*COORDINATES, *VELOCITIES)
#: The loads' direct part in each acceleration (the mass matrix diag(m I, J)): a translation takes
#: the force along its axis and the joints' forces through their frames; a rotation every moment,
#: the joints' forces through their lever arms, not the force at the centre of gravity
ACCELERATION_LOADS = {
    **{axis: ("layout", *FRAMES, f"F_{axis}", *(f"{name}_{side}" for side in SIDES for name in REACTIONS[:3]))
       for axis in AXES},
    **{name: ("layout", *PLACEMENT, *INPUTS[len(AXES):]) for name in COORDINATES[len(AXES):]},
}


#: The states' nominals (State.nominal), from the default layout: a translation's the decade of its largest
#: static sag along an axis under the weight (z: 5.1 mm; the linear layout's 3.6 mm), a rotation's of its
#: largest about one (pitch: 4.1 mrad; 2.9), a velocity's its coordinate's times NOMINAL_RATE, the decade of the
#: lowest mode's angular frequency (4.79 Hz: 30.1 rad/s; 4.87 Hz); tests/core/test_mounts_modes.py derives them
#: from the layout
TRANSLATION_NOMINAL = 1e-3  # m
ROTATION_NOMINAL = 1e-3  # rad
NOMINAL_RATE = 10.0  # 1/s
NOMINALS = {name: TRANSLATION_NOMINAL if name in AXES else ROTATION_NOMINAL for name in COORDINATES}
#: A branch force's nominal: the decade of a branch's force at the translations' nominal deflection on the rubber
#: layout, its rate w_j k times 1 mm (1.8 to 86 N, mean 25 N); tests/core/test_mounts_rates.py derives it
BRANCH_NOMINAL = 10.0  # N


def derivative_name(name: str) -> str:
    """``F_x`` -> ``F_x_dot``, ``Rz_in_left`` -> ``Rz_in_dot_left`` (the side stays last)."""
    for side in SIDES:
        if name.endswith(f"_{side}"):
            return f"{name[:-len(side) - 1]}_dot_{side}"
    return f"{name}_dot"


def _unit(name: str, order: int) -> tuple[str, str | None]:
    linear = name in AXES
    base = "m" if linear else "rad"
    if order == 0:
        return (base, "mm" if linear else "deg")
    return (f"{base}/s" if order == 1 else f"{base}/s2", None)


def _load_unit(name: str) -> str:
    return "N" if name.startswith(("F", "R")) else "N.m"


def _inputs() -> tuple[Variable, ...]:
    texts = {
        "F_x": "Force on the powertrain at its centre of gravity along vehicle x (for any use)",
        "F_y": "Force on the powertrain at its centre of gravity along vehicle y",
        "F_z": "Force on the powertrain at its centre of gravity along vehicle z (the weight is applied already)",
        "M_x": "Moment on the powertrain about vehicle x", "M_y": "Moment on the powertrain about vehicle y",
        "M_z": "Moment on the powertrain about vehicle z",
        "T_motor": "Motor torque on its shaft about motor_axis: the powertrain carries its reaction -T_motor "
                   "(leave 0 when the joints' T_in already carry the drive torque)",
    }
    for side in SIDES:
        for name in REACTIONS:
            texts[f"{name}_{side}"] = (f"TripodCoupling.{name} of the {side} inboard joint, in its frame X'Y'Z' "
                                       "(wire the output of the same name): the powertrain carries its opposite")
    held = [Variable(name, "input", 0.0, texts[name], _load_unit(name)) for name in INPUTS]
    rates = [Variable(derivative_name(name), "input", 0.0,
                      f"Rate of {name} over the step (first-order hold; 0: held)",
                      f"{_load_unit(name)}/s", derivative=name) for name in INPUTS]
    return tuple(held + rates)


def _geometry() -> tuple[Variable, ...]:
    defaults = {
        "left": ((0.0, 0.22, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
        "right": ((0.0, -0.28, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    }
    found = []
    for side in SIDES:
        centre, shaft, bend = defaults[side]
        for axis, value in zip(AXES, centre):
            found.append(Variable(f"{axis}_joint_{side}", "parameter", value,
                                  f"Centre O of the {side} inboard joint, vehicle {axis}", "m", "mm"))
        for axis, value in zip(AXES, shaft):
            found.append(Variable(f"shaft_{axis}_{side}", "parameter", value,
                                  f"Halfshaft direction of the {side} joint (its Z': the housing's axis, "
                                  f"towards the wheel), vehicle {axis} component", "1"))
        for axis, value in zip(AXES, bend):
            found.append(Variable(f"bend_{axis}_{side}", "parameter", value,
                                  f"Bend-plane direction of the {side} joint (its X': the output shaft "
                                  f"leans towards -X'), vehicle {axis} component (its part along the shaft "
                                  "is dropped)", "1"))
    for axis, value in zip(AXES, (0.0, 1.0, 0.0)):
        found.append(Variable(f"motor_axis_{axis}", "parameter", value,
                              f"Axis of the motor's torque (crankshaft), vehicle {axis} component; also the "
                              "torque of the torque roll axis", "1"))
    return tuple(found)


def _motion() -> tuple[Variable, ...]:
    """Displacements and velocities (the states), accelerations: zero at initialisation, the model
    starting at rest in the equilibrium under the start inputs."""
    names = {0: "Displacement", 1: "Velocity", 2: "Acceleration"}
    found = []
    for order, suffix in ((0, ""), (1, "_dot"), (2, "_ddot")):
        for name in COORDINATES:
            unit, display = _unit(name, order)
            what = f"of the centre of gravity along vehicle {name}" if name in AXES else \
                f"{name} (small rotation about vehicle {AXES[COORDINATES.index(name) - 3]})"
            found.append(Variable(f"{name}{suffix}", "output", 0.0,
                                  f"{names[order]} {what}, from the static equilibrium under the weight",
                                  unit, display, **({"depends_on": (*ACCELERATION_LOADS[name], *MOTION,
                                                                    *BRANCH_FORCES),
                                                     "initial_depends_on": ()} if order == 2 else {})))
    return tuple(found)


def _branches() -> tuple[Variable, ...]:
    """The Maxwell branches' forces (Model Exchange's states) and their rates (R2): a branch's rate depends on its
    force and the deflection rate along its axis, so on the velocities; both 0 at rest, where the model starts.
    Locals: internal states no host wires (the mount forces include them), readable, set only as Model Exchange's
    continuous states."""
    found = []
    for i, names in enumerate(MOUNT_BRANCHES, start=1):
        for name in names:
            k, j = name.split("_")[1][-1], name.split("_")[3][-1]
            text = (f"Force of Maxwell branch {j} of mount {i} along the mount's axis {k} (rubber damping: it adds to "
                    "the spring's force, which the mount exerts on the powertrain with the opposite sign; 0 for a "
                    "mount without dynamic_ratio or beyond the layout's)")
            found.append(Variable(name, "local", 0.0, text, "N"))
            found.append(Variable(f"{name}_dot", "local", 0.0,
                                  f"Rate of {name}: its spring's rate times the deflection rate, less the force over "
                                  "the branch's relaxation time", "N/s",
                                  depends_on=(name, *VELOCITIES), initial_depends_on=()))
    return tuple(found)


def _states() -> tuple[State, ...]:
    """Displacements starting in the equilibrium under the start inputs, velocities at rest (on progressive
    mounts that equilibrium's displacement from the weight's depends on the weight: g)."""
    return (*(State(name, (*LOADS, "g"), f"{name}_dot", NOMINALS[name]) for name in COORDINATES),
            *(State(f"{name}_dot", (), f"{name}_ddot", NOMINALS[name] * NOMINAL_RATE) for name in COORDINATES),
            *(State(name, (), f"{name}_dot", BRANCH_NOMINAL) for name in BRANCH_FORCES))


def _mounts() -> tuple[Variable, ...]:
    return tuple(
        Variable(f"F_{axis}_mount{i}", "output", 0.0,
                 f"Force of mount {i} on the powertrain along vehicle {axis}, the weight's preload included "
                 "(0 when the layout has fewer mounts)", "N",
                 depends_on=("layout", "g", *MOTION, *MOUNT_BRANCHES[i - 1]))
        for i in range(1, MAX_MOUNTS + 1) for axis in AXES)


def _statics_and_modes() -> tuple[Variable, ...]:
    """Static sag, modes and torque roll axis: functions of the parameters alone (the modes those of the
    operating point under the weight and T_mean about motor_axis: the tangent rates of progressive mounts
    and the rubber's branches there)."""
    found = []
    for name in COORDINATES:
        unit, display = _unit(name, 0)
        found.append(Variable(f"{name}_static", "output", 0.0,
                              f"Static sag {name} under the weight and T_mean, from the unloaded mounts",
                              unit, display, depends_on=STATICS))
    found.append(Variable("wind_up", "output", 0.0,
                          "Static rotation about motor_axis under T_mean, from the equilibrium under the weight "
                          "(positive along the reaction -T_mean)", "rad", "deg",
                          depends_on=STATICS))
    found += [Variable(f"f_mode_{j}", "output", 0.0,
                       f"Natural frequency of mode {j} (ascending) at the static equilibrium under the weight and "
                       "T_mean, with the rubber's storage stiffness at that frequency", "Hz", depends_on=STATICS)
              for j in range(1, 7)]
    found += [Variable(f"zeta_mode_{j}", "output", 0.0,
                       f"Damping ratio of mode {j} (modal strain energy: loss over twice the storage stiffness "
                       "at its frequency)", "1", depends_on=STATICS)
              for j in range(1, 7)]
    for j in range(1, 7):
        found.append(Variable(f"mode_{j}_coordinate", "output", 0,
                              f"Coordinate with the largest kinetic-energy share of mode {j}: {COORDINATE_INDEX}",
                              type="Integer", depends_on=STATICS))
        found.append(Variable(f"mode_{j}_share", "output", 0.0,
                              f"Kinetic-energy share of mode {j} in its dominant coordinate", "1",
                              depends_on=STATICS))
    found += [Variable(f"share_{j}_{name}", "output", 0.0,
                       f"Kinetic-energy share of coordinate {name} in mode {j} (each mode's shares sum to 1)", "1",
                       depends_on=STATICS)
              for j in range(1, 7) for name in COORDINATES]
    found += [Variable(f"torque_roll_axis_{axis}", "output", 0.0,
                       f"Torque roll axis (unit vector, vehicle {axis} component): the free powertrain's "
                       "rotation under a torque about motor_axis", "1", depends_on=("layout", *MOTOR_AXIS))
              for axis in AXES]
    found.append(Variable("mount_count", "output", 0, "Number of mounts in the layout", type="Integer",
                          depends_on=("layout",)))
    return tuple(found)


#: Each side's halfshaft in the package's design position: the left joint bent 8 deg on the 0.45 m shaft, the
#: right one 6 deg on the 0.70 m one, both in the vertical plane (psi 0: the bend plane X'Z' holds bend_*)
DESIGN = {"left": (0.45, math.radians(8.0)), "right": (0.70, math.radians(6.0))}
#: The plunge each joint allows from its housing's reference point O, both ways [m]
PLUNGE_TRAVEL = 0.025
HOUSING_MOTION = "housing_motion"


def _shaft_placement(side: str) -> tuple[str, ...]:
    """The parameters that place one side's halfshaft: its joint's centre and frame, its wheel."""
    return ("layout", *(f"{axis}_joint_{side}" for axis in AXES),
            *(f"{kind}_{axis}_{side}" for kind in ("shaft", "bend") for axis in AXES),
            f"l_{side}", f"beta_design_{side}", f"psi_design_{side}", f"plunge_design_{side}", HOUSING_MOTION)


def _halfshafts() -> tuple[Variable, ...]:
    """The wheels' places (by the design geometry), the joints' limits, the switch, and each side's
    geometry (:mod:`.halfshafts`): its angles and plunge from the motion, their rates from the velocities
    too, the second rates from the accelerations, so from the loads as well (direct feedthrough)."""
    found = [Variable(HOUSING_MOTION, "parameter", 1,
                      "1 = the halfshaft outputs (beta_left ... plunge_ddot_right) follow the powertrain's motion; "
                      "0 = they hold the design geometry (beta_design_*, psi_design_*, plunge_design_*; rates 0): "
                      "the joints' housings as if fixed", type="Integer", min=0, max=1)]
    for side in SIDES:
        length, beta = DESIGN[side]
        found += [
            Variable(f"l_{side}", "parameter", length,
                     f"Length L of the {side} halfshaft between its joints' centres (TripodCoupling's l)", "m", "mm",
                     min=0.0, min_exclusive=True),
            Variable(f"beta_design_{side}", "parameter", beta,
                     f"Bend angle of the {side} halfshaft with the powertrain at rest at q = 0 (the static "
                     "equilibrium under the weight): with psi_design, plunge_design and l it places the wheel's "
                     "joint centre, fixed to the body", "rad", "deg", min=0.0, max=BETA_LIMIT),
            Variable(f"psi_design_{side}", "parameter", 0.0,
                     f"Bend-plane angle of the {side} halfshaft about the housing's axis Z' at q = 0, from X' "
                     "(bend_*) towards Y' (0: the output shaft leans towards -X')", "rad", "deg",
                     min=-math.pi, max=math.pi),
            Variable(f"plunge_design_{side}", "parameter", 0.0,
                     f"Plunge of the {side} joint at q = 0: the spider's centre along Z' from the housing's "
                     "point O (x_joint_*)", "m", "mm"),
            Variable(f"beta_max_{side}", "parameter", math.radians(45.0),
                     f"Largest bend angle of the {side} joint (its TripodCoupling's beta_max)", "rad", "deg",
                     min=0.0, max=BETA_LIMIT),
            Variable(f"plunge_min_{side}", "parameter", -PLUNGE_TRAVEL,
                     f"Shortest plunge the {side} joint's housing allows (the spider towards the housing's bottom)",
                     "m", "mm"),
            Variable(f"plunge_max_{side}", "parameter", PLUNGE_TRAVEL,
                     f"Longest plunge the {side} joint's housing allows (the spider towards its mouth)", "m", "mm"),
        ]
    texts = {"beta": "Bend angle of the {side} halfshaft at its inboard joint",
             "psi": "Bend-plane angle of the {side} halfshaft about its housing's axis Z', from X' towards Y'",
             "plunge": "Plunge of the {side} joint: the spider's centre along Z' from the housing's point O"}
    units = {"beta": ("rad", "deg"), "psi": ("rad", "deg"), "plunge": ("m", "mm")}
    for side in SIDES:
        placed = _shaft_placement(side)
        for name in GEOMETRY:
            base = name.split("_")[0]
            order = {"": 0, "dot": 1, "ddot": 2}[name[len(base) + 1:]]
            unit, display = units[base]
            unit = unit if order == 0 else f"{unit}/s" if order == 1 else f"{unit}/s2"
            text = texts[base].format(side=side)
            if order:
                text = f"{('First', 'Second')[order - 1]} time derivative of the {text[0].lower()}{text[1:]}"
            depends = (*placed, *COORDINATES) if order == 0 else (*placed, *MOTION) if order == 1 else \
                (*placed, *PLACEMENT, *INPUTS, *MOTION, *BRANCH_FORCES)
            found.append(Variable(f"{name}_{side}", "output", 0.0, text, unit, display if order == 0 else None,
                                  depends_on=tuple(dict.fromkeys(depends)),
                                  **({"initial_depends_on": ()} if order else {})))
    return tuple(found)


RELATIONS = tuple(
    relation for side in SIDES for relation in (
        Relation(f"beta_design_{side}", "<=", f"beta_max_{side}", reason=f"the {side} joint's largest bend"),
        Relation(f"plunge_design_{side}", ">=", f"plunge_min_{side}", reason=f"the {side} joint's stroke"),
        Relation(f"plunge_design_{side}", "<=", f"plunge_max_{side}", reason=f"the {side} joint's stroke"),
    ))


SPEC = ModelSpec(
    name="PowertrainMounts",
    description=(
        "Rigid powertrain (six degrees of freedom) on 1 to 8 rubber mounts (linear or progressive, viscous or "
        "constant-loss-factor damping), small motion about its "
        "static equilibrium in vehicle axes (ISO 8855), loaded by two TripodCoupling housings, a motor's "
        "reaction torque and a free force and moment; exact time stepping (matrix exponential, zero- or "
        "first-order hold), modal table with the kinetic-energy decoupling and the torque roll axis."
    ),
    variables=(
        Variable("layout", "parameter", DEFAULT_LAYOUT,
                 "Powertrain and mounts (TOML): a file path ending in '.toml' (any case; a relative path is "
                 "relative to the importing process's working directory), or the name of a layout shipped "
                 f"in the FMU ('{RUBBER_LAYOUT}': rubber mounts; '{SHARED_LAYOUT}': the same powertrain on "
                 "linear springs and viscous dampers)", type="String"),
        Variable("g", "parameter", 9.81, "Gravitational acceleration (the weight along -z)", "m/s2", min=0.0),
        Variable("T_mean", "parameter", 0.0,
                 "Mean drive torque of the static sag outputs: the powertrain carries -T_mean about motor_axis",
                 "N.m"),
        *_geometry(),
        *_inputs(),
        *_motion(),
        *_mounts(),
        *_statics_and_modes(),
        # appended after every other variable: value references are positions
        *_halfshafts(),
        *_branches(),
    ),
    default_experiment=DefaultExperiment(0.0, 1.0, 1e-3),
    relations=RELATIONS,
    states=_states(),
)
