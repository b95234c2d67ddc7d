"""The native rotor library's cubic splines (``spline.c``) against scipy's CubicSpline (not-a-knot)."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from support.native_rotor import compile_rotor

#: Agreement relative to the data's scale (largest |y| of the column): the slopes come from the same
#: pivoted elimination as scipy's, so the values differ by round-off alone (measured: at most 1.9e-14).
RTOL = 1e-13


class Spline(ctypes.Structure):
    _fields_ = [("n", ctypes.c_int), ("m", ctypes.c_int), ("x", ctypes.POINTER(ctypes.c_double)),
                ("c", ctypes.POINTER(ctypes.c_double))]


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    lib = compile_rotor(tmp_path_factory.mktemp("spline"), ["spline"])
    double_p = ctypes.POINTER(ctypes.c_double)
    lib.cubic_spline_build.argtypes = [ctypes.POINTER(Spline), ctypes.c_int, double_p, ctypes.c_int, double_p]
    lib.cubic_spline_build.restype = ctypes.c_int
    lib.cubic_spline_evaluate.argtypes = [ctypes.POINTER(Spline), ctypes.c_double, double_p]
    lib.cubic_spline_evaluate.restype = None
    lib.cubic_spline_value.argtypes = [ctypes.POINTER(Spline), ctypes.c_double, ctypes.c_int]
    lib.cubic_spline_value.restype = ctypes.c_double
    lib.cubic_spline_free.argtypes = [ctypes.POINTER(Spline)]
    lib.cubic_spline_free.restype = None
    return lib


def assert_close_to_scale(got: np.ndarray, expected: np.ndarray, y: np.ndarray) -> None:
    """``got`` within RTOL of each column's largest |y| of ``expected``."""
    error = np.max(np.abs(got - expected), axis=0, initial=0.0) / np.max(np.abs(y), axis=0)
    assert np.all(error <= RTOL), f"relative differences {error}"


def _pointer(a: np.ndarray):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


def native_spline(lib, x: np.ndarray, y: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The native spline of ``y`` (n, m) over ``x`` evaluated at every ``at``."""
    x = np.ascontiguousarray(x, dtype=float)
    y = np.ascontiguousarray(y, dtype=float)
    spline = Spline()
    assert lib.cubic_spline_build(ctypes.byref(spline), x.size, _pointer(x), y.shape[1], _pointer(y)) == 0
    try:
        out = np.empty((at.size, y.shape[1]))
        row = np.empty(y.shape[1])
        for i, v in enumerate(at):
            lib.cubic_spline_evaluate(ctypes.byref(spline), float(v), _pointer(row))
            out[i] = row
            single = [lib.cubic_spline_value(ctypes.byref(spline), float(v), j) for j in range(y.shape[1])]
            np.testing.assert_array_equal(single, row)  # one column alone: the same value
        return out
    finally:
        lib.cubic_spline_free(ctypes.byref(spline))


def _points(x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Every knot, points inside every interval, and points beyond both ends."""
    span = x[-1] - x[0]
    inside = x[:-1, None] + rng.random((x.size - 1, 3)) * np.diff(x)[:, None]
    beyond = np.concatenate([x[0] - span * rng.random(4) * 0.2, x[-1] + span * rng.random(4) * 0.2])
    return np.concatenate([x, inside.ravel(), beyond, np.nextafter(x, -np.inf), np.nextafter(x, np.inf)])


@pytest.mark.parametrize("n", [2, 3, 4, 5, 6, 9, 41, 120])
@pytest.mark.parametrize("m", [1, 4])
def test_spline_matches_scipy_on_random_data(library, n, m):
    rng = np.random.default_rng(1000 * n + m)
    # Knot spacings over four decades of ratio in half the trials, two for the parabola (n = 3): its
    # cubic coefficient is round-off of the order eps |slope| / dx^2, which an uneven pair of spacings
    # magnifies beyond the ends in scipy's spline as in this one (1e-9 of the data at 600:1).
    decades = 1.0 if n == 3 else 2.0
    for trial in range(20):
        spacing = rng.random(n - 1) + 0.05 if trial % 2 else 10.0 ** rng.uniform(-decades, decades, n - 1)
        x = rng.uniform(-5.0, 5.0) + np.concatenate([[0.0], np.cumsum(spacing)])
        scale = 10.0 ** rng.uniform(-3.0, 5.0, m)
        y = (rng.standard_normal((n, m)) + rng.uniform(-3.0, 3.0, m)) * scale
        at = _points(x, rng)
        expected = CubicSpline(x, y)(at)
        got = native_spline(library, x, y, at)
        assert_close_to_scale(got, expected, y)


def test_spline_of_smooth_and_constant_columns(library):
    x = np.linspace(0.0, 1500.0, 41)
    y = np.column_stack([np.sqrt(1.0 + x), np.full(x.size, 1e5), 3.0 * x - 2.0, x ** 3 / 1e6])
    at = np.linspace(-100.0, 1600.0, 997)
    got = native_spline(library, x, y, at)
    assert_close_to_scale(got, CubicSpline(x, y)(at), y)
    assert np.all(got[:, 1] == 1e5)  # a constant column stays exactly constant


def test_spline_interval_choice_at_the_knots(library):
    # a kinked data set: scipy evaluates a knot with the interval to its right, the last knot with the last
    x = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    y = np.array([[0.0], [1.0], [0.0], [5.0], [-2.0]])
    at = np.concatenate([x, [np.nan, -np.inf, np.inf]])
    got = native_spline(library, x, y, at)
    expected = CubicSpline(x, y)(at)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(expected))
    finite = np.isfinite(expected)
    np.testing.assert_allclose(got[finite], expected[finite], rtol=0.0, atol=RTOL * 5.0)


def test_bad_knots_are_refused(library):
    for x in ([0.0], [0.0, 0.0, 1.0], [0.0, 2.0, 1.0], [0.0, np.nan, 1.0]):
        x = np.asarray(x, dtype=float)
        y = np.zeros((x.size, 1))
        spline = Spline()
        assert library.cubic_spline_build(ctypes.byref(spline), x.size, _pointer(x), 1, _pointer(y)) == -1
        library.cubic_spline_free(ctypes.byref(spline))
