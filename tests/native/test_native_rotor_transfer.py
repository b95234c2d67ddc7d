"""The native rotor library's transfer matrices and root searches (``transfer.c``, ``roots.c``) against
the Python core (``driveline.rotor.transfer``, ``roots``, ``driveline``).

The library is compiled on its own (:mod:`native_rotor`) and called through ctypes; the ``Driveline``
structure of ``rotor.h`` is filled from a Python :class:`~driveline.rotor.Driveline` through ctypes
structures that mirror the header (:func:`native_rotor.c_driveline`).

Tolerances, and why:

* determinant: the C port evaluates one point at a time, and so does the reference here (the Python
  core cuts every segment of a batch into the pieces its fastest point needs, which changes the
  round-off by up to 1e-9 relative in the anisotropic 8x8 state at w ~ 1e5 rad/s). Both then do
  the same operations; what is left is libm/SIMD round-off of sinh, exp and pow (numpy vectorises
  them) and the order of sums, amplified by the cancellation in the final 2x2 minor or 4x4
  determinant: measured 1.1e-12 (isotropic) and 7e-12 (anisotropic up to 5000 rad/s), checked at
  5e-12. The anisotropic 8x8 propagation, whose forward and backward parts grow at different rates,
  is itself noisy above 5000 rad/s: at w = 10447, spin = 2182 rad/s the Python core's f moves by
  1.4e-10 when w moves by 3 ulp (the C port differs by 1.5e-10), so it is checked at 1e-9 up to 2e4 rad/s. Next to a root, where |f| is small against its size
  at w +- 1 % (at high w that window holds roots), the error is bounded by 1e-12 of that size instead
  (measured: 4e-11 relative at a point with 1 % of the local size, w = 78 000 rad/s);
* roots (lines, whirl senses, order resonances, critical speeds): both refine to xtol 1e-12 +
  4 eps |x| on functions that agree to ~1e-12, so the roots agree to round-off: measured 3e-15
  isotropic, 1.1e-13 anisotropic; checked at 1e-12 relative, and the counts, order, orders and whirl
  senses exactly;
* forward fraction (anisotropic mode classification): the C port sums the squared amplitudes as
  quadratic forms of the null vector instead of mapping the vector back, measured 3e-14 absolute;
  checked at 1e-9.
"""

from __future__ import annotations

import ctypes
import time

import numpy as np
import pytest

from driveline.rotor import budget, load_driveline, transfer
from driveline.rotor.driveline import SEARCH_LIMIT, Driveline
from driveline.rotor.elements import Bearing, ConcentratedMass, Hinge, ShaftSegment
from driveline.rotor.loader import example_path, loads_driveline, one_piece_shaft
from fmu_harness.checks.analysis_work import ROUND_OFF_LAYOUT, SIX_SEGMENT_LAYOUT

from support.native_rotor import (CHAIN_SIGNATURES, DOUBLE_P, ERROR_KIND, ErrorKind, P, c_array, c_driveline,
                                  compile_rotor, declare, raised)


class CBudget(ctypes.Structure):
    _fields_ = [("left", ctypes.c_longlong), ("spent", ctypes.c_int), ("stage", ctypes.c_char_p),
                ("spent_in", ctypes.c_char_p)]


class CLine(ctypes.Structure):
    _fields_ = [(name, ctypes.c_double) for name in ("w", "s", "o")]


class CRoots(ctypes.Structure):
    _fields_ = [("count", ctypes.c_int), ("x", DOUBLE_P)]


class COrderResonance(ctypes.Structure):
    _fields_ = [("order", ctypes.c_int), ("whirl", ctypes.c_int), ("spin", ctypes.c_double)]


WHIRL_BITS = {"forward": 1, "backward": 2}
ERROR_SIZE = 512


def _declare(lib: ctypes.CDLL) -> ctypes.CDLL:
    chain, size, error = ctypes.c_void_p, ctypes.c_size_t, ctypes.c_char_p
    signatures = {
        **CHAIN_SIGNATURES,
        "chain_isotropic": (ctypes.c_int, [chain]),
        "chain_kappa": (ctypes.c_double, [chain]),
        "chain_freedoms": (ctypes.c_int, [chain]),
        "chain_determinant": (None, [chain, size, DOUBLE_P, DOUBLE_P, DOUBLE_P]),
        "chain_determinant_rounding": (None, [chain, size, DOUBLE_P, DOUBLE_P, DOUBLE_P, DOUBLE_P]),
        "chain_forward_fraction": (ctypes.c_double, [chain, ctypes.c_double, ctypes.c_double]),
        "chain_set_budget": (None, [chain, P(CBudget)]),
        "chain_stations": (ctypes.c_int, [chain]),
        "rotor_roots_free": (None, [P(CRoots), ctypes.c_int]),
        "rotor_line_roots": (ErrorKind, [chain, P(CLine), ctypes.c_int, ctypes.c_int, ctypes.c_double,
                                         ctypes.c_double, P(ctypes.c_ubyte), P(CRoots), error, size]),
        "rotor_roots_by_whirl": (ErrorKind, [chain, P(CLine), ctypes.c_int, ctypes.c_int, ctypes.c_double,
                                             ctypes.c_double, P(CRoots), P(CRoots), error, size]),
        "rotor_order_resonances": (ErrorKind, [chain, P(ctypes.c_int), ctypes.c_int, ctypes.c_int, ctypes.c_int,
                                               ctypes.c_double, ctypes.c_double, P(P(COrderResonance)),
                                               P(ctypes.c_int), error, size]),
        "rotor_critical_speeds": (ErrorKind, [chain, ctypes.c_int, DOUBLE_P, P(ctypes.c_int), error, size]),
    }
    return declare(lib, signatures)


LIBC = ctypes.CDLL(None)
LIBC.free.argtypes = [ctypes.c_void_p]
LIBC.free.restype = None


class NativeChain:
    """``chain_new`` of a Python driveline, and the library's searches on it with the Python core's
    argument conventions (``None`` where the C interface takes 0)."""

    def __init__(self, lib: ctypes.CDLL, driveline: Driveline) -> None:
        self.lib = lib
        self.struct = c_driveline(driveline)
        error, chain = ctypes.create_string_buffer(ERROR_SIZE), ctypes.c_void_p()
        kind = lib.chain_new(ctypes.byref(self.struct), ctypes.byref(chain), error, ERROR_SIZE)
        if kind != ERROR_KIND["ERROR_NONE"]:
            assert not chain
            raise raised(kind, error.value.decode())
        self.pointer = chain.value

    def __del__(self) -> None:
        if getattr(self, "pointer", None):
            self.lib.chain_free(self.pointer)

    def _call(self, name: str, *args) -> None:
        """The library function ``name``; a failure raised as the Python exception its kind stands for."""
        error = ctypes.create_string_buffer(ERROR_SIZE)
        kind = getattr(self.lib, name)(self.pointer, *args, error, ERROR_SIZE)
        if kind != ERROR_KIND["ERROR_NONE"]:
            raise raised(kind, error.value.decode())

    def _roots(self, roots: ctypes.Array, m: int) -> list[np.ndarray]:
        out = [np.array(roots[i].x[:roots[i].count], dtype=float) for i in range(m)]
        self.lib.rotor_roots_free(roots, m)
        return out

    def determinant(self, w: np.ndarray, spin: np.ndarray) -> np.ndarray:
        w = np.ascontiguousarray(w, dtype=float)
        spin = np.ascontiguousarray(spin, dtype=float)
        f = np.empty(w.size)
        self.lib.chain_determinant(self.pointer, w.size, w.ctypes.data_as(DOUBLE_P), spin.ctypes.data_as(DOUBLE_P),
                                   f.ctypes.data_as(DOUBLE_P))
        return f

    def determinant_and_rounding(self, w: np.ndarray, spin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        w = np.ascontiguousarray(w, dtype=float)
        spin = np.ascontiguousarray(spin, dtype=float)
        f, rounding = np.empty(w.size), np.empty(w.size)
        self.lib.chain_determinant_rounding(self.pointer, w.size, w.ctypes.data_as(DOUBLE_P),
                                            spin.ctypes.data_as(DOUBLE_P), f.ctypes.data_as(DOUBLE_P),
                                            rounding.ctypes.data_as(DOUBLE_P))
        return f, rounding

    def line_roots(self, lines, n, x_max, limit=1e5, coarse=None) -> list[np.ndarray]:
        m = len(lines)
        roots = (CRoots * m)()
        flags = None if coarse is None else c_array(ctypes.c_ubyte, [int(bool(c)) for c in coarse])
        self._call("rotor_line_roots", c_array(CLine, [CLine(*line) for line in lines]), m, 0 if n is None else n,
                   0.0 if x_max is None else x_max, limit, flags, roots)
        return self._roots(roots, m)

    def roots_by_whirl(self, cases, n, x_max, limit=1e5) -> list[dict[str, np.ndarray]]:
        m = len(cases)
        forward, backward = (CRoots * m)(), (CRoots * m)()
        self._call("rotor_roots_by_whirl", c_array(CLine, [CLine(*case) for case in cases]), m,
                   0 if n is None else n, 0.0 if x_max is None else x_max, limit, forward, backward)
        return [{"forward": f, "backward": b} for f, b in zip(self._roots(forward, m), self._roots(backward, m))]

    def order_resonances(self, orders, whirls, n, spin_max, limit=1e5) -> list[tuple[int, str, float]]:
        found, count = P(COrderResonance)(), ctypes.c_int()
        self._call("rotor_order_resonances", c_array(ctypes.c_int, list(orders)), len(orders),
                   sum(WHIRL_BITS[w] for w in whirls), 0 if n is None else n, 0.0 if spin_max is None else spin_max,
                   limit, ctypes.byref(found), ctypes.byref(count))
        out = [(found[i].order, "forward" if found[i].whirl == 1 else "backward", found[i].spin)
               for i in range(count.value)]
        LIBC.free(found)
        return out

    def critical_speeds(self, n: int) -> np.ndarray:
        spins, count = (ctypes.c_double * max(n, 1))(), ctypes.c_int()
        self._call("rotor_critical_speeds", n, spins, ctypes.byref(count))
        return np.array(spins[:count.value])


@pytest.fixture(scope="module")
def lib(tmp_path_factory) -> ctypes.CDLL:
    return _declare(compile_rotor(tmp_path_factory.mktemp("rotor"), ["transfer", "roots"]))


def _tube(shear: bool) -> Driveline:
    """The FMU's default one-piece tube."""
    return one_piece_shaft(1.4, 0.0762, 0.0729, 2.1e11, 7850.0, 2.5, 0.004, 0.002, 1e7, shear=shear)


def _joint(node: int) -> ConcentratedMass:
    return ConcentratedMass(node, 2.5, 0.004, 0.002)


DRIVELINES = {
    "tube_timoshenko": lambda: _tube(True),
    "tube_rayleigh": lambda: _tube(False),
    "two_piece": lambda: load_driveline(example_path("two_piece_propshaft")),
    "two_piece_hinged": lambda: load_driveline(example_path("two_piece_propshaft_hinged")),
    "spring_hinge": lambda: Driveline(
        [ShaftSegment(0.7, 0.0762, 0.0729), ShaftSegment(0.8, 0.0635, 0.0603, shear=True)],
        [ConcentratedMass(1, 2.0, 0.003, 0.0015)], [Bearing(0, 1e7), Bearing(2, 1e7)], joints=[Hinge(1, 2e4)]),
    "pinned": lambda: Driveline([ShaftSegment(1.2, 0.05)], left="pinned", right="pinned"),
    "clamped_free": lambda: Driveline([ShaftSegment(1.0, 0.05, 0.04, shear=True)],
                                      [ConcentratedMass(1, 3.0, 0.01, 0.005)], left="clamped", right="free"),
    "euler_bernoulli": lambda: Driveline([ShaftSegment(1.0, 0.06, rotary_inertia=False, gyroscopic=False)],
                                         left="pinned", right="clamped"),
    "anisotropic": lambda: Driveline([ShaftSegment(1.4, 0.0762, 0.0729)], [_joint(0), _joint(1)],
                                     [Bearing(0, 1e7, kyy=2e6), Bearing(1, 1e7, kyy=2e6)]),
    "anisotropic_hinged": lambda: Driveline(
        [ShaftSegment(0.7, 0.0762, 0.0729), ShaftSegment(0.1, 0.035), ShaftSegment(0.8, 0.0635, 0.0603)],
        [_joint(0), ConcentratedMass(2, 2.0, 0.003, 0.0015), _joint(3)],
        [Bearing(0, 1e7, kyy=3e6), Bearing(1, 1e6, kyy=4e5), Bearing(3, 1e7)], joints=[Hinge(2), Hinge(1, 5e3)]),
    "twenty_segments": lambda: Driveline([ShaftSegment(0.07, 0.0762, 0.0729, shear=True)] * 20,
                                         [_joint(0), _joint(20)], [Bearing(0, 1e7), Bearing(20, 1e7)]),
}
ANISOTROPIC = ("anisotropic", "anisotropic_hinged")
ROOT_RTOL = 1e-12


@pytest.fixture(scope="module", params=sorted(DRIVELINES))
def pair(request, lib) -> tuple[Driveline, NativeChain]:
    driveline = DRIVELINES[request.param]()
    return driveline, NativeChain(lib, driveline)


def _assert_roots(native: list[np.ndarray], python: list[np.ndarray]) -> None:
    assert [r.size for r in native] == [r.size for r in python]
    for c, p in zip(native, python):
        np.testing.assert_allclose(c, p, rtol=ROOT_RTOL, atol=0.0)


def test_chain_constants(pair):
    driveline, native = pair
    chain = driveline._chain
    extra = sum(len(frozenset().union(*(el.freedoms for el in node))) for node in chain.points)
    assert native.lib.chain_isotropic(native.pointer) == int(driveline.is_isotropic)
    assert native.lib.chain_freedoms(native.pointer) == extra
    assert native.lib.chain_kappa(native.pointer) == pytest.approx(driveline._kappa, rel=1e-15)


def test_determinant(pair):
    """f(w, spin) at 150 points, low and high frequencies, signed w for isotropic chains; the Python
    core evaluated point by point (see the module docstring)."""
    driveline, native = pair
    rng = np.random.default_rng(7)
    anisotropic = not driveline.is_isotropic
    w = np.concatenate([rng.uniform(0.0, 5000.0, 120), rng.uniform(5000.0, 1e5 if not anisotropic else 2e4, 30)])
    if not anisotropic:
        w *= rng.choice([-1.0, 1.0], w.size)
    spin = rng.uniform(0.0, 3000.0, w.size)
    python = np.array([driveline.determinant(a, b)[0] for a, b in zip(w, spin)])
    native_f = native.determinant(w, spin)
    assert np.all(np.isfinite(native_f))
    # next to a root |f| is small against its size at w +- 1 %: there the error is set against that size
    local = np.maximum(np.abs(native.determinant(0.99 * w, spin)), np.abs(native.determinant(1.01 * w, spin)))
    rtol = 1e-9 if anisotropic else 5e-12
    error = np.abs(native_f - python)
    assert np.all(error <= rtol * np.abs(python) + 1e-12 * local), np.max(error / np.abs(python))
    away = np.abs(python) > 1e-3 * local
    assert np.count_nonzero(away) > 0.8 * w.size
    assert np.array_equal(np.sign(native_f[away]), np.sign(python[away]))


def _lines(driveline: Driveline) -> np.ndarray:
    lines = np.array([(1.0, 0.0, 0.0), (1.0, 0.0, 1500.0), (-1.0, 0.0, 1500.0), (2.0, 1.0, 0.0), (-3.0, 1.0, 0.0),
                      (0.5, 0.3, 100.0)])
    return lines if driveline.is_isotropic else lines[lines[:, 0] > 0.0]


def test_line_roots_up_to_x_max(pair):
    """Every root up to x_max, every other line on a coarse grid."""
    driveline, native = pair
    lines = _lines(driveline)
    coarse = [i % 2 == 0 for i in range(len(lines))]
    python = driveline._line_roots(lines, None, 4000.0, 1e5, coarse)
    _assert_roots(native.line_roots(lines, None, 4000.0, 1e5, coarse), python)
    assert sum(r.size for r in python) >= len(lines)


def test_line_roots_first_n(pair):
    """The first n below the limit, with the 4x widening of the range (a tight limit cuts the count)."""
    driveline, native = pair
    lines = _lines(driveline)
    for n, limit in ((5, 1e5), (8, 3000.0)):
        python = driveline._line_roots(lines, n, None, limit)
        _assert_roots(native.line_roots(lines, n, None, limit), python)


def test_roots_by_whirl(pair):
    """Per whirl sense, standstill cases searched once, anisotropic roots classified by their modes."""
    driveline, native = pair
    cases = [(1.0, 0.0, 0.0), (1.0, 0.0, 800.0), (2.0, 1.0, 0.0)]
    for n, x_max in ((3, None), (None, 2500.0)):
        python = driveline._roots_by_whirl(cases, ("forward", "backward"), n, x_max, 1e5)
        native_roots = native.roots_by_whirl(cases, n, x_max)
        for whirl in ("forward", "backward"):
            _assert_roots([r[whirl] for r in native_roots], [r[whirl] for r in python])


def _assert_resonances(native: list[tuple[int, str, float]], python: list) -> None:
    assert [(o, w) for o, w, _ in native] == [(r.order, r.whirl) for r in python]
    np.testing.assert_allclose([s for _, _, s in native], [r.spin for r in python], rtol=ROOT_RTOL, atol=0.0)


def test_order_resonances(pair):
    """Orders 1, 2, 3 in both senses: all up to 3000 rad/s, and the first 3 of each."""
    driveline, native = pair
    both = ("forward", "backward")
    python = driveline.order_resonances((1, 2, 3), both, None, 3000.0)
    assert python
    _assert_resonances(native.order_resonances((1, 2, 3), both, None, 3000.0), python)
    _assert_resonances(native.order_resonances((1, 2, 3), both, 3, None),
                       driveline.order_resonances((1, 2, 3), both, 3, None))
    _assert_resonances(native.order_resonances((2,), ("backward",), 2, None),
                       driveline.order_resonances((2,), ("backward",), 2, None))


def test_critical_speeds(pair):
    driveline, native = pair
    python = driveline.critical_speeds(3)
    native_speeds = native.critical_speeds(3)
    assert native_speeds.size == python.size
    np.testing.assert_allclose(native_speeds, python, rtol=ROOT_RTOL, atol=0.0)
    np.testing.assert_allclose(native.critical_speeds(1), python[:1], rtol=ROOT_RTOL, atol=0.0)


@pytest.mark.parametrize("name", ANISOTROPIC)
def test_forward_fraction(lib, name):
    """The forward share of sum |U|^2 at the synchronous roots and at off-root points, as mode_shape's
    with 4 points per segment (at a root the mode; elsewhere the smallest singular vector's shape)."""
    driveline = DRIVELINES[name]()
    native = NativeChain(lib, driveline)
    found = driveline.order_resonances((1,), ("forward", "backward"), 6, None)
    assert {r.whirl for r in found} == {"forward", "backward"}
    for r in found:
        expected = driveline.mode_shape(r.spin, r.spin, 4).forward_fraction
        fraction = lib.chain_forward_fraction(native.pointer, r.spin, r.spin)
        assert fraction == pytest.approx(expected, abs=1e-9)
        assert (fraction >= 0.5) == (r.whirl == "forward")


def test_isotropic_forward_fraction(lib):
    native = NativeChain(lib, _tube(True))
    assert lib.chain_forward_fraction(native.pointer, 655.0, 655.0) == 1.0
    assert lib.chain_forward_fraction(native.pointer, -655.0, 655.0) == 0.0


def test_cross_coupled_bearing_is_refused(lib):
    driveline = Driveline([ShaftSegment(1.0, 0.05)], bearings=[Bearing(0, 1e7), Bearing(1, 1e7, kyx=-2e5)])
    with pytest.raises(ValueError) as python:
        driveline.determinant(100.0, 0.0)
    with pytest.raises(ValueError) as native:
        NativeChain(lib, driveline)
    assert str(native.value) == str(python.value)
    assert "cross-coupled" in str(native.value)


def _three_segments(masses, bearings, hinges, **cross) -> Driveline:
    return Driveline([ShaftSegment(0.5, 0.05)] * 3, masses=[_joint(node) for node in masses],
                     bearings=[Bearing(node, 1e7, **cross) for node in bearings],
                     joints=[Hinge(node) for node in hinges])


@pytest.mark.parametrize("masses, bearings, hinges", [
    ((4,), (0, 3), (1,)),  # nodes are 0..3
    ((1,), (0, 7), (2,)),
    ((1, 2), (0, 3), (0,)),  # a hinge at an end
    ((1,), (0, 3), (2, 3)),
    ((1,), (0, 3), (9,)),
])
def test_nodes_are_checked_as_the_driveline_checks_them(lib, masses, bearings, hinges):
    """``chain_new`` refuses a point element off the nodes, or a hinge at an end, with the message
    of ``Driveline.__post_init__`` (where no Python driveline with such nodes gets made), before
    a bearing's cross-coupling, as the Python core refuses a driveline before building its chain."""
    with pytest.raises(ValueError) as python:
        _three_segments(masses, bearings, hinges)
    struct = c_driveline(_three_segments([1] * len(masses), [0] * len(bearings), [1] * len(hinges), kyx=-2e5))
    for array, nodes in ((struct.masses, masses), (struct.bearings, bearings), (struct.hinges, hinges)):
        for i, node in enumerate(nodes):
            array[i].node = node
    error, chain = ctypes.create_string_buffer(ERROR_SIZE), ctypes.c_void_p()
    kind = lib.chain_new(ctypes.byref(struct), ctypes.byref(chain), error, ERROR_SIZE)
    assert not chain
    assert (kind, error.value.decode()) == (ERROR_KIND["ERROR_VALUE"], str(python.value))


@pytest.mark.parametrize(
    "call",
    [
        lambda d: d.order_resonances((1,), ("forward",), None, None),
        lambda d: d.order_resonances((1,), ("forward",), -2, None),
        lambda d: d.order_resonances((1,), ("forward",), 3, -1.5e-7),
        lambda d: d.order_resonances((1,), ("forward",), 3, float("nan")),
        lambda d: d.order_resonances((2, 0), ("forward",), 3, None),
        lambda d: d.order_resonances((1,), ("forward",), 3, None, -123.25),
        lambda d: d.order_resonances((1,), ("forward",), 3, None, -1e16),
        lambda d: d.order_resonances((1,), ("forward",), 3, None, float("inf")),
        lambda d: d.critical_speeds(0),
    ],
)
def test_error_texts(lib, call):
    driveline = _tube(True)
    with pytest.raises(ValueError) as python:
        call(driveline)
    with pytest.raises(ValueError) as native:
        call(NativeChain(lib, driveline))
    assert str(native.value) == str(python.value)


def test_default_tube_cost(lib):
    """The FMU's analysis needs the critical speeds in well under its 20 ms: one search, CPU time."""
    native = NativeChain(lib, _tube(True))
    start = time.process_time()
    for _ in range(10):
        native.critical_speeds(3)
    assert (time.process_time() - start) / 10 < 0.02


def test_close_pairs_found_in_dips(lib):
    """Bearings 0.1 % apart in x and y split every planar mode into a pair closer than the grid step:
    the pairs show as dips of |f| only and are found on the sub-grids (seed Sec. 8 reworked)."""
    driveline = Driveline([ShaftSegment(1.4, 0.0762, 0.0729)], [_joint(0), _joint(1)],
                          [Bearing(0, 1e7, kyy=0.999e7), Bearing(1, 1e7)])
    native = NativeChain(lib, driveline)
    line = np.array([(1.0, 0.0, 0.0)])
    python = driveline._line_roots(line, None, 2500.0, 1e5)
    assert np.min(np.diff(python[0])) < 1e-4 * python[0][0]  # a pair closer than a grid step
    _assert_roots(native.line_roots(line, None, 2500.0), python)
    _assert_roots(native.line_roots(line, 8, None), driveline._line_roots(line, 8, None, 1e5))


def test_rounding_level(pair):
    """The rounding level of f (transfer.determinant_and_rounding) at the points of test_determinant: a
    sum of magnitudes, without cancellation, so it agrees to the propagation's round-off (measured
    below 1e-9; checked at 1e-6, far inside the factor ROUNDING the search applies to it); f itself is
    chain_determinant's, bit for bit."""
    driveline, native = pair
    rng = np.random.default_rng(7)
    w = rng.uniform(1.0, 5000.0, 60) * (rng.choice([-1.0, 1.0], 60) if driveline.is_isotropic else 1.0)
    spin = rng.uniform(0.0, 3000.0, w.size)
    python = np.array([transfer.determinant_and_rounding(driveline._chain, a, b) for a, b in zip(w, spin)])[:, :, 0]
    f, rounding = native.determinant_and_rounding(w, spin)
    assert np.array_equal(f, native.determinant(w, spin))
    assert np.all(rounding > 0.0)
    np.testing.assert_allclose(rounding, python[:, 1], rtol=1e-6, atol=0.0)


def test_the_round_off_layout_is_searched_alike_and_quickly(lib):
    """The layout of extreme materials whose determinant ripples at its rounding level next to a close
    pair (fmu_harness.checks.analysis_work.ROUND_OFF_LAYOUT): at two speeds where the Python search once
    took 8 and 21 s, the first four roots in both cores alike, in well under a second of CPU time for
    both speeds natively. The tolerance is this layout's: its segments' stiffnesses differ 1e12-fold,
    and the two cores' determinants differ by their propagation's round-off, which moves even its simple
    roots by up to 9.4e-8 relative (measured) and the double root by a sub-grid point (1.4e-8); 2e-7."""
    driveline = loads_driveline(ROUND_OFF_LAYOUT)
    native = NativeChain(lib, driveline)
    lines = np.array([(1.0, 0.0, 0.0), (1.0, 0.0, 0.051854897560696)])
    started = time.process_time()
    found = native.line_roots(lines, 4, None)
    assert time.process_time() - started < 0.5
    python = driveline._line_roots(lines, 4, None, 1e5)
    assert [r.size for r in found] == [r.size for r in python] == [4, 4]
    for c, p in zip(found, python):
        np.testing.assert_allclose(c, p, rtol=2e-7, atol=0.0)
        assert c[2] == c[3] and p[2] == p[3]  # the pair: a double root in both


@pytest.mark.parametrize("name", ["two_piece", "spring_hinge", "anisotropic_hinged"])
def test_both_cores_pay_the_same_units(lib, name):
    """The budget's units (driveline/rotor/budget.py) of every kind of search the analysis runs (the
    critical speeds, the order resonances up to a bound and the first n, a line up to the search limit)
    are the same in both cores: the C port pays per point what the Python core pays per batch, the
    same steps of the same evaluations. Only where the two cores' round-off decides differently (a
    bracket's refinement converging one step sooner near 1e5 rad/s) do they differ, by a few
    evaluations: measured at most 60 units of 16 359 (3.7e-3, four evaluations), checked at 5e-3. Half
    the units stop either core, with the stage named (the C port's message is the model's placeholder)."""
    driveline = DRIVELINES[name]()
    native = NativeChain(lib, driveline)
    assert lib.chain_stations(native.pointer) == driveline._chain.stations
    searches = [lambda d: d.critical_speeds(3),
                lambda d: d.order_resonances((1, 2), ("forward", "backward"), None, 3000.0),
                lambda d: d.order_resonances((3,), ("forward",), 2, None),
                lambda d: d.line_roots(np.array([(1.0, 0.0, 800.0)]), None, 1e5)]
    for search in searches:
        python_budget = budget.Budget(10**12)
        with budget.spending(python_budget, "critical speeds"):
            search(PythonSearches(driveline))
        native_budget = CBudget(10**12, 0, b"", b"")
        lib.chain_set_budget(native.pointer, ctypes.byref(native_budget))
        search(native)
        paid = 10**12 - python_budget.left
        assert paid > 0 and abs(10**12 - native_budget.left - paid) <= 5e-3 * paid
        half = CBudget(paid // 2, 0, b"critical speeds", b"")
        lib.chain_set_budget(native.pointer, ctypes.byref(half))
        with pytest.raises(ValueError, match="work budget is spent"):
            search(native)
        assert half.spent and half.spent_in == b"critical speeds"
        lib.chain_set_budget(native.pointer, None)
        with pytest.raises(budget.BudgetSpent, match="in the critical speeds"), \
                budget.spending(budget.Budget(paid // 2), "critical speeds"):
            search(PythonSearches(driveline))


class PythonSearches:
    """The Python core's searches under NativeChain's names."""

    def __init__(self, driveline: Driveline) -> None:
        self.driveline = driveline

    def critical_speeds(self, n: int) -> np.ndarray:
        return self.driveline.critical_speeds(n)

    def order_resonances(self, orders, whirls, n, spin_max, limit=1e5):
        return self.driveline.order_resonances(orders, whirls, n, spin_max, limit)

    def line_roots(self, lines, n, x_max, limit=1e5):
        return self.driveline._line_roots(lines, n, x_max, limit)


def test_the_six_segment_round_off_layout_gets_the_same_verdict_in_both_cores(lib):
    """Both cores accept the same line searches and find the same roots: the Campbell table's lines at
    standstill up to the search limit (both whirl senses), where the native search was refused ("more than
    512 dips on one line") and the Python one was not (issue 45, defect 6). Near w = 16 457 rad/s the
    determinant is noise of about 5e10 where the end determinant's rounding level says 1.5e-4; the level of
    a dip's points now takes the difference from a second evaluation with every segment cut into one more
    piece (the propagation's round-off, about the noise), so that neither core re-scans that dip below what
    f resolves: both find its pair of roots there, 1e-8 apart relative. The tolerance is the round-off
    layout's (above), 2e-7 relative: measured 1.0e-7 (the root at 97.3 rad/s)."""
    driveline = loads_driveline(SIX_SEGMENT_LAYOUT)
    native = NativeChain(lib, driveline)
    lines = np.array([(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0)])
    python = driveline._line_roots(lines, None, SEARCH_LIMIT, SEARCH_LIMIT)
    found = native.line_roots(lines, None, SEARCH_LIMIT, SEARCH_LIMIT)
    assert [r.size for r in found] == [r.size for r in python] == [18, 18]
    for c, p in zip(found, python):
        np.testing.assert_allclose(c, p, rtol=2e-7, atol=0.0)
