"""All outputs of the coupling at once, for one configuration (an FMU step) or whole arrays.

The FMU's model and vectorised sweeps call the same function, so a sweep that needs no
time stepping gives exactly what stepping the FMU would, without a Python loop.
"""

from __future__ import annotations

import numpy as np

from ..scalar import Real, arcsin
from . import closed_form, dynamics, plane_solver
from .geometry import orbit_radius
from .reactions import exact_reactions
from .reactions_closed_form import leading_order_reactions
from .spec import EXACT

ARMS = ("1", "2", "3")


def efficiency(output_power: Real, loss: Real) -> Real:
    """``P_out / (P_out + P_friction)`` with ``P_out = T_load omega_spin``; 1 where no power flows."""
    total = output_power + loss
    if type(total) is float:
        return output_power / total if total else 1.0
    return np.divide(output_power, total, out=np.ones_like(total), where=total != 0)


def coupling_outputs(
    phi_in: Real, beta: Real, omega_in: Real, T_load: Real, r: float, l: float, m: float,
    kinematics: int, solution: plane_solver.Solution | None = None,
    alpha_in: Real = 0.0, seed_reactions: int = 0, mu: float = 0.0, v_slip: float = 1e-3,
) -> tuple[dict[str, Real], plane_solver.Solution | None]:
    """The ``TripodCoupling`` outputs (names as in the spec) and the exact solver's solution.

    ``solution`` warm-starts the exact solver (kinematics = 1) and is returned updated.
    ``kinematics = 1`` gives the exact reactions (:mod:`.reactions`), 0 their closed forms
    (:mod:`.reactions_closed_form`); ``seed_reactions = 1`` replaces ``a_plunger_sum``,
    ``Rz_out``, ``Rx_in`` and ``Ry_in`` by the seed's eqs 20, 30, 33 and 34 as printed.
    ``mu`` > 0 (exact mode only) adds Coulomb friction regularised over ``v_slip`` [m/s].
    """
    rho = orbit_radius(beta, r)
    pin = dynamics.pin_force(T_load, rho, r)
    if kinematics == EXACT:
        phi_out, ratio, solution = plane_solver.solve(phi_in, beta, r, l, solution)
        theta = solution.cone_angle
        forces = exact_reactions(phi_in, beta, omega_in, alpha_in, T_load, r, l, m, solution.x, solution.y, mu, v_slip)
        omega_spin, axial_in, loss = forces.omega_spin, forces.Rz_in, forces.P_friction
    else:
        deviation, ratio = closed_form.kinematics(phi_in, beta, r, l)
        phi_out = phi_in + deviation
        theta = arcsin(rho / l)
        forces = leading_order_reactions(phi_in, beta, omega_in, alpha_in, T_load, r, l, m, ratio, pin)
        omega_spin, axial_in, loss = omega_in * ratio, 0.0 * ratio, 0.0 * ratio
    output_power = T_load * omega_spin
    values = {
        "phi_out": phi_out,
        "delta_phi": phi_out - phi_in,
        "omega_out": omega_in * ratio,
        "omega_spin": omega_spin,
        "T_in": forces.T_in,
        "F_pin": pin,
        "rho": rho,
        "theta": theta,
        "a_plunger_sum": forces.a_plunger_sum,
        "Rz_out": forces.Rz_out,
        "Rx_out": forces.Rx_out,
        "Ry_out": forces.Ry_out,
        "Rx_in": forces.Rx_in,
        "Ry_in": forces.Ry_in,
        "Mx_in": forces.Mx_in,
        "My_in": forces.My_in,
        "Rz_in": axial_in,
        "P_friction": loss,
        "efficiency": efficiency(output_power, loss),
    }
    for arm, f_arm, f_plunger in zip(ARMS, forces.F_arm, forces.F_plunger):
        values["F_arm" + arm] = f_arm
        values["F_plunger" + arm] = f_plunger
    if seed_reactions:
        seed = dynamics.reactions(phi_in, beta, omega_in, rho, l, m)
        values.update(a_plunger_sum=seed.a_plunger_sum, Rz_out=seed.Rz_out, Rx_in=seed.Rx_in, Ry_in=seed.Ry_in)
    return values, solution
