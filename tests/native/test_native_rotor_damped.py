"""The native rotor library's finite elements (``fem.c``, ``damped.c``, ``unbalance_outputs.c``) against the
Python core: the plausibility check's natural frequencies (model.natural_frequencies, scipy's eigh) and the
FMU's unbalance outputs (UnbalanceOutputs.build and evaluate: numpy's eig, ARPACK above
DENSE_SIZE, LAPACK's banded solve; in C the dense solver, shift-invert Arnoldi above DENSE_SIZE).

Both sides round differently (their own eigensolvers and factorisations), so they agree to the
rounding level of each problem, which the tolerances below state and bound.
"""

from __future__ import annotations

import ctypes
import dataclasses

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from driveline.rotor import Bearing, ConcentratedMass, Driveline, ShaftSegment, Unbalance, model, one_piece_shaft
from driveline.rotor.damped import DENSE_SIZE, DampedRotor
from driveline.rotor.driveline import EXCITED_SHARE
from driveline.rotor.fem import assemble, elements_by_length
from driveline.rotor.loader import example_path, load_driveline, loads_driveline
from driveline.rotor.unbalance_outputs import DAMPED_MODES, FE_ELEMENTS, TABLE_ELEMENTS, UnbalanceOutputs

from support.derivatives import EXTRAPOLATION_ROUNDING, extrapolated
from support.native_rotor import (DOUBLE_P, ERROR_KIND, SOLVE_ROUNDING, CDriveline, ErrorKind, P, c_driveline,
                                  compile_rotor, declare, unbalances)

EPS = np.finfo(float).eps


def frequency_tolerance(expected: np.ndarray) -> np.ndarray:
    """Absolute tolerance of each natural frequency of one plane, from the eigenproblem's conditioning.

    Both cores reduce K x = w^2 M x by Cholesky to a symmetric A and solve it backward stably, so each
    eigenvalue carries an error of about p(n) eps ||A||_2 = p(n) eps w_max^2 (LAPACK's eigenvalue bound,
    p(n) a modest function of the order n, taken as n); w = sqrt(lambda) halves the relative error and
    two independent solves double it: |dw_i| <= n eps (w_max / w_i)^2 w_i. Measured on the layouts
    below (numpy 2.4, scipy 1.17, n from 7 to 27): |dw_i| / (eps (w_max / w_i)^2 w_i) at most 5.6; the
    hinged layout's lowest frequency is 5.9e-12 apart (a 40-digit reference puts both cores 1.5e-11
    off there) against its bound of 1.2e-8: the norm-wise bound is pessimistic for the lowest
    frequencies, yet a modelling error moves them by far more."""
    w_max = np.max(expected)
    return expected.size * EPS * (w_max / expected) ** 2 * expected


def assert_frequencies_agree(got: np.ndarray, expected: np.ndarray) -> None:
    tolerance = frequency_tolerance(expected)
    excess = np.abs(got - expected) / tolerance
    assert np.all(excess <= 1.0), f"frequency {int(np.argmax(excess))} off by {np.max(excess):.2f} tolerances"


#: Response and largest bearing force, relative to their largest value over the run: the banded
#: solves round differently, amplified near a lightly damped resonance (measured at most 1.1e-10,
#: 0.07 % from the resonance of the Rayleigh tube's zeta = 0.0016 mode).
RESPONSE_RTOL = 1e-9
#: Damping ratios, absolute, in units of eps times the spread max|lam| / min|lam| of the mode
#: table's first-order eigenproblem: an eigensolver determines Re(lam) only to about eps ||A||, and
#: zeta = -Re(lam) / |lam| (numpy's own errors against a 30-digit reference reach 2e-13 on the
#: 20-segment shaft, 2e-13 on the default tube's zeta = 0.0016 mode). Measured differences: at most
#: 16 units on the one- and two-piece layouts, 51 on the 20-segment shaft; the C Arnoldi against
#: ARPACK 14 on the 60-segment shafts, 12 on the 100-segment ones (5e-12 absolute). The tabulated damped
#: frequencies, relative, in the same units (Im(lam) is as uncertain as Re(lam)): measured at most 30.
ZETA_UNITS = 200.0

TUBE = dict(L_shaft=1.4, D_outer=0.0762, D_inner=0.0729, E=2.1e11, density=7850.0, m_joint=2.5, Jp_joint=0.004,
            Jd_joint=0.002, k_bearing=1e7)
DEFAULT = one_piece_shaft(**TUBE, c_bearing=500.0)  # the FMU's defaults (Timoshenko)
RAYLEIGH = one_piece_shaft(**TUBE, c_bearing=500.0, shear=False)
TWO_PIECE = load_driveline(example_path("two_piece_propshaft"))
HINGED = load_driveline(example_path("two_piece_propshaft_hinged"))
ENDS = dataclasses.replace(DEFAULT, left="pinned", right="clamped")
ANISOTROPIC = dataclasses.replace(DEFAULT, bearings=[Bearing(0, 1e7, 3e6, cxx=300.0), Bearing(1, 2e7, cxx=100.0)])
CROSS_COUPLED = dataclasses.replace(DEFAULT, bearings=[
    Bearing(0, 1e7, 2e6, cxx=300.0, cyy=100.0, kxy=1e5, kyx=-2e5, cxy=10.0, cyx=30.0), Bearing(1, 1e7, 2e6, cxx=300.0)])


def equal_segments(count: int, anisotropic: bool = False, masses: bool = False) -> Driveline:
    """The default tube cut into ``count`` equal Timoshenko segments on damped bearings (``anisotropic``:
    kxx != kyy, the doubled system), with ``masses``: a small concentrated mass at every third inner node."""
    segment = ShaftSegment(1.4 / count, 0.0762, 0.0729, shear=True)
    bearings = ([Bearing(0, 1e7, 3e6, cxx=300.0), Bearing(count, 2e7, cxx=100.0)] if anisotropic
                else [Bearing(0, 1e7, cxx=500.0), Bearing(count, 1e7, cxx=500.0)])
    points = [ConcentratedMass(k, 0.02, 1e-5, 5e-6) for k in range(1, count, 3)] if masses else []
    return Driveline([segment] * count, points, bearings)


# the two-piece shaft with damped bearings and unbalances of its own, one at a node, one in a segment
OWN_UNBALANCES = loads_driveline(example_path("two_piece_propshaft").read_text().replace(
    "stiffness = 1.0e7", "stiffness = 1.0e7\ndamping = 800.0").replace("stiffness = 1.0e6", "stiffness = 1.0e6\ndamping = 200.0")
    + "\n[[unbalances]]\nnode = 1\namount = 5e-5\n\n[[unbalances]]\nposition = 1.2\namount = 1e-4\nphase = 2.0\n")
SEGMENTS_20 = equal_segments(20)  # 84 first-order unknowns in the mode table: numpy's dense eig
SEGMENTS_60 = equal_segments(60)  # 244 > DENSE_SIZE: ARPACK in Python, shift-invert Arnoldi in C
# the damped modes by Arnoldi on both sides: 488, 404 and 808 first-order unknowns in the mode table
ARNOLDI = {"segments_60_anisotropic": equal_segments(60, True), "segments_100": equal_segments(100),
           "segments_100_anisotropic": equal_segments(100, True)}

NATURAL = {"default": DEFAULT, "rayleigh": RAYLEIGH, "two_piece": TWO_PIECE, "hinged": HINGED, "ends": ENDS,
           "anisotropic": ANISOTROPIC}
OUTPUTS = {**NATURAL, "cross_coupled": CROSS_COUPLED, "own_unbalances": OWN_UNBALANCES, "segments_20": SEGMENTS_20,
           "segments_60": SEGMENTS_60, **ARNOLDI}
OMEGA_MAX = 1500.0


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    lib = compile_rotor(tmp_path_factory.mktemp("damped"), ["fem", "unbalance_outputs", "spline", "layout", "pyrepr"])
    driveline_p, outputs_p, error, size = P(CDriveline), ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t
    declare(lib, {
        "fe_natural_frequencies": (ErrorKind, [driveline_p, ctypes.c_int, P(DOUBLE_P), P(ctypes.c_int), error,
                                               size]),
        "unbalance_outputs_new": (ErrorKind, [driveline_p, ctypes.c_void_p, ctypes.c_int, ctypes.c_double,
                                              ctypes.c_double, P(outputs_p), error, size]),
        "unbalance_outputs_evaluate": (None, [outputs_p, ctypes.c_double, DOUBLE_P]),
        "unbalance_outputs_slopes": (None, [outputs_p, ctypes.c_double, DOUBLE_P]),
        "unbalance_outputs_modes": (None, [outputs_p, ctypes.c_double, DOUBLE_P]),
        "unbalance_outputs_free": (None, [outputs_p]),
    })
    lib.free.argtypes = [ctypes.c_void_p]  # libc's, through the library's dependencies
    return lib


def natural_frequencies(lib, d: Driveline, elements: int = model.FE_ELEMENTS) -> np.ndarray:
    c = c_driveline(d)
    values, count, error = ctypes.POINTER(ctypes.c_double)(), ctypes.c_int(), ctypes.create_string_buffer(512)
    assert lib.fe_natural_frequencies(ctypes.byref(c), elements, ctypes.byref(values), ctypes.byref(count), error,
                                      512) == ERROR_KIND["ERROR_NONE"], error.value
    out = np.array(values[:count.value])
    lib.free(ctypes.cast(values, ctypes.c_void_p))
    return out


def outputs(lib, d: Driveline, items, fraction: float, omega_max: float, speeds, table: bool = False,
            slopes: bool = False) -> np.ndarray:
    """The C UnbalanceOutputs' evaluate at ``speeds`` (rows: response, force, damping ratio), with ``table``
    also its mode table (the damped frequencies, then the damping ratios), with ``slopes`` instead their
    derivatives in the speed."""
    c = c_driveline(d)
    excited = unbalances(items)
    error, made = ctypes.create_string_buffer(512), ctypes.c_void_p()
    kind = lib.unbalance_outputs_new(ctypes.byref(c), excited, len(items), fraction, omega_max, ctypes.byref(made),
                                     error, 512)
    assert kind == ERROR_KIND["ERROR_NONE"], error.value
    handle = made.value
    try:
        out, modes = (ctypes.c_double * 3)(), (ctypes.c_double * (2 * DAMPED_MODES))()
        rows = []
        for speed in speeds:
            (lib.unbalance_outputs_slopes if slopes else lib.unbalance_outputs_evaluate)(handle, speed, out)
            lib.unbalance_outputs_modes(handle, speed, modes)
            rows.append(list(out) + (list(modes) if table else []))
    finally:
        lib.unbalance_outputs_free(handle)
    return np.array(rows)


def excitation(d: Driveline) -> tuple[Unbalance, ...]:
    """As the FMU: a layout's own unbalances, else 1e-4 kg m at the middle."""
    return tuple(d.unbalances) or (Unbalance(0.5 * d.length, 1e-4),)


def spread(d: Driveline) -> float:
    """max|lam| / min|lam| of the mode table's first-order eigenproblem at standstill."""
    rotor = DampedRotor(d, elements_by_length(d, TABLE_ELEMENTS))
    upper, stiffness, damping, _ = rotor._dense_blocks
    size = np.abs(np.linalg.eigvals(np.block([[upper], [stiffness, damping]])))
    return float(size.max() / size.min())


@pytest.mark.parametrize("name", NATURAL)
def test_natural_frequencies_match_the_python_check(library, name):
    d = NATURAL[name]
    expected = np.sort(model.natural_frequencies(d))
    got = natural_frequencies(library, d)
    assert got.size == expected.size
    assert_frequencies_agree(np.sort(got), expected)


def test_natural_frequencies_take_each_plane_of_anisotropic_bearings(library):
    """Two planes: the kxx frequencies first, each plane ascending (Python's set of planes has no order)."""
    got = natural_frequencies(library, ANISOTROPIC)
    half = got.size // 2
    for k in (lambda b: b.kxx, lambda b: b.k_yy):
        plane = dataclasses.replace(ANISOTROPIC, bearings=[Bearing(b.node, k(b)) for b in ANISOTROPIC.bearings])
        expected = model.natural_frequencies(plane)
        part, got = got[:half], got[half:]
        assert_frequencies_agree(part, expected)


def test_no_elements_fail_as_pythons_zero_division(library):
    """Elements of length / 0: fem's ZeroDivisionError, its kind (not a ValueError) and its message."""
    with pytest.raises(ZeroDivisionError) as python:
        assemble(DEFAULT, 0)
    c, values, count = c_driveline(DEFAULT), ctypes.POINTER(ctypes.c_double)(), ctypes.c_int()
    error = ctypes.create_string_buffer(512)
    kind = library.fe_natural_frequencies(ctypes.byref(c), 0, ctypes.byref(values), ctypes.byref(count), error, 512)
    assert (kind, error.value.decode(), count.value, bool(values)) == (ERROR_KIND["ERROR_ZERO_DIVISION"],
                                                                       str(python.value), 0, False)


@pytest.mark.parametrize("name", OUTPUTS)
def test_unbalance_outputs_match_the_python_model(library, name):
    d = OUTPUTS[name]
    items = excitation(d)
    speeds = np.linspace(0.0, OMEGA_MAX, 101 if name not in ARNOLDI else 51)
    python = UnbalanceOutputs.build(d, items, 0.5, OMEGA_MAX)
    expected = np.array([python.evaluate(speed) for speed in speeds])
    got = outputs(library, d, items, 0.5, OMEGA_MAX, speeds, table=True)
    assert np.all(np.isfinite(got)) and np.all(got[0, :2] == 0.0)
    for column in (0, 1):
        scale = np.max(np.abs(expected[:, column]))
        assert np.max(np.abs(got[:, column] - expected[:, column])) <= RESPONSE_RTOL * scale
    bound = ZETA_UNITS * EPS * spread(d)
    zeta = np.max(np.abs(got[:, 2] - expected[:, 2]))
    assert zeta <= bound, f"damping ratios differ by {zeta:.3g}"
    # the mode table itself: the damped frequencies (relative) and damping ratios of the modes the FMU uses
    table = python.modes(speeds)
    frequencies = np.max(np.abs(got[:, 3:3 + DAMPED_MODES] / table[:, :DAMPED_MODES] - 1.0))
    assert frequencies <= bound, f"damped frequencies differ by {frequencies:.3g}"
    zeta = np.max(np.abs(got[:, 3 + DAMPED_MODES:] - table[:, DAMPED_MODES:]))
    assert zeta <= bound, f"tabulated damping ratios differ by {zeta:.3g}"


#: Slopes at speeds off the mode table's knots and away from resonances and from where the nearest mode changes
SLOPE_SPEEDS = (37.0, 310.0, 790.0, 1220.0)


@pytest.mark.parametrize("name", ["default", "ends", "anisotropic", "cross_coupled", "own_unbalances"])
def test_the_slopes_are_the_derivatives_of_the_outputs(library, name):
    """unbalance_outputs_slopes against Richardson-extrapolated central differences of the outputs (steps 2e-3,
    1e-3, 5e-4 of the speed: error O(h^6)): on the fixed ends' bearings (no row), the doubled system of
    anisotropic and cross-coupled bearings (elliptic orbits: |B| > 0, complex k_b), a layout's own unbalances
    with a phase. Within 1e-9 of the slope, plus the values' rounding (SOLVE_ROUNDING, eps for the spline's
    damping ratio) as the extrapolation multiplies it (EXTRAPOLATION_ROUNDING / h)."""
    d = OUTPUTS[name]
    items = excitation(d)
    got = outputs(library, d, items, 0.3, OMEGA_MAX, SLOPE_SPEEDS, slopes=True)
    for speed, slope in zip(SLOPE_SPEEDS, got):
        h = 2e-3 * speed
        reference = extrapolated(lambda x: outputs(library, d, items, 0.3, OMEGA_MAX, [x])[0], speed, h)
        size = np.abs(outputs(library, d, items, 0.3, OMEGA_MAX, [speed - h, speed + h])).max(axis=0)
        rounding = np.array([SOLVE_ROUNDING, SOLVE_ROUNDING, EPS]) * size * EXTRAPOLATION_ROUNDING / h
        assert np.all(np.abs(slope - reference) <= 1e-9 * np.abs(reference) + rounding), (speed, slope, reference)
        assert slope[0] != 0.0 and (slope[1] != 0.0 or name == "ends"), (speed, slope)  # ends: bearings held


def test_the_mode_table_above_the_dense_size_is_arpacks_selection(library):
    """The 60-segment shafts' mode tables exceed DENSE_SIZE in Python, where ARPACK finds the modes."""
    for d in (SEGMENTS_60, ARNOLDI["segments_60_anisotropic"]):
        rotor = DampedRotor(d, elements_by_length(d, TABLE_ELEMENTS))
        assert 2 * rotor.M.shape[0] > DENSE_SIZE


def test_a_layout_cut_by_many_point_elements_stays_fast(library):
    """300 segments cut by 99 concentrated masses: 1204 first-order unknowns, where the dense eigensolver
    took a minute and a half for the mode table (now well under a second); the Arnoldi mode table agrees with ARPACK's at three of its speeds (DampedRotor.modes
    as UnbalanceOutputs.build calls it) and the response with Python's banded solve."""
    d = equal_segments(300, masses=True)
    items = excitation(d)
    rotor = DampedRotor(d, elements_by_length(d, TABLE_ELEMENTS))
    assert elements_by_length(d, FE_ELEMENTS) == elements_by_length(d, TABLE_ELEMENTS)  # one model serves both
    knots = np.linspace(0.0, OMEGA_MAX, 11)[[0, 5, 10]]
    table, smallest = [], np.inf
    for spin in knots:
        modes = rotor.modes(spin, 4 * DAMPED_MODES)
        smallest = min(smallest, *(abs(m.eigenvalue) for m in modes)) if spin == 0.0 else smallest
        excited = [m for m in modes if m.forward_share >= EXCITED_SHARE]
        assert len(excited) >= DAMPED_MODES
        table.append([m.frequency for m in excited[:DAMPED_MODES]] + [m.damping_ratio for m in excited[:DAMPED_MODES]])
    table = np.array(table)
    speeds = np.array([*knots, 333.0, 1234.5])
    got = outputs(library, d, items, 0.5, OMEGA_MAX, speeds, table=True)
    python = UnbalanceOutputs(rotor, rotor.load(items), rotor.shape_rows([0.5 * d.length]), CubicSpline(knots, table))
    expected = np.array([python.evaluate(speed)[:2] for speed in speeds])
    for column in (0, 1):
        assert np.max(np.abs(got[:, column] - expected[:, column])) <= RESPONSE_RTOL * np.max(expected[:, column])
    # ZETA_UNITS with max|lam| bounded by the 1-norm of B^-1 A (a dense eigensolver would take seconds
    # here), about 10 times max|lam| on the 60- and 100-segment shafts: the bound is 2.5e-9, the
    # measured differences 2.1e-11 (frequencies, relative) and 1.1e-12 (damping ratios)
    upper, stiffness, damping, _ = rotor._dense_blocks
    largest = np.max(np.sum(np.abs(upper), axis=0) + np.sum(np.abs(np.hstack([stiffness, damping])), axis=0))
    bound = ZETA_UNITS * EPS * largest / smallest
    frequencies = np.max(np.abs(got[:3, 3:3 + DAMPED_MODES] / table[:, :DAMPED_MODES] - 1.0))
    zeta = np.max(np.abs(got[:3, 3 + DAMPED_MODES:] - table[:, DAMPED_MODES:]))
    assert frequencies <= bound and zeta <= bound, (frequencies, zeta, bound)


def test_response_position_and_omega_max_are_honoured(library):
    d = OWN_UNBALANCES
    speeds = np.linspace(0.0, 900.0, 37)
    python = UnbalanceOutputs.build(d, d.unbalances, 0.83, 900.0)
    expected = np.array([python.evaluate(speed) for speed in speeds])
    got = outputs(library, d, d.unbalances, 0.83, 900.0, speeds)
    for column in (0, 1):
        assert np.max(np.abs(got[:, column] - expected[:, column])) <= RESPONSE_RTOL * np.max(expected[:, column])
    assert np.max(np.abs(got[:, 2] - expected[:, 2])) <= ZETA_UNITS * EPS * spread(d)


def test_speed_zero_gives_no_response_and_the_tabulated_damping(library):
    got = outputs(library, DEFAULT, excitation(DEFAULT), 0.5, OMEGA_MAX, [0.0])
    python = UnbalanceOutputs.build(DEFAULT, excitation(DEFAULT), 0.5, OMEGA_MAX).evaluate(0.0)
    assert got[0, 0] == 0.0 and got[0, 1] == 0.0
    assert got[0, 2] == pytest.approx(python[2], rel=1e-9)


@pytest.mark.parametrize("omega_max", [0.0, -5.0, float("nan"), float("inf")])
@pytest.mark.filterwarnings("ignore:invalid value encountered in multiply:RuntimeWarning")  # numpy's linspace to inf
def test_refusals_are_worded_as_pythons(library, omega_max):
    """Equal or falling knots, which CubicSpline refuses; knots that are not finite, which numpy's eig
    refuses."""
    with pytest.raises(ValueError) as refused:
        UnbalanceOutputs.build(DEFAULT, excitation(DEFAULT), 0.5, omega_max)
    c = c_driveline(DEFAULT)
    excited = unbalances(excitation(DEFAULT))
    error, made = ctypes.create_string_buffer(512), ctypes.c_void_p()
    kind = library.unbalance_outputs_new(ctypes.byref(c), excited, 1, 0.5, omega_max, ctypes.byref(made), error, 512)
    assert (kind, made.value, error.value.decode()) == (ERROR_KIND["ERROR_VALUE"], None, str(refused.value))
