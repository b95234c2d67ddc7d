"""ctypes mirrors of the driveline structures of the native rotor library (``rotor.h``), built from
a Python :class:`~driveline.rotor.Driveline`, for tests that call the library directly."""

from __future__ import annotations

import ctypes

from driveline.rotor import Driveline
from driveline.rotor.elements import Hinge

END = {"free": 0, "pinned": 1, "clamped": 2}


class Segment(ctypes.Structure):
    _fields_ = [(name, ctypes.c_double) for name in ("length", "outer_diameter", "inner_diameter", "youngs_modulus",
                                                      "density", "poisson_ratio")] + \
               [(name, ctypes.c_int) for name in ("rotary_inertia", "gyroscopic", "shear")]


class Mass(ctypes.Structure):
    _fields_ = [("node", ctypes.c_int), ("mass", ctypes.c_double), ("polar_inertia", ctypes.c_double),
                ("diametral_inertia", ctypes.c_double)]


class Bearing(ctypes.Structure):
    _fields_ = [("node", ctypes.c_int)] + [(name, ctypes.c_double) for name in
                                           ("kxx", "kyy", "cxx", "cyy", "kxy", "kyx", "cxy", "cyx")]


class Hinge_(ctypes.Structure):
    _fields_ = [("node", ctypes.c_int), ("bending_stiffness", ctypes.c_double)]


class Unbalance(ctypes.Structure):
    _fields_ = [("position", ctypes.c_double), ("amount", ctypes.c_double), ("phase", ctypes.c_double)]


class CDriveline(ctypes.Structure):
    _fields_ = [(name, ctypes.c_int) for name in ("n_segments", "n_masses", "n_bearings", "n_hinges",
                                                   "n_unbalances")] + [
        ("segments", ctypes.POINTER(Segment)), ("masses", ctypes.POINTER(Mass)), ("bearings", ctypes.POINTER(Bearing)),
        ("hinges", ctypes.POINTER(Hinge_)), ("unbalances", ctypes.POINTER(Unbalance)),
        ("left", ctypes.c_int), ("right", ctypes.c_int)]


def _array(kind, items):
    array = (kind * max(1, len(items)))(*items)
    return array, ctypes.cast(array, ctypes.POINTER(kind))


def unbalances(items) -> tuple:
    """A ctypes array of RotorUnbalance and its pointer."""
    return _array(Unbalance, [Unbalance(u.position, u.amount, u.phase) for u in items])


def c_driveline(d: Driveline) -> CDriveline:
    """The C twin of ``d`` (it keeps its arrays alive as attributes)."""
    segments = [Segment(s.length, s.outer_diameter, s.inner_diameter, s.youngs_modulus, s.density, s.poisson_ratio,
                        int(s.rotary_inertia), int(s.gyroscopic), int(s.shear)) for s in d.segments]
    masses = [Mass(m.node, m.mass, m.polar_inertia, m.diametral_inertia) for m in d.masses]
    bearings = [Bearing(b.node, b.kxx, b.k_yy, b.cxx, b.c_yy, b.kxy, b.kyx, b.cxy, b.cyx) for b in d.bearings]
    hinges = [Hinge_(h.node, h.bending_stiffness) for h in d.joints if isinstance(h, Hinge)]
    assert len(hinges) == len(d.joints)
    arrays = [_array(kind, items) for kind, items in ((Segment, segments), (Mass, masses), (Bearing, bearings),
                                                     (Hinge_, hinges))]
    kept = unbalances(d.unbalances)
    out = CDriveline(len(segments), len(masses), len(bearings), len(hinges), len(d.unbalances),
                     arrays[0][1], arrays[1][1], arrays[2][1], arrays[3][1], kept[1], END[d.left.value],
                     END[d.right.value])
    out._keep = (arrays, kept)
    return out
