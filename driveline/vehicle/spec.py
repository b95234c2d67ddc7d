"""Interface of the ``VehicleDriveline`` FMU: the single source for the FMI 2.0 and 3.0 builds."""

from __future__ import annotations

import math

from ..variables import DefaultExperiment, ModelSpec, State, Variable, decade
from . import compact_car as car

POSITIVE = {"min": 0.0, "min_exclusive": True}
SIDES = ("left", "right")
# What the outputs are computed from (``depends_on``, the states among it): the case's and side gears'
# accelerations (eqs V1, V2), a halfshaft's torque (V3), a tyre's force (V5), the car's (V7, V8)
GEARS = ("ratio", "J_motor", "J_diff", "J_side", "T_motor", "T_in_left", "T_in_right")
HALFSHAFT = ("k_{side}", "c_{side}", "phi_out_{side}", "omega_out_{side}", "phi_wheel_{side}", "omega_wheel_{side}")
TYRE = ("m_vehicle", "grade", "front_share", "C_slip")
CAR = ("m_vehicle", "J_wheel", "r_wheel", "f_roll", "rho_air", "c_drag", "A_front", "grade", "v_low", "v_x")
ROLLING = ("v_start", "r_wheel")  # the start: rolling at v_start without slip
V_MAX = 150.0  # m/s, the fastest start: 540 km/h


EXPERIMENT = DefaultExperiment(0.0, 4.0, 1e-4)
URBAN_SPEED = 50.0 / 3.6  # m/s, the car's typical speed
DRIVE_TORQUE = car.MOTOR_PEAK_TORQUE * car.RATIO / 2.0  # N.m, one halfshaft's share of the motor's peak
#: The states' nominals (State.nominal), the decade of their typical magnitudes in the default car: the
#: speeds at URBAN_SPEED (the car's 13.9 m/s, the wheels' and side gears' 45 rad/s), the distance
#: travelled over the default experiment at that speed (56 m), the wheel's angle as the halfshaft's twist
#: under DRIVE_TORQUE (what the wheel's motion against the joint's output is made of: 0.16 rad left,
#: 0.25 rad right; a wheel that rolls winds it past that, where the relative tolerance governs), the
#: slip that carries DRIVE_TORQUE (0.044)
NOMINALS = {
    "v_x": decade(URBAN_SPEED),
    "omega": decade(URBAN_SPEED / car.WHEEL_RADIUS),
    "x": decade(URBAN_SPEED * (EXPERIMENT.stop_time - EXPERIMENT.start_time)),
    "phi_wheel": decade(DRIVE_TORQUE / max(car.TORSIONAL_STIFFNESS_LEFT, car.TORSIONAL_STIFFNESS_RIGHT)),
    "slip": decade(DRIVE_TORQUE / (car.WHEEL_RADIUS * car.SLIP_STIFFNESS)),
}


def _side(names: tuple[str, ...], side: str) -> tuple[str, ...]:
    return tuple(name.format(side=side) for name in names)


def _per_side(name: str, causality: str, start: tuple[float, float] | float, text: str, unit: str | None,
              display: str | None = None, depends_on: tuple[str, ...] | None = None,
              initial_depends_on: tuple[str, ...] | None = None, **bounds: float | bool) -> tuple[Variable, ...]:
    """A variable per side; ``{side}`` in its text and dependencies is the side's name."""
    starts = start if isinstance(start, tuple) else (start, start)
    return tuple(Variable(f"{name}_{side}", causality, value, text.format(side=side), unit, display,
                          depends_on=None if depends_on is None else _side(depends_on, side),
                          initial_depends_on=None if initial_depends_on is None else _side(initial_depends_on, side),
                          **bounds)
                 for side, value in zip(SIDES, starts))


SPEC = ModelSpec(
    name="VehicleDriveline",
    description=(
        "Front-wheel drive between the motor and the road without the joints: motor, reduction gear and "
        "open differential inertia, halfshafts (torsional stiffness and damping from each joint's output "
        "angle to its wheel), wheels, tyres with transient slip saturating at the road's friction, the car's "
        "mass, rolling resistance, drag and grade. Each joint's quantities in its own frame (Z' towards its "
        "wheel: forward, the right joint turns negatively). Defaults: a 2011 Nissan Leaf."
    ),
    variables=(
        Variable("ratio", "parameter", car.RATIO, "Overall ratio i: motor speed / differential case speed", "1",
                 **POSITIVE),
        Variable("J_motor", "parameter", car.MOTOR_INERTIA, "Motor rotor inertia (with the gear's input shaft)",
                 "kg.m2", min=0.0),
        Variable("J_diff", "parameter", car.DIFFERENTIAL_INERTIA,
                 "Differential case and final gear inertia, at the case's speed", "kg.m2", min=0.0),
        Variable("J_side", "parameter", car.SIDE_INERTIA,
                 "Inertia of one side gear with the joint's housing, at its own speed (the differential's "
                 "internal degree of freedom)", "kg.m2", **POSITIVE),
        *_per_side("k", "parameter", (car.TORSIONAL_STIFFNESS_LEFT, car.TORSIONAL_STIFFNESS_RIGHT),
                   "Torsional stiffness of the {side} halfshaft, joint output to wheel", "N.m/rad", min=0.0),
        *_per_side("c", "parameter", car.TORSIONAL_DAMPING, "Torsional damping of the {side} halfshaft",
                   "N.m.s/rad", min=0.0),
        Variable("J_wheel", "parameter", car.WHEEL_INERTIA,
                 "Polar inertia of one wheel with its tyre (front and rear alike)", "kg.m2", **POSITIVE),
        Variable("r_wheel", "parameter", car.WHEEL_RADIUS, "Rolling radius of the tyres", "m", "mm", **POSITIVE),
        Variable("m_vehicle", "parameter", car.MASS, "Mass of the car with its load", "kg", **POSITIVE),
        Variable("front_share", "parameter", car.FRONT_SHARE, "Front axle's share of the weight", "1",
                 min=0.0, max=1.0, min_exclusive=True),
        Variable("C_slip", "parameter", car.SLIP_STIFFNESS,
                 "Longitudinal slip stiffness of one front tyre: force per unit slip at small slip", "N", **POSITIVE),
        Variable("sigma_slip", "parameter", car.RELAXATION_LENGTH, "Relaxation length of the longitudinal slip",
                 "m", "mm", **POSITIVE),
        *_per_side("mu_road", "parameter", car.ROAD_FRICTION,
                   "Tyre-road friction coefficient under the {side} front wheel", "1", **POSITIVE),
        Variable("f_roll", "parameter", car.ROLLING_RESISTANCE, "Rolling resistance coefficient", "1", min=0.0),
        Variable("rho_air", "parameter", car.AIR_DENSITY, "Air density", "kg/m3", min=0.0),
        Variable("c_drag", "parameter", car.DRAG_COEFFICIENT, "Aerodynamic drag coefficient", "1", min=0.0),
        Variable("A_front", "parameter", car.FRONTAL_AREA, "Frontal area", "m2", min=0.0),
        Variable("grade", "parameter", 0.0, "Road grade angle, uphill positive", "rad", "deg",
                 min=-math.radians(30.0), max=math.radians(30.0)),
        Variable("v_low", "parameter", 0.1,
                 "Low-speed regularisation: the slip's speed |v| + v_low, rolling resistance's sign tanh(v / v_low)",
                 "m/s", "km/h", **POSITIVE),
        Variable("v_start", "parameter", 0.0, "Car speed at the start time (rolling without slip), within 540 km/h "
                 "either way: beyond any road car (the drag's v |v| overflows from 1e154 m/s on)", "m/s", "km/h",
                 min=-V_MAX, max=V_MAX),
        Variable("T_motor", "input", 0.0, "Motor torque on its rotor, forward positive", "N.m"),
        *_per_side("T_in", "input", 0.0,
                   "Torque the {side} joint takes from its input shaft, the side gear (the joint's T_in)", "N.m"),
        *_per_side("phi_out", "input", 0.0,
                   "Output shaft angle of the {side} joint (the joint's phi_out), moving at omega_out over the step",
                   "rad", "deg"),
        *_per_side("omega_out", "input", 0.0, "Output shaft speed of the {side} joint (the joint's omega_out)",
                   "rad/s", "rpm"),
        *_per_side("omega_in", "output", 0.0, "Speed of the {side} side gear, the joint's input shaft",
                   "rad/s", "rpm"),
        *_per_side("alpha_in", "output", 0.0, "Angular acceleration of the {side} side gear", "rad/s2",
                   depends_on=GEARS),
        *_per_side("T_load", "output", 0.0, "Torque in the {side} halfshaft, the joint's load torque", "N.m",
                   depends_on=HALFSHAFT, initial_depends_on=("c_{side}", "omega_out_{side}", "omega_wheel_{side}")),
        Variable("T_reaction", "output", 0.0,
                 "Torque of the drive's rotating parts on the powertrain housing about the axle direction "
                 "(y): minus both joints' T_in, minus the rate of the parts' angular momentum", "N.m",
                 depends_on=GEARS),
        Variable("omega_motor", "output", 0.0, "Motor speed", "rad/s", "rpm",
                 depends_on=("ratio", "omega_in_left", "omega_in_right")),
        *_per_side("omega_wheel", "output", 0.0, "Speed of the {side} front wheel", "rad/s", "rpm"),
        *_per_side("F_x", "output", 0.0, "Longitudinal force of the road on the {side} front tyre", "N",
                   depends_on=(*TYRE, "mu_road_{side}", "slip_{side}"), initial_depends_on=()),
        *_per_side("slip", "output", 0.0, "Transient longitudinal slip of the {side} front tyre", "1"),
        Variable("v_x", "output", 0.0, "Car speed", "m/s", "km/h"),
        Variable("a_x", "output", 0.0, "Car acceleration", "m/s2", depends_on=(*CAR, *TYRE[2:], "mu_road_left",
                 "mu_road_right", "slip_left", "slip_right"), initial_depends_on=CAR),
        Variable("x", "output", 0.0, "Distance travelled from the start", "m"),
        *_per_side("phi_wheel", "output", 0.0, "Angle of the {side} front wheel (from the joint's phi_out at the "
                   "start: the halfshaft untwisted)", "rad", "deg"),
        *_per_side("alpha_wheel", "output", 0.0, "Angular acceleration of the {side} front wheel", "rad/s2",
                   depends_on=(*HALFSHAFT, "J_wheel", "r_wheel", *TYRE, "mu_road_{side}", "slip_{side}"),
                   initial_depends_on=("c_{side}", "omega_out_{side}", "omega_wheel_{side}", "J_wheel")),
        *_per_side("slip_dot", "output", 0.0, "Rate of the {side} front tyre's transient slip (eq V6)", "1/s",
                   depends_on=("r_wheel", "v_low", "sigma_slip", "omega_wheel_{side}", "v_x", "slip_{side}"),
                   initial_depends_on=()),
    ),
    # the Model Exchange states: dynamics.py's state, the case's and the differential's speeds as the side
    # gears' (omega_in_left = case + diff, omega_in_right = -(case - diff)), with their nominals (NOMINALS)
    states=(*(State(f"omega_in_{side}", ROLLING, f"alpha_in_{side}", NOMINALS["omega"]) for side in SIDES),
            *(state for side in SIDES for state in (State(f"phi_wheel_{side}", (f"phi_out_{side}",),
                                                          f"omega_wheel_{side}", NOMINALS["phi_wheel"]),
                                                    State(f"omega_wheel_{side}", ROLLING, f"alpha_wheel_{side}",
                                                          NOMINALS["omega"]))),
            State("v_x", ("v_start",), "a_x", NOMINALS["v_x"]), State("x", (), "v_x", NOMINALS["x"]),
            *(State(f"slip_{side}", (), f"slip_dot_{side}", NOMINALS["slip"]) for side in SIDES)),
    default_experiment=EXPERIMENT,
)
