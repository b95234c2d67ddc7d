"""Driveline critical speeds by the transfer matrix method (seed: Hruby & Nahlik 2021).

Elements (:class:`ShaftSegment`, :class:`ConcentratedMass`, :class:`Bearing`) are
assembled into a :class:`Driveline`, whose frequency determinant is scanned for
whirl frequencies, critical speeds and order resonances; with bearing damping and
:class:`Unbalance`, :class:`damped.DampedRotor` gives the damped whirl and the
unbalance response (finite elements). Plain numpy/scipy; all speeds and frequencies
in rad/s.

Typical use::

    d = one_piece_shaft(1.4, 0.0762, 0.0729, 2.1e11, 7850.0, 2.5, 0.004, 0.002, 1e7)
    d.critical_speeds(3)                  # first three critical speeds (unbalance-excited)
    d.whirl_frequencies(500.0)            # forward / backward whirl at 500 rad/s
    d.nearest_order_resonance(300.0, orders=(1, 2))
"""

from .driveline import (
    CampbellDiagram,
    CriticalSpeed,
    Driveline,
    OrderResonance,
    WhirlFrequencies,
)
from .elements import Bearing, ConcentratedMass, EndCondition, Hinge, PointElement, ShaftSegment, Unbalance
from .loader import example_path, load_driveline, loads_driveline, one_piece_shaft
from .transfer import ModeShape

__all__ = [
    "Bearing",
    "CampbellDiagram",
    "ConcentratedMass",
    "CriticalSpeed",
    "Driveline",
    "EndCondition",
    "Hinge",
    "ModeShape",
    "OrderResonance",
    "PointElement",
    "ShaftSegment",
    "Unbalance",
    "WhirlFrequencies",
    "example_path",
    "load_driveline",
    "loads_driveline",
    "one_piece_shaft",
]
