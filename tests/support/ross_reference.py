"""The project's rotors rebuilt in ROSS (ross-rotordynamics), the established reference.

Used by the tests (agreement of the critical speeds) and by the benchmark (time to the
same answer). ROSS is imported on first use; it is a test dependency, not a runtime one.
"""

from __future__ import annotations

import contextlib
import os
import sys
import warnings
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from driveline.rotor import Driveline


@contextlib.contextmanager
def _quiet_stdout() -> Iterator[None]:
    """Silence file descriptor 1, where compiled code prints too."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        try:
            yield
        finally:
            os.dup2(saved, 1)
            os.close(saved)


def _ross() -> Any:
    """Import ROSS quietly: it warns, and its CoolProp dependency prints a REFPROP notice."""
    with warnings.catch_warnings(), _quiet_stdout():
        warnings.simplefilter("ignore")
        import ross

    return ross


E, RHO = 2.1e11, 7850.0
#: Elements per metre of shaft in ROSS. Cubic Hermite elements converge as h**4;
#: at 24/m ROSS's first three critical speeds are within 2e-5 of their mesh limit
#: (measured: 3.4e-5 at 20/m, 2.1e-6 at 40/m for the worst case, mode 3 of (a)).
ELEMENTS_PER_METRE = 24
#: ROSS's run_critical_speed defaults to rtol = 0.5 %; tightened so that its own
#: Newton tolerance does not enter the comparison (1e-10 makes its secant steps
#: wander in round-off and only costs time).
ROSS_RTOL = 1e-8


def ross_rotor(d: Driveline) -> tuple[Any, list[int]]:
    """The same rotor in ROSS, and the ROSS node of each of our nodes: Timoshenko elements
    (Cowper's coefficient) where our segment has ``shear``, Rayleigh ones elsewhere; bearings
    with their stiffness, damping and cross-coupling."""
    rs = _ross()
    mat = rs.Material(name="steel_test", rho=RHO, E=E, Poisson=0.3)
    shaft, node_of_station = [], [0]
    for seg in d.segments:
        if (seg.youngs_modulus, seg.density, seg.poisson_ratio) != (E, RHO, 0.3):
            raise ValueError("the ROSS rebuild supports steel segments only (E = 2.1e11 Pa, rho = 7850 kg/m3, nu = 0.3)")
        n_el = max(4, int(np.ceil(seg.length * ELEMENTS_PER_METRE)))
        shaft += [
            rs.ShaftElement(
                seg.length / n_el, idl=seg.inner_diameter, odl=seg.outer_diameter, material=mat,
                shear_effects=seg.shear, shear_method_calc="cowper", rotary_inertia=True, gyroscopic=True,
            )
            for _ in range(n_el)
        ]
        node_of_station.append(node_of_station[-1] + n_el)
    disks = [
        rs.DiskElement(n=node_of_station[m.node], m=m.mass, Id=m.diametral_inertia, Ip=m.polar_inertia)
        for m in d.masses
    ]
    bearings = [
        rs.BearingElement(n=node_of_station[b.node], kxx=b.kxx, kyy=b.k_yy, kxy=b.kxy, kyx=b.kyx,
                          cxx=b.cxx, cyy=b.c_yy, cxy=b.cxy, cyx=b.cyx)
        for b in d.bearings
    ]
    return rs.Rotor(shaft, disk_elements=disks, bearing_elements=bearings), node_of_station


def _forward_fraction(vec: np.ndarray) -> tuple[float, float]:
    """(lateral share, forward share) of a ROSS eigenvector (dofs x, y, z, alpha, beta, theta).

    With ``x = Re(X e^{iwt})``, ``y = Re(Y e^{iwt})``, ``x + iy`` holds the forward
    circle ``(X + iY)/2 e^{iwt}`` and the backward circle ``conj(X - iY)/2 e^{-iwt}``.
    """
    x, y, z, th = vec[0::6], vec[1::6], vec[2::6], vec[5::6]
    lat = np.sum(np.abs(x) ** 2 + np.abs(y) ** 2)
    other = np.sum(np.abs(z) ** 2 + np.abs(th) ** 2)
    fwd = np.sum(np.abs(x + 1j * y) ** 2)
    bwd = np.sum(np.abs(x - 1j * y) ** 2)
    return lat / (lat + other), fwd / (fwd + bwd)


def ross_forward_critical_speeds(d: Driveline, n: int = 3) -> np.ndarray:
    """First ``n`` forward lateral critical speeds from ``run_critical_speed``, filtered."""
    rotor, _ = ross_rotor(d)
    num_modes = 4 * n  # n backward/forward pairs, each a complex-conjugate pair
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cs = rotor.run_critical_speed(num_modes=num_modes, rtol=ROSS_RTOL)
    out = []
    for i, speed in enumerate(cs.wn()):
        modal = rotor.run_modal(speed, num_modes=num_modes)
        # the entry's own mode is the one whose natural frequency equals the speed
        j = int(np.argmin(np.abs(modal.wn - speed)))
        lateral, forward = _forward_fraction(modal.evectors[: modal.ndof, j])
        if lateral > 0.9 and forward > 0.9:
            out.append(speed)
    out = np.unique(np.round(out, 9))
    if out.size < n:
        raise ArithmeticError(f"ROSS returned only {out.size} forward lateral critical speeds")
    return out[:n]


def ross_unbalance_response(d: Driveline, node: int, amount: float, phase: float, probe: int
                            ) -> Callable[[np.ndarray], np.ndarray]:
    """Major semi-axis [m] of the orbit at our node ``probe`` from ROSS's ``run_unbalance_response``
    for an unbalance ``amount`` [kg m] at ``phase`` [rad] on our node ``node``, as a function of the
    speeds (the ROSS rotor is built once)."""
    rotor, node_of_station = ross_rotor(d)
    dof = rotor.number_dof * node_of_station[probe]

    def major(spins: np.ndarray) -> np.ndarray:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            response = rotor.run_unbalance_response(node_of_station[node], amount, phase,
                                                    frequency=np.atleast_1d(np.asarray(spins, dtype=float)))
        x, y = response.forced_resp[dof], response.forced_resp[dof + 1]
        # x + i y = A exp(i W t) + B exp(-i W t), A = (X + i Y)/2, B = conj(X - i Y)/2
        return 0.5 * (np.abs(x + 1j * y) + np.abs(x - 1j * y))

    return major


def ross_damped_modes(d: Driveline, spin: float, num_modes: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """Damped natural frequencies ``wd`` [rad/s] and logarithmic decrements of ROSS's ``run_modal``."""
    rotor, _ = ross_rotor(d)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        modal = rotor.run_modal(spin, num_modes=num_modes)
    return np.asarray(modal.wd), np.asarray(modal.log_dec)
