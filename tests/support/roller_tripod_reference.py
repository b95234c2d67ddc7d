"""An independent computation of the roller tripods' contacts (docs/tripod_coupling.md, "Roller
tripods"), written from the docs' equations, not from driveline.tripod.rollers:

* pose from the Newton closure (driveline.tripod.exact), not the plane solver;
* velocities and accelerations of the output shaft, the rollers along their grooves and along their
  trunnions from the closure differentiated as vectors, ``S' + Omega x d_j + sdot_j a_j = omega e_z x
  g_j + zdot_j e_z`` and its derivative, each a 9 x 9 linear system (numpy's solve);
* the single roller's slips from absolute velocities: the roller turns at ``Omega + omega_r a_j``,
  ``omega_r`` such that its contact point does not slip along the rolling direction, and the slip is
  its velocity less the track's at the contact point;
* the double roller's needles from absolute angular velocities: the outer roller's, such that its
  contact point rests on the track along it, against the inner ring's, the tripod's; their friction's
  moment about the outer roller's axis balanced by the track's tangential force (its spin balance);
* the forces as 15 unknowns per configuration (the three force vectors on the arms, the three
  horizontal normal forces of the tracks) and 15 equations (the tripod's moments about S, the friction
  law along each trunnion, each roller's force balance), solved by scipy's ``root``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import root

from driveline.tripod import exact, geometry
from driveline.tripod.reactions import slip_sign

EZ = np.array([0.0, 0.0, 1.0])
HORIZONTAL = np.array([1.0, 1.0, 0.0])


@dataclass
class Case:
    """One configuration of the joint and its parameters."""

    tripod_type: int
    phi_in: float
    beta: float
    omega: float
    omega_dot: float
    T_load: float
    r: float
    l: float
    m: float
    mu: float
    mu_roll: float
    slip_speed: float
    roller_radius: float
    beta_dot: float = 0.0
    beta_ddot: float = 0.0
    roller_bore_radius: float = 0.0


def random_case(rng: np.random.Generator, tripod_type: int) -> Case:
    """A configuration drawn over the ranges a driveline meets, either sense of speed and torque."""
    case = Case(
        tripod_type=tripod_type, phi_in=rng.uniform(0.0, 2.0 * np.pi), beta=np.radians(rng.uniform(1.0, 40.0)),
        omega=rng.choice((-1.0, 1.0)) * rng.uniform(20.0, 600.0), omega_dot=rng.uniform(-500.0, 500.0),
        T_load=rng.uniform(-600.0, 600.0), r=rng.uniform(0.018, 0.04), l=rng.uniform(0.3, 1.0),
        m=rng.uniform(0.0, 0.5), mu=rng.uniform(0.0, 0.15), mu_roll=rng.uniform(0.0, 0.01),
        slip_speed=10.0 ** rng.uniform(-4.0, -2.0), roller_radius=rng.uniform(0.01, 0.02),
        beta_dot=rng.uniform(-2.0, 2.0), beta_ddot=rng.uniform(-20.0, 20.0),
    )
    if tripod_type == 2:  # the needles' bore, below the smallest outer radius drawn
        case.roller_bore_radius = rng.uniform(0.004, 0.009)
    return case


def _skew(v: np.ndarray) -> np.ndarray:
    """The matrix of ``v x``."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _unit(v: np.ndarray) -> np.ndarray:
    size = np.linalg.norm(v)
    return v / size if size > 0.0 else v


def motion(case: Case) -> dict[str, np.ndarray]:
    """Pose, velocities and accelerations from the Newton closure and two 9 x 9 systems."""
    pose = exact.exact_pose(np.array([case.phi_in]), case.beta, case.r, case.l)
    sb, cb = np.sin(case.beta), np.cos(case.beta)
    S = case.l * np.array([-sb, 0.0, cb])
    e_beta = np.array([-cb, 0.0, -sb])
    S_dot = case.l * case.beta_dot * e_beta
    S_ddot = case.l * (case.beta_ddot * e_beta - case.beta_dot**2 * np.array([-sb, 0.0, cb]))
    P = pose.tripod_centre[0]
    U = (S - P) / case.l
    angles = case.phi_in + geometry.THIRD_TURN * geometry.ARM_INDEX
    g = np.stack([case.r * np.cos(angles), case.r * np.sin(angles), np.zeros(3)], -1)
    b = g + pose.plunger_positions[0][:, None] * EZ
    a = np.array([_unit(bj - P) for bj in b])
    d = b - S
    # S' + Omega x d_j + sdot_j a_j - zdot_j e_z = omega e_z x g_j: unknowns (Omega, zdot, sdot)
    A = np.zeros((9, 9))
    for j in range(3):
        A[3 * j:3 * j + 3, 0:3] = -_skew(d[j])
        A[3 * j:3 * j + 3, 3 + j] = -EZ
        A[3 * j:3 * j + 3, 6 + j] = a[j]
    rhs = np.concatenate([case.omega * np.cross(EZ, g[j]) - S_dot for j in range(3)])
    x = np.linalg.solve(A, rhs)
    Omega, zdot, sdot = x[0:3], x[3:6], x[6:9]
    # the derivative: S'' + Omega' x d + Omega x (Omega x d + sdot a) + sddot a + sdot Omega x a
    #                 = omega' e_z x g - omega^2 g_xy + zddot e_z
    rhs = []
    for j in range(3):
        groove = case.omega_dot * np.cross(EZ, g[j]) - case.omega**2 * g[j]
        tripod = S_ddot + np.cross(Omega, np.cross(Omega, d[j]) + sdot[j] * a[j]) + sdot[j] * np.cross(Omega, a[j])
        rhs.append(groove - tripod)
    x = np.linalg.solve(A, np.concatenate(rhs))
    zddot = x[3:6]
    acceleration = np.array([case.omega_dot * np.cross(EZ, g[j]) - case.omega**2 * g[j] + zddot[j] * EZ
                             for j in range(3)])
    return dict(S=S, S_dot=S_dot, P=P, U=U, g=g, b=b, a=a, d=d, Omega=Omega, zdot=zdot, sdot=sdot, zddot=zddot,
                acceleration=acceleration)


def track_contact(case: Case, mo: dict, j: int, normal: np.ndarray) -> dict[str, np.ndarray | float]:
    """The track's friction force and moment about b_j on roller j, and the slips, for the horizontal
    normal force vector ``normal`` of the track on the roller."""
    N = np.linalg.norm(normal)
    k = _unit(normal)
    b, a, zdot = mo["b"][j], mo["a"][j], mo["zdot"][j]
    R = case.roller_radius
    contact = b - R * k
    centre_velocity = case.omega * np.cross(EZ, mo["g"][j]) + zdot * EZ  # the roller's centre on its groove
    track_velocity = case.omega * np.cross(EZ, contact)
    if case.tripod_type == 2:  # outer roller parallel to the track: rolls along it at zdot
        F_roll = -case.mu_roll * N * slip_sign(zdot, case.slip_speed)
        # it turns about its horizontal axis normal to k, so fast that its contact point rests on the track
        axis_o = np.cross(k, EZ)

        def rest(spin: float) -> float:
            return (centre_velocity + np.cross(case.omega * EZ + spin * axis_o, contact - b) - track_velocity) @ EZ

        outer = case.omega * EZ - rest(0.0) / (rest(1.0) - rest(0.0)) * axis_o  # its angular velocity
        # the needles move with the inner ring, which turns with the tripod (Omega): their slip along the
        # ring's axis a over the outer roller's bore, under the loaded needle at b - r_b k
        needle = -case.roller_bore_radius * k
        v_needle = np.cross(mo["Omega"] - outer, needle) @ a
        F_needle = case.mu * N * slip_sign(v_needle, case.slip_speed) * a  # their friction on the outer roller
        # the outer roller's spin balance about axis_o: the needles' friction at the bore, the track's
        # tangential force along e_z at the contact; the inner ring passes the needles' moment to the trunnion
        tangential = -(np.cross(needle, F_needle) @ axis_o) / (np.cross(contact - b, EZ) @ axis_o)
        return dict(N=N, k=k, friction=(F_roll + tangential) * EZ, moment=np.cross(needle, -F_needle), v_roll=zdot,
                    v_skew=v_needle, F_roll=F_roll, F_skew=-(F_needle @ a))
    along = np.cross(a, k)
    u = _unit(along)
    s = np.cross(k, u)

    def slip(omega_r: float) -> np.ndarray:
        return centre_velocity + np.cross(mo["Omega"] + omega_r * a, contact - b) - track_velocity

    # the roller turns freely on the trunnion: no slip along u (linear in omega_r)
    omega_r = -(slip(0.0) @ u) / ((slip(1.0) - slip(0.0)) @ u)
    spin_on_track = (mo["Omega"] + omega_r * a - case.omega * EZ) @ a
    v_roll = R * np.linalg.norm(along) * spin_on_track
    v_skew = slip(omega_r) @ s
    F_roll = -case.mu_roll * N * slip_sign(v_roll, case.slip_speed)
    F_skew = -case.mu * N * slip_sign(v_skew, case.slip_speed)
    friction = F_roll * u + F_skew * s
    # moments about b: the contact forces at R k from it, and the rolling resistance's couple about a,
    # as large as the spin on the needles needs (no moment about a)
    moment = np.cross(contact - b, friction)
    moment = moment - (moment @ a) * a
    return dict(N=N, k=k, friction=friction, moment=moment, v_roll=v_roll, v_skew=v_skew, F_roll=F_roll,
                F_skew=F_skew)


def solve(case: Case) -> dict[str, np.ndarray | float]:
    """Contacts, slips and reactions of one configuration."""
    mo = motion(case)

    def contacts(unknowns: np.ndarray) -> list[dict]:
        normals = unknowns[9:].reshape(3, 2)
        return [track_contact(case, mo, j, np.array([normals[j, 0], normals[j, 1], 0.0])) for j in range(3)]

    def residual(unknowns: np.ndarray) -> np.ndarray:
        F = unknowns[:9].reshape(3, 3)
        tracks = contacts(unknowns)
        moment = sum(np.cross(mo["d"][j], F[j]) + tracks[j]["moment"] for j in range(3)) - case.T_load * mo["U"]
        along = np.sum(F * mo["a"], axis=1)
        trunnion = along - case.mu * np.linalg.norm(F - along[:, None] * mo["a"], axis=1) * slip_sign(
            mo["sdot"], case.slip_speed)
        roller = [np.concatenate([tracks[j]["N"] * tracks[j]["k"][:2], [0.0]]) + tracks[j]["friction"] - F[j]
                  - case.m * mo["acceleration"][j] for j in range(3)]
        return np.concatenate([moment / case.l, trunnion, np.concatenate(roller)])

    start = np.zeros(15)
    for j in range(3):  # the load's share on each arm, normal to arm and groove
        n = _unit(np.cross(mo["a"][j], EZ))
        start[3 * j:3 * j + 3] = -case.T_load / (3.0 * case.r) * n
        start[9 + 2 * j:11 + 2 * j] = start[3 * j:3 * j + 2]
    solution = root(residual, start, method="hybr", options={"xtol": 1e-15, "maxfev": 20000})
    F = solution.x[:9].reshape(3, 3)
    tracks = contacts(solution.x)
    along = np.sum(F * mo["a"], axis=1)
    track_forces = np.array([t["N"] * np.array([t["k"][0], t["k"][1], 0.0]) + t["friction"] for t in tracks])
    moments_O = sum(np.cross(mo["b"][j], track_forces[j]) + tracks[j]["moment"] for j in range(3))
    return dict(
        residual=np.abs(residual(solution.x)).max(),
        F=F, N_track=np.array([t["N"] for t in tracks]), N_trunnion=np.linalg.norm(F - along[:, None] * mo["a"], axis=1),
        F_trunnion=along, F_roll=np.array([t["F_roll"] for t in tracks]), F_skew=np.array([t["F_skew"] for t in tracks]),
        v_trunnion=mo["sdot"], v_roll=np.array([t["v_roll"] for t in tracks]),
        v_skew=np.array([t["v_skew"] for t in tracks]), zdot=mo["zdot"],
        R_in=track_forces.sum(axis=0), M_in=moments_O, R_out=-F.sum(axis=0), Omega=mo["Omega"], U=mo["U"],
        P_friction=float(np.sum(along * mo["sdot"]) - sum(t["F_roll"] * t["v_roll"] + t["F_skew"] * t["v_skew"]
                                                          for t in tracks)),
    )
