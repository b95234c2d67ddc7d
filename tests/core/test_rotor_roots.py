"""Root search: no missed and no spurious roots.

The reference is an independent finite-element model (``driveline.rotor.fem``:
cubic Hermite Rayleigh elements, eigenvalues of the linearised gyroscopic
problem), which shares no code with the transfer-matrix path.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from driveline.rotor import (
    Bearing,
    ConcentratedMass,
    Driveline,
    ShaftSegment,
    example_path,
    fem,
    load_driveline,
    one_piece_shaft,
)
from driveline.rotor import transfer
from driveline.rotor.loader import loads_driveline
from driveline.rotor.roots import MAX_DIPS, BatchReport, find_roots_batch
from fmu_harness.checks.analysis_work import ROUND_OFF_LAYOUT

from support.rotor_checks import drivelines, rayleigh



def find_roots(f, grid) -> BatchReport:
    """The root search on one function: its roots are ``roots[0]``."""
    return find_roots_batch(lambda x, k: f(x), [grid])


#: FE elements per segment.
N_EL = 40
#: Agreement of each matched frequency. The FE error grows as (mode number / N_EL)^4:
#: measured 1e-8 at mode 1 and 1.5e-5 at mode 8 of the tube; 1e-4 leaves margin.
#: The point of these tests is the count; values only confirm the pairing.
FE_RTOL = 1e-4


def _fe_in_range(d: Driveline, spin: float, n: int) -> tuple[np.ndarray, np.ndarray, float]:
    """FE forward/backward frequencies below a cut placed midway between FE modes n and n+1."""
    lam = fem.whirl_frequencies(d, spin, N_EL)
    fwd = lam[lam > 1e-6]
    bwd = -lam[lam < -1e-6][::-1]
    both = np.sort(np.concatenate([fwd, bwd]))
    # cut well away from every FE frequency so that FE error cannot move a root across it
    cut = 0.5 * (both[2 * n - 1] + both[2 * n]) if both[2 * n] - both[2 * n - 1] > 1e-3 * both[2 * n] else both[2 * n + 1] * 0.999
    return fwd[fwd < cut], bwd[bwd < cut], cut


def _two_piece() -> Driveline:
    return rayleigh(load_driveline(example_path()))


def _tube() -> Driveline:
    return one_piece_shaft(1.4, 0.0762, 0.0729, 2.1e11, 7850.0, 2.5, 0.004, 0.002, 1e7, shear=False)


def _soft_heavy() -> Driveline:
    """Heavy joints on soft bearings: rigid-body modes close to each other and to zero."""
    seg = ShaftSegment(1.2, 0.09, 0.086)
    return Driveline(
        [seg, seg],
        [ConcentratedMass(0, 8.0, 0.05, 0.03), ConcentratedMass(1, 3.0, 0.01, 0.2), ConcentratedMass(2, 8.0, 0.05, 0.03)],
        [Bearing(0, 2e4), Bearing(1, 5e3), Bearing(2, 2.1e4)],
    )


@pytest.mark.parametrize("make", [_tube, _two_piece, _soft_heavy])
@pytest.mark.parametrize("spin", [0.0, 400.0, 2500.0])
def test_root_count_matches_finite_elements(make, spin):
    d = make()
    fe_f, fe_b, cut = _fe_in_range(d, spin, 8)
    wf = d.whirl_frequencies(spin, w_max=cut)
    assert wf.forward.size == fe_f.size, (wf.forward, fe_f)
    assert wf.backward.size == fe_b.size, (wf.backward, fe_b)
    assert np.allclose(wf.forward, fe_f, rtol=FE_RTOL, atol=0.0)
    assert np.allclose(wf.backward, fe_b, rtol=FE_RTOL, atol=0.0)


def test_no_roots_lost_to_a_much_finer_scan():
    # Sign changes of the determinant on a grid 50x finer than the search grid:
    # every one must be a reported root (and nothing else).
    d = _two_piece()
    spin = 700.0
    wf = d.whirl_frequencies(spin, w_max=12000.0)
    fine = np.linspace(1.0, 12000.0, 60001)
    f = d.determinant(fine, spin)
    changes = np.flatnonzero(np.sign(f[:-1]) != np.sign(f[1:]))
    assert changes.size == wf.forward.size
    assert np.all(np.abs(fine[changes] - wf.forward) <= fine[1] - fine[0])


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(d=drivelines(), spin=st.sampled_from([0.0, 300.0, 3000.0]))
def test_random_drivelines_match_finite_elements(d, spin):
    # Random layouts; 6 modes of each sense. Short stiff segments between heavy
    # masses are the hard cases for the grid; the FE check covers them.
    fe_f, fe_b, cut = _fe_in_range(d, spin, 6)
    wf = d.whirl_frequencies(spin, w_max=cut)
    assert wf.forward.size == fe_f.size
    assert wf.backward.size == fe_b.size
    assert np.allclose(wf.forward, fe_f, rtol=FE_RTOL, atol=0.0)
    assert np.allclose(wf.backward, fe_b, rtol=FE_RTOL, atol=0.0)


# -- the bracketing search itself -------------------------------------------------
GRID = np.linspace(0.0123, 10.0123, 101)  # step 0.1, offset from the roots below


@pytest.mark.parametrize("gap", [1e-2, 1e-4, 1e-6, 1e-8, 1e-10])
def test_close_pair_is_found(gap):
    # Two simple roots much closer than the grid step produce no sign change on
    # the grid; the dip refinement must still return both.
    rep = find_roots(lambda x: (x - 1.0) * (x - 1.0 - gap) * np.cos(x), GRID)
    expected = np.sort(np.r_[1.0, 1.0 + gap, np.pi / 2 + np.pi * np.arange(3)])
    assert rep.roots[0].size == expected.size
    # brentq xtol = 1e-12 (absolute) on these O(1) roots: 1e-11
    assert np.allclose(rep.roots[0], expected, rtol=0, atol=1e-11)


def test_double_root_reported_twice():
    rep = find_roots(lambda x: (x - 1.2345678) ** 2 * (x + 3.0), GRID)
    assert rep.double_roots == 1
    # located by the dip recursion down to ~1e-12 wide; f ~ (x - r)^2 is flat
    # within round-off over ~1e-8 around r, hence 1e-9 (measured 8e-15 here)
    assert np.allclose(rep.roots[0], [1.2345678, 1.2345678], atol=1e-9)


def test_poles_are_rejected():
    # tan changes sign at its poles pi/2 + k pi as well as at its roots k pi.
    rep = find_roots(np.tan, np.linspace(0.1, 10.0, 101))
    # brentq tolerance: 1e-11
    assert np.allclose(rep.roots[0], np.pi * np.arange(1, 4), atol=1e-11)
    assert rep.rejected_poles == 3


def test_no_spurious_roots_from_dips_or_round_off():
    # A positive dip and a flat stretch carrying round-off ripple: no roots.
    assert find_roots(lambda x: (x - 0.3) ** 2 + 1e-3, np.linspace(-1, 1, 101)).roots[0].size == 0
    ripple = lambda x: 0.3 + 1e-16 * np.sin(1e6 * x)
    rep = find_roots(ripple, np.linspace(0.0, 1.0, 101))
    assert rep.roots[0].size == 0 and rep.dips_examined == 0


def test_a_dip_at_the_rounding_level_is_a_double_root_not_a_chase():
    """A double root under a ripple of +-1e-9 that changes sign on every sub-grid (round-off as a badly
    conditioned determinant shows it): told that rounding level, the search stops where the dip's bottom
    reaches it and reports a double root there; told nothing, it chases the ripple's dips and sign
    changes level after level until the per-line cap refuses it."""
    def f(x):
        return (x - 0.5) ** 2 + 1e-9 * (0.5 + np.sin(1e13 * x))

    told = find_roots_batch(lambda x, k: (f(x), np.full(x.size, 1e-9)), [GRID - 0.0123])
    assert told.double_roots == 1 and told.evaluations == GRID.size
    assert np.allclose(told.roots[0], 0.5, rtol=0, atol=1e-4)  # |f| <= 8e-9 within 9e-5 of the root
    with pytest.raises(ArithmeticError, match="dips on one line"):
        find_roots(f, GRID - 0.0123)


def test_a_second_evaluation_tells_the_rounding_the_first_does_not_see():
    """The ripple above with no rounding level given (as the end determinant's level misses the round-off
    of the propagation before it, issue 45), but evaluated ``again`` another way that rounds otherwise: the
    difference raises the level of the dip's three points (three evaluations more), so the search stops at
    the ripple's depth with the double root, as when told the level; without it, the cap (above)."""
    def f(x):
        return (x - 0.5) ** 2 + 1e-9 * (0.5 + np.sin(1e13 * x))

    def again(x, k):
        return (x - 0.5) ** 2 + 1e-9 * (0.5 + np.cos(3e12 * x))

    report = find_roots_batch(lambda x, k: (f(x), np.zeros(x.size)), [GRID - 0.0123], again=again)
    assert report.double_roots == 1 and report.evaluations == GRID.size + 3
    assert np.allclose(report.roots[0], 0.5, rtol=0, atol=1e-4)


def test_ripple_as_deep_as_the_rounding_is_not_examined():
    """Dips of 1e-6 +- 1e-7 with a rounding level of 2e-8 at every point: resolved from zero, but no
    deeper than 8 times the rounding of their three points, so dropped; told no rounding, the same
    dips are examined (and found to hold no root)."""
    def f(x):
        return 1e-6 + 1e-7 * np.sin(40.0 * x)

    told = find_roots_batch(lambda x, k: (f(x), np.full(x.size, 2e-8)), [GRID])
    blind = find_roots(f, GRID)
    assert told.dips_examined == 0 and told.roots[0].size == 0
    assert blind.dips_examined > 0 and blind.roots[0].size == 0


@pytest.mark.parametrize("periods, refused", [(200, False), (600, True)])
def test_at_most_max_dips_are_rescanned_on_one_line(periods, refused):
    """Positive dips of a cosine, ten grid points a period, each examined on two levels: 200 periods
    stay under MAX_DIPS re-scans, 600 are refused with the rule named; a second line in the same
    batch does not share the first one's count."""
    grid = np.linspace(0.1, 2.0 * np.pi * periods + 0.1, 10 * periods + 1)

    def f(x, k):
        return 1.0001 + np.cos(x)

    if refused:
        with pytest.raises(ArithmeticError, match=f"more than {MAX_DIPS} dips on one line"):
            find_roots_batch(f, [grid])
    else:
        report = find_roots_batch(f, [grid, grid])
        assert MAX_DIPS < report.dips_examined < 2 * MAX_DIPS and not any(r.size for r in report.roots)


def test_the_round_off_layout_is_searched_in_a_bounded_number_of_evaluations():
    """The layout of extreme materials whose determinant ripples at about its rounding level near a
    close pair at 11 384 rad/s (docs/critical_speeds.md): at standstill the search once took 1.7
    million evaluations; now it takes well under a thousand. What the design guarantees is the bound
    and the pair found twice; whether the pair resolves into two sign changes or bottoms out as a
    double root depends on the libraries' rounding (numpy 2.4 resolves it 1.1e-4 rad/s apart), so the
    double-root path is held by the constructed ripple above, whose outcome is certain."""
    driveline = loads_driveline(ROUND_OFF_LAYOUT)
    for spin in (0.0, 0.051854897560696):
        grid = driveline._grid(4.0e4, 1.0)
        report = find_roots_batch(
            lambda x, k: transfer.determinant_and_rounding(driveline._chain, x, spin), [grid])
        roots = report.roots[0]
        assert report.evaluations < 1000
        assert np.allclose(roots[:2], [98.4798381, 312.0615041], rtol=1e-8)
        assert np.count_nonzero(np.abs(roots - 11384.045) < 1e-2) == 2


def test_roots_come_lowest_first():
    rep = find_roots(np.sin, GRID)
    assert np.allclose(rep.roots[0][:2], [np.pi, 2 * np.pi], atol=1e-11)


def test_grid_validation():
    with pytest.raises(ValueError, match="grid"):
        find_roots(np.sin, np.array([1.0, 0.5, 2.0]))
