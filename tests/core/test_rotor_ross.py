"""Forward critical speeds against ROSS (finite elements, Rayleigh beams, fine mesh).

ROSS is an optional test dependency: the module is skipped when it is missing.
ROSS results are computed once per module (they take seconds, ours milliseconds).
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from driveline.rotor import (
    Bearing,
    ConcentratedMass,
    Driveline,
    ShaftSegment,
    example_path,
    load_driveline,
    one_piece_shaft,
    Unbalance,
)
from driveline.rotor.damped import DampedRotor

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    pytest.importorskip("ross")

from support.ross_reference import (  # noqa: E402
    E,
    RHO,
    ross_damped_modes,
    ross_forward_critical_speeds,
    ross_unbalance_response,
)
from support.rotor_checks import response_peaks  # noqa: E402

#: Required agreement. The brief asks for 0.5 %; we measure 2e-8 to 2e-5 (Rayleigh
#: beams; the rest is ROSS's mesh error, falling as h**4) and 5.6e-6 to 1.4e-5 with
#: shear (Timoshenko elements, whose error falls as h**2: 1.4e-6 to 3.5e-6 at 48
#: elements per metre), so 1e-4 keeps a margin for ROSS's discretisation while still
#: catching modelling errors: a wrong gyroscopic sign moves these forward critical
#: speeds by 1-4 %, leaving shear out by 0.2-0.8 %.
REL_TOL = 1e-4
#: Peaks of the unbalance response (speed and amplitude) and logarithmic decrements, Timoshenko tube.
FORCED_TOL = 3e-4


def uniform_shaft() -> Driveline:
    """(a) solid 40 mm steel shaft, 1 m, on rigid simple supports (1e12 N/m bearings)."""
    seg = ShaftSegment(1.0, 0.040, 0.0, E, RHO)
    return Driveline([seg], bearings=[Bearing(0, 1e12), Bearing(1, 1e12)])


def tube_propshaft() -> Driveline:
    """(b) one-piece tube: OD 76.2 mm, wall 1.65 mm, 1.4 m, 2.5 kg joints, 1e7 N/m bearings; Rayleigh beam."""
    return one_piece_shaft(1.4, 0.0762, 0.0762 - 2 * 0.00165, E, RHO, 2.5, 0.004, 0.002, 1e7, shear=False)


def tube_propshaft_shear() -> Driveline:
    """(b) with a Timoshenko tube (Cowper's shear coefficient, nu = 0.3; the default), as ROSS with shear on."""
    return one_piece_shaft(1.4, 0.0762, 0.0762 - 2 * 0.00165, E, RHO, 2.5, 0.004, 0.002, 1e7)


def two_piece_propshaft() -> Driveline:
    """(c) the shipped two-piece example with a centre bearing (Timoshenko tubes, the layout default)."""
    return load_driveline(example_path("two_piece_propshaft"))


CASES = {"a_uniform": uniform_shaft, "b_tube": tube_propshaft, "b_tube_shear": tube_propshaft_shear,
         "c_two_piece": two_piece_propshaft}


@pytest.fixture(scope="module", autouse=True)
def ross_started() -> None:
    """ROSS's first damped modal analysis in a process costs about 9 s of CPU of its own
    start-up (the second about 0.5 s): paid once per module here, so that each test's measured
    cost, which counts its module's fixtures, is what running it alone costs."""
    ross_damped_modes(FORCED["anisotropic_cross_coupled"](), 600.0)


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


def two_halves(bearings: list[Bearing], cut: float) -> Driveline:
    """Rotor (b) with a Timoshenko tube cut at ``cut`` [m] (node 1), on ``bearings`` at nodes 0 and 2,
    and an unbalance of 1e-4 kg m at node 1."""
    tube = tube_propshaft_shear().segments[0]
    segments = [dataclasses.replace(tube, length=cut), dataclasses.replace(tube, length=tube.length - cut)]
    joints = [ConcentratedMass(n, 2.5, 0.004, 0.002) for n in (0, 2)]
    return Driveline(segments, joints, bearings, unbalances=[Unbalance(cut, 1e-4, 0.3)])


FORCED = {
    "isotropic_damped": lambda: two_halves([Bearing(n, 1e6, cxx=500.0) for n in (0, 2)], 0.7),
    "anisotropic_cross_coupled": lambda: two_halves(
        [Bearing(n, 1e7, 2e6, cxx=200.0, cyy=100.0, kxy=1e5, kyx=-1e5, cxy=20.0) for n in (0, 2)], 0.5),
}


@pytest.mark.parametrize("name", sorted(FORCED))
def test_unbalance_response_peaks_match_ross(name):
    """Peaks of the orbit's major semi-axis at the unbalance (node 1) below 2000 rad/s: ours (FE, 80
    elements per segment) against ROSS's ``run_unbalance_response`` (24 elements per metre), each
    peak refined to 1e-9 on both sides. The brief asks for 1e-3; measured <= 1.4e-5 in speed and
    <= 9.3e-5 in amplitude: ROSS's Timoshenko elements converge as h**2."""
    d = FORCED[name]()
    ours_speed, ours_peak = response_peaks(DampedRotor(d, 80), np.arange(50.0, 2000.0, 2.0), d.unbalances[0].position)
    assert ours_speed.size >= 2
    ross = ross_unbalance_response(d, 1, 1e-4, 0.3, 1)
    for speed, peak in zip(ours_speed, ours_peak):
        found = minimize_scalar(lambda s: -ross(s)[0], bracket=(speed * 0.999, speed, speed * 1.001), tol=1e-9)
        assert found.x == pytest.approx(speed, rel=FORCED_TOL), name
        assert -found.fun == pytest.approx(peak, rel=FORCED_TOL), name


@pytest.mark.parametrize("name", sorted(FORCED))
def test_damped_modes_match_ross(name):
    """First six damped modes at 600 rad/s: frequency and logarithmic decrement against ROSS's
    ``run_modal``; measured <= 1.3e-5 and <= 6e-5."""
    d = FORCED[name]()
    wd, log_dec = ross_damped_modes(d, 600.0)
    for mode in DampedRotor(d, 80).modes(600.0, 6):
        j = int(np.argmin(np.abs(wd - mode.frequency)))
        assert wd[j] == pytest.approx(mode.frequency, rel=REL_TOL)
        assert log_dec[j] == pytest.approx(mode.log_decrement, rel=FORCED_TOL)
