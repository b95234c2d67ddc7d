"""All outputs of the coupling at once, for one configuration (an FMU step) or whole arrays.

The FMU's model and vectorised sweeps call the same function, so a sweep that needs no
time stepping gives exactly what stepping the FMU would, without a Python loop.
"""

from __future__ import annotations

from ..scalar import Real, arcsin
from . import closed_form, dynamics, plane_solver
from .geometry import orbit_radius
from .spec import EXACT

def coupling_outputs(
    phi_in: Real, beta: Real, omega_in: Real, T_load: Real, r: float, l: float, m: float,
    kinematics: int, solution: plane_solver.Solution | None = None,
) -> tuple[dict[str, Real], plane_solver.Solution | None]:
    """The ``TripodCoupling`` outputs (names as in the spec) and the exact solver's solution.

    ``solution`` warm-starts the exact solver (kinematics = 1) and is returned updated.
    """
    rho = orbit_radius(beta, r)
    if kinematics == EXACT:
        phi_out, ratio, solution = plane_solver.solve(phi_in, beta, r, l, solution)
        theta = solution.cone_angle
    else:
        deviation, ratio = closed_form.kinematics(phi_in, beta, r, l)
        phi_out = phi_in + deviation
        theta = arcsin(rho / l)
    a_sum, rz, rx, ry = dynamics.reactions(phi_in, beta, omega_in, rho, l, m)
    return {
        "phi_out": phi_out,
        "delta_phi": phi_out - phi_in,
        "omega_out": omega_in * ratio,
        "T_in": dynamics.input_torque(T_load, ratio),
        "F_pin": dynamics.pin_force(T_load, rho, r),
        "rho": rho,
        "theta": theta,
        "a_plunger_sum": a_sum,
        "Rz_out": rz,
        "Rx_in": rx,
        "Ry_in": ry,
    }, solution
