"""Forward critical speeds against ROSS (finite elements, Rayleigh beams, fine mesh).

ROSS is an optional test dependency: the module is skipped when it is missing.
ROSS results are computed once per module (they take seconds, ours milliseconds).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from driveline.rotor import (
    Bearing,
    Driveline,
    ShaftSegment,
    example_path,
    load_driveline,
    one_piece_shaft,
)

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    rs = pytest.importorskip("ross")

E, RHO = 2.1e11, 7850.0
#: Elements per metre of shaft in ROSS. Cubic Hermite elements converge as h**4;
#: at 24/m ROSS's first three critical speeds are within 2e-5 of their mesh limit
#: (measured: 3.4e-5 at 20/m, 2.1e-6 at 40/m for the worst case, mode 3 of (a)).
ELEMENTS_PER_METRE = 24
#: ROSS's run_critical_speed defaults to rtol = 0.5 %; tightened so that its own
#: Newton tolerance does not enter the comparison (1e-10 makes its secant steps
#: wander in round-off and only costs time).
ROSS_RTOL = 1e-8
#: Required agreement. The brief asks for 0.5 %; we measure 2e-8 to 2e-5 (both
#: models are Rayleigh beams; the rest is ROSS's mesh error, falling as h**4), so
#: 1e-4 keeps a margin for ROSS's discretisation while still catching modelling
#: errors: a wrong gyroscopic sign moves these forward critical speeds by 1-4 %.
REL_TOL = 1e-4


def _ross_rotor(d: Driveline):
    """The same rotor in ROSS: shear off (Rayleigh beam), undamped bearings."""
    mat = rs.Material(name="steel_test", rho=RHO, E=E, Poisson=0.3)
    shaft, node_of_station = [], [0]
    for seg in d.segments:
        assert seg.youngs_modulus == E and seg.density == RHO
        n_el = max(4, int(np.ceil(seg.length * ELEMENTS_PER_METRE)))
        shaft += [
            rs.ShaftElement(
                seg.length / n_el, idl=seg.inner_diameter, odl=seg.outer_diameter, material=mat,
                shear_effects=False, rotary_inertia=True, gyroscopic=True,
            )
            for _ in range(n_el)
        ]
        node_of_station.append(node_of_station[-1] + n_el)
    disks = [
        rs.DiskElement(n=node_of_station[m.node], m=m.mass, Id=m.diametral_inertia, Ip=m.polar_inertia)
        for m in d.masses
    ]
    bearings = [rs.BearingElement(n=node_of_station[b.node], kxx=b.kxx, cxx=0.0) for b in d.bearings]
    return rs.Rotor(shaft, disk_elements=disks, bearing_elements=bearings)


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
    rotor = _ross_rotor(d)
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
    assert out.size >= n, f"ROSS returned only {out.size} forward lateral critical speeds"
    return out[:n]


def uniform_shaft() -> Driveline:
    """(a) solid 40 mm steel shaft, 1 m, on rigid simple supports (1e12 N/m bearings)."""
    seg = ShaftSegment(1.0, 0.040, 0.0, E, RHO)
    return Driveline([seg], bearings=[Bearing(0, 1e12), Bearing(1, 1e12)])


def tube_propshaft() -> Driveline:
    """(b) one-piece tube: OD 76.2 mm, wall 1.65 mm, 1.4 m, 2.5 kg joints, 1e7 N/m bearings."""
    return one_piece_shaft(1.4, 0.0762, 0.0762 - 2 * 0.00165, E, RHO, 2.5, 0.004, 0.002, 1e7)


def two_piece_propshaft() -> Driveline:
    """(c) the shipped two-piece example with a centre bearing."""
    return load_driveline(example_path("two_piece_propshaft"))


CASES = {"a_uniform": uniform_shaft, "b_tube": tube_propshaft, "c_two_piece": two_piece_propshaft}


@pytest.fixture(scope="module")
def ross_cs():
    """ROSS critical speeds per case, computed at most once per module."""
    cache: dict[str, np.ndarray] = {}

    def get(name: str) -> np.ndarray:
        if name not in cache:
            cache[name] = ross_forward_critical_speeds(CASES[name]())
        return cache[name]

    return get


@pytest.mark.parametrize("name", sorted(CASES))
def test_forward_critical_speeds_match_ross(name, ross_cs):
    ours = CASES[name]().critical_speeds(3)
    ross = ross_cs(name)
    rel = np.abs(ours - ross) / ross
    assert np.all(rel <= REL_TOL), f"{name}: ours {ours}, ROSS {ross}, rel {rel}"


def test_uniform_shaft_ross_close_to_pinned_analytic(ross_cs):
    """ROSS with 1e12 N/m supports vs our exactly pinned shaft: supports are rigid enough."""
    d = uniform_shaft()
    pinned = Driveline(d.segments, left="pinned", right="pinned")
    ours = pinned.critical_speeds(3)
    # the 1e12 N/m supports shift the frequencies by <= 5e-6 (measured); ROSS's mesh
    # error adds <= 2e-5: same tolerance as above.
    assert np.allclose(ours, ross_cs("a_uniform"), rtol=REL_TOL, atol=0.0)
