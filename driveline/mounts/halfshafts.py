"""The halfshafts on the moving powertrain: each inboard joint's bend angle, bend-plane angle and plunge,
with their first and second rates, from the powertrain's motion (:mod:`driveline.halfshaft.geometry`).

Each joint's housing sits on the powertrain at its centre O, its frame X'Y'Z' that of
:func:`.joints.joint_frame`; the outboard joint's centre W sits at its wheel, fixed to the body. W is
placed by the design geometry: the halfshaft of length L bent by ``beta_design`` in the plane
``psi_design`` with the plunge ``plunge_design`` while the powertrain is at q = 0 (the static
equilibrium under the weight), the inverse of (H1)-(H3) (:func:`~driveline.halfshaft.geometry.design_wheel`).

The powertrain's motion is small (its equations are linear in q about that equilibrium), and so is the
pose of each housing here: to first order in q, turning the housing by ``theta`` and moving O by
``T(O) q`` places the wheel centre in the housing frame where moving O by the displacement of the
powertrain's point at W, ``T(W) q`` (:func:`.layout.point_map`), in the unturned frame does:

    a = F^T (W - O - T(W) q)        a' = -F^T T(W) q'        a'' = -F^T T(W) q''

(the terms dropped are of second order in the rotation, 1e-5 of a for the launch's 3 mrad). So the
housing's motion handed to (H1)-(H5) is its design frame F with O moving by ``T(W) q`` and no turn: the
rates are then the exact time derivatives of the angles and the plunge of the linearised pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..halfshaft.geometry import HousingMotion, ShaftGeometry, design_wheel, shaft_geometry
from .layout import point_map

#: The geometry's values in the order of the outputs of each side (``{name}_{side}``).
GEOMETRY = ("beta", "beta_dot", "beta_ddot", "psi", "psi_dot", "psi_ddot", "plunge", "plunge_dot", "plunge_ddot")


@dataclass(frozen=True)
class Halfshaft:
    """One side's halfshaft: the housing's design frame and centre, the wheel centre, the shaft's length,
    the map ``T(W)`` of the powertrain's motion to the displacement of its point at W, and the design
    geometry (its values with the housing held)."""

    frame: np.ndarray
    centre: np.ndarray
    wheel: np.ndarray
    length: float
    wheel_map: np.ndarray
    design: ShaftGeometry

    @classmethod
    def of(cls, frame: np.ndarray, centre: np.ndarray, centre_of_gravity: np.ndarray, length: float, beta: float,
           psi: float, plunge: float) -> Halfshaft:
        wheel = design_wheel(frame, centre, length, beta, psi, plunge)
        return cls(frame, np.asarray(centre, float), wheel, length, point_map(wheel, centre_of_gravity),
                   ShaftGeometry(beta, 0.0, 0.0, psi, 0.0, 0.0, plunge, 0.0, 0.0))

    def motion(self, q: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray) -> HousingMotion:
        """The housing's motion equivalent to the first order in ``q`` (module docstring)."""
        zero = np.zeros(3)
        return HousingMotion(self.frame, self.centre + self.wheel_map @ q, self.wheel_map @ velocity,
                             self.wheel_map @ acceleration, zero, zero)

    def geometry(self, q: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray) -> ShaftGeometry:
        """(H1)-(H5) at the powertrain's motion; GeometryError when the wheel centre lies beyond the shaft's
        reach from the housing's axis."""
        return shaft_geometry(self.motion(q, velocity, acceleration), self.wheel, self.length)


def values(found: ShaftGeometry) -> tuple[float, ...]:
    """The geometry in the order of :data:`GEOMETRY`."""
    return tuple(float(getattr(found, name)) for name in GEOMETRY)
