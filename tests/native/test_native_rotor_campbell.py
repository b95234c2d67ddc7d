"""The native rotor library's Campbell table (``campbell.c`` on ``transfer.c``/``roots.c``) against the
Python core's ``model.whirl_table``: the same branches through the same knots, so the same table."""

from __future__ import annotations

import ctypes
import dataclasses
import time

import numpy as np
import pytest

from driveline.rotor import Bearing, Driveline, example_path, load_driveline, one_piece_shaft
from driveline.rotor.campbell import whirl_branches
from driveline.rotor.model import CAMPBELL_POINTS, WHIRL_MODES, analyse_structure, whirl_table

from support.native_rotor import (CHAIN_SIGNATURES, DOUBLE_P, ERROR_KIND, ROTOR_SOURCES, ErrorKind, P, c_driveline,
                                  compile_rotor, declare)

#: Agreement of every whirl frequency, relative to the largest magnitude of its column over the speeds
#: compared. The C port evaluates the same determinant at the same points, follows the same branches
#: through the same knots (their count is compared exactly) and splines them as scipy does, so the
#: tables differ by round-off alone: measured at most 1.5e-15 (tubes, two-piece layouts), 6.7e-15
#: (crossing branches), 7.6e-15 (anisotropic bearings: the roots' own search round-off). 1e-12 is
#: campbell.SPLINE_RTOL, the interpolation error the table aims at: a difference below it is below what
#: the table claims to resolve, and a different refinement, which would hide under it, shows in the
#: knot count.
RTOL = 1e-12
#: Speeds compared: knots, between knots and both ends.
SPEEDS = 200


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    missing = [m for m in ("transfer", "roots") if not (ROTOR_SOURCES / f"{m}.c").is_file()]
    if missing:
        pytest.skip(f"the rotor library has no {' or '.join(missing)} module yet")
    lib = compile_rotor(tmp_path_factory.mktemp("campbell"), ["transfer", "roots", "spline", "campbell"])
    table = ctypes.c_void_p
    return declare(lib, {
        **CHAIN_SIGNATURES,
        "whirl_table_new": (ErrorKind, [ctypes.c_void_p, ctypes.c_double, ctypes.c_int, ctypes.c_int, P(table),
                                        ctypes.c_char_p, ctypes.c_size_t]),
        "whirl_table_evaluate": (None, [table, ctypes.c_double, DOUBLE_P]),
        "whirl_table_knots": (ctypes.c_int, [table]),
        "whirl_table_free": (None, [table]),
    })


class NativeTable:
    """whirl_table_new on the chain of a driveline; ``seconds``: the CPU time it took."""

    def __init__(self, lib, d: Driveline, omega_max: float, n_modes: int = WHIRL_MODES,
                 points: int = CAMPBELL_POINTS) -> None:
        self._lib, self._n = lib, n_modes
        self._driveline = driveline = c_driveline(d)
        error, chain, table = ctypes.create_string_buffer(512), ctypes.c_void_p(), ctypes.c_void_p()
        assert lib.chain_new(ctypes.byref(driveline), ctypes.byref(chain), error, len(error)) == ERROR_KIND[
            "ERROR_NONE"], error.value.decode()
        self._chain = chain.value
        start = time.process_time()
        self.kind = lib.whirl_table_new(self._chain, omega_max, points, n_modes, ctypes.byref(table), error, len(error))
        self.seconds = time.process_time() - start
        self._table, self.error = table.value, error.value.decode()

    def close(self) -> None:
        if self._table:
            self._lib.whirl_table_free(self._table)
        self._lib.chain_free(self._chain)
        self._table = self._chain = None

    @property
    def knots(self) -> int:
        return self._lib.whirl_table_knots(self._table)

    def __call__(self, speed: float) -> np.ndarray:
        out = (ctypes.c_double * (2 * self._n))()
        self._lib.whirl_table_evaluate(self._table, speed, out)
        return np.array(out)


def tube(shear: bool = True) -> Driveline:
    """The FMU's default one-piece tube (Timoshenko, or Rayleigh)."""
    return one_piece_shaft(1.4, 0.0762, 0.0729, 2.1e11, 7850.0, 2.5, 0.004, 0.002, 1e7, shear=shear)


def crossing() -> Driveline:
    """tests/core/test_rotor_campbell.py's heavy joints on soft bearings: two backward branches cross."""
    return one_piece_shaft(1.4, 0.0762, 0.0729, 2.1e11, 7850.0, 10.0, 0.2, 0.1, 3e5)


def anisotropic() -> Driveline:
    """The default tube with bearings five times softer vertically."""
    d = tube()
    return dataclasses.replace(d, bearings=[Bearing(b.node, b.kxx, 0.2 * b.kxx) for b in d.bearings])


def gyroscopic() -> Driveline:
    """tests/core/test_rotor_campbell.py's joints of large polar inertia: up to 10000 rad/s a forward branch
    leaves the first search bound, which is widened."""
    return one_piece_shaft(1.4, 0.0762, 0.0729, 2.1e11, 7850.0, 2.5, 2.0, 0.1, 1e7)


def beyond_the_limit() -> Driveline:
    """tests/core/test_rotor_campbell.py's short shaft on stiff bearings: up to 20000 rad/s a forward branch
    leaves the search limit between the first speeds, the complete branches are refined."""
    return one_piece_shaft(0.5, 0.0762, 0.0729, 2.1e11, 7850.0, 10.0, 1.0, 0.1, 1e9)


CASES = {
    "tube-1500": (tube, 1500.0),
    "tube-6000": (tube, 6000.0),
    "rayleigh-tube-1500": (lambda: tube(False), 1500.0),
    "rayleigh-tube-6000": (lambda: tube(False), 6000.0),
    "two-piece": (lambda: load_driveline(example_path("two_piece_propshaft")), 1500.0),
    "two-piece-hinged": (lambda: load_driveline(example_path("two_piece_propshaft_hinged")), 1500.0),
    "crossing": (crossing, 1500.0),
    "anisotropic": (anisotropic, 1500.0),
    "gyroscopic-10000": (gyroscopic, 10000.0),
    "beyond-the-limit-20000": (beyond_the_limit, 20000.0),
}


def speeds_for(omega_max: float, knots: np.ndarray) -> np.ndarray:
    """About SPEEDS speeds over [0, omega_max]: equal steps off the knots, some knots, both ends."""
    between = np.linspace(0.0, omega_max, SPEEDS - 20)[1:-1] + 0.123 * omega_max / SPEEDS
    return np.unique(np.concatenate([[0.0, omega_max], between, knots[:: max(knots.size // 18, 1)]]))


@pytest.mark.parametrize("case", CASES)
def test_native_whirl_table_matches_the_python_one(library, case):
    make, omega_max = CASES[case]
    d = make()
    expected_table = whirl_table(analyse_structure(d), omega_max)
    branches = whirl_branches(d, np.linspace(0.0, omega_max, CAMPBELL_POINTS), WHIRL_MODES)
    native = NativeTable(library, d, omega_max)
    try:
        assert native.error == ""
        assert native.knots == branches.spins.size
        speeds = speeds_for(omega_max, branches.spins)
        expected = np.array([expected_table(s) for s in speeds])
        got = np.array([native(s) for s in speeds])
    finally:
        native.close()
    scale = np.max(np.abs(expected), axis=0)
    difference = np.max(np.abs(got - expected), axis=0) / scale
    assert np.all(difference <= RTOL), f"{case}: relative differences {difference}"


def test_bad_speed_ranges_are_refused(library):
    for omega_max, points in ((0.0, 41), (-1.0, 41), (float("nan"), 41), (1500.0, 1)):
        native = NativeTable(library, tube(), omega_max, points=points)
        try:
            assert native.error == "spins must be at least two increasing finite speeds >= 0 rad/s"
            assert native.kind == ERROR_KIND["ERROR_VALUE"] and not native._table
        finally:
            native.close()
