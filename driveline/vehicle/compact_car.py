"""The default car of ``VehicleDriveline``: a compact (C-segment) electric front-wheel-drive hatchback,
the 2011 Nissan Leaf (ZE0), with the source of each number; what no maker publishes is estimated
and said so (docs/vehicle_driveline.md lists them).
"""

from __future__ import annotations

import math

#: Overall ratio motor speed / differential case speed, the single-speed reduction gear (Nissan Leaf
#: press kit 2010, "reduction gear ratio 7.9377").
RATIO = 7.9377
#: Motor peak torque [N.m] (Nissan Leaf press kit 2010: EM61 motor, 80 kW, 280 N.m).
MOTOR_PEAK_TORQUE = 280.0
#: Kerb mass about 1,520 kg (Nissan's data for the 2011 model, 1,493 to 1,525 kg by trim) plus a 75 kg
#: driver [kg].
MASS = 1520.0 + 75.0
#: Drag coefficient (Nissan Leaf press kit 2010: Cd 0.28).
DRAG_COEFFICIENT = 0.28
#: Frontal area [m2]: width 1.770 m times height 1.550 m (press kit) times 0.84, an estimate of the
#: share of the bounding rectangle a hatchback's silhouette fills.
FRONTAL_AREA = 1.770 * 1.550 * 0.84
#: Tyre 205/55 R16 (press kit): unloaded radius 0.5 (16 x 25.4 mm) + 0.55 x 205 mm = 0.316 m; the
#: rolling radius is taken 3 % less (the tyre's deflection under load, estimated) [m].
WHEEL_RADIUS = 0.97 * (0.5 * 16.0 * 0.0254 + 0.55 * 0.205)
#: Front axle's share of the weight, estimated for a front-motor car (unpublished).
FRONT_SHARE = 0.58
#: Rolling resistance coefficient of a low-resistance passenger-car tyre on asphalt (passenger-car
#: tyres lie between about 0.008 and 0.015; estimated).
ROLLING_RESISTANCE = 0.010
#: Air density at 20 deg C and 1013 hPa [kg/m3].
AIR_DENSITY = 1.204
#: Tyre-road friction coefficient, dry asphalt (peak values of 0.9 to 1.2 are usual).
ROAD_FRICTION = 1.0
#: Longitudinal slip stiffness [N per unit slip], estimated as 18 times the static front wheel load
#: (about 4,500 N), a usual ratio for passenger-car tyres.
SLIP_STIFFNESS = 18.0 * MASS * 9.80665 * FRONT_SHARE / 2.0
#: Longitudinal relaxation length [m], estimated: of the order of the contact length.
RELAXATION_LENGTH = 0.2
#: Wheel and tyre 205/55 R16 polar inertia [kg.m2], estimated.
WHEEL_INERTIA = 0.9
#: Motor rotor inertia [kg.m2], estimated for an 80 kW permanent-magnet machine (unpublished).
MOTOR_INERTIA = 0.035
#: Differential case with the final gear, at the case's speed [kg.m2], estimated.
DIFFERENTIAL_INERTIA = 0.06
#: One side gear with its half of the spider gears and the tripod housing, at its own speed [kg.m2],
#: estimated.
SIDE_INERTIA = 0.015
#: Halfshafts: solid steel bars of 25 mm, shear modulus 80 GPa, the left 0.45 m and the right 0.70 m
#: long (transverse layout with the differential left of centre): k = G pi d^4 / (32 L) [N.m/rad].
SHEAR_MODULUS = 80e9
SHAFT_DIAMETER = 0.025
SHAFT_LENGTH_LEFT, SHAFT_LENGTH_RIGHT = 0.45, 0.70
TORSIONAL_STIFFNESS_LEFT, TORSIONAL_STIFFNESS_RIGHT = (
    SHEAR_MODULUS * math.pi * SHAFT_DIAMETER**4 / (32.0 * length) for length in (SHAFT_LENGTH_LEFT, SHAFT_LENGTH_RIGHT)
)
#: Halfshaft torsional damping [N.m.s/rad]: about 3 % of critical damping of a wheel on the left shaft.
TORSIONAL_DAMPING = 0.03 * 2.0 * math.sqrt(TORSIONAL_STIFFNESS_LEFT * WHEEL_INERTIA)
