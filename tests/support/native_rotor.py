"""The native CriticalSpeeds FMU's rotor library (``fmu_src/native/models/critical_speeds/``) compiled on
its own (with the shared libraries of ``fmu_src/native/lib/`` it uses), for tests that call its modules
through ctypes and compare them with the Python core.

Compiled with the native FMUs' flags (warnings as errors) except hidden visibility, so that the
library's functions can be called; a test passes the modules it needs and, where ctypes cannot call a
function directly (structures owning arrays), a small C shim of its own.

Also the ctypes mirrors of the driveline structures of ``rotor.h``, :func:`c_driveline` to fill them
from a Python :class:`~driveline.rotor.Driveline`, and :func:`declare` for the functions' signatures.
"""

from __future__ import annotations

import ctypes
import re
import subprocess
from pathlib import Path

from driveline.rotor import Driveline
from driveline.rotor.elements import Hinge

from fmu_harness.packaging import native, toolchain
from fmu_harness.packaging.native_constants import ERROR_KINDS, error_kind_name
from fmu_harness.packaging.native_constants import HEADER as CONSTANTS_HEADER
from fmu_harness.packaging.native_constants import constants_header

ROTOR_SOURCES = native.model_folder("CriticalSpeeds")
TEST_FLAGS = (*(flag for flag in toolchain.CFLAGS if not flag.startswith("-fvisibility")), "-fPIC")

#: Relative rounding of the unbalance response and the bearing forces: the banded solve of the dynamic stiffness
#: rounds at about cond eps (largest deviation from a cubic through 41 speeds 1e-5 |omega_in| apart, both cores,
#: measured 2026-11-27: 5.2e-13 at the FMU's start values to 9.8e-12 on tests/support/anisotropic_tube.toml)
SOLVE_ROUNDING = 3e-11

P = ctypes.POINTER
DOUBLE_P = P(ctypes.c_double)
#: The generated enum ErrorKind, which a function that fails with a message returns (a C int).
ErrorKind = ctypes.c_int
#: The value of each kind's name in the generated header (ERROR_NONE is 0).
ERROR_KIND = {name: int(value) for name, value in re.findall(r"\b(ERROR_[A-Z_]+) = (-?\d+)", constants_header())}


def raised(kind: int, message: str) -> Exception:
    """The Python exception that the ErrorKind value ``kind`` stands for, with ``message``."""
    exceptions = {ERROR_KIND[error_kind_name(exception)]: exception for exception in ERROR_KINDS}
    return exceptions[kind](message)


#: The modules a module calls into besides itself (the layout reader's parts, shared in ``lib/``, and the
#: elements' checks with the loader, the linear algebra with the damped model, the shaft elements with both
#: models).
NEEDS = {"layout": ("layout_file", "toml", "messages", "arena", "elements"), "damped": ("linalg",),
         "unbalance_outputs": ("damped", "linalg"),
         "transfer": ("elements",), "fem": ("elements",)}


def compile_rotor(folder: Path, modules: list[str], shims: list[Path] = ()) -> ctypes.CDLL:
    """The shared library of the rotor ``modules`` (``"transfer"`` is ``transfer.c``) with the modules
    they need (:data:`NEEDS`) and ``shims``, built in ``folder``; a module not in the rotor's folder is
    one of ``lib/`` (``"toml"`` is ``lib/toml.c``)."""
    needed = list(dict.fromkeys(part for module in modules for part in (module, *NEEDS.get(module, ()))))
    sources = [str(next(path for folder in (ROTOR_SOURCES, native.LIBRARY_SOURCES)
                        if (path := folder / f"{module}.c").is_file())) for module in needed]
    sources += [str(shim) for shim in shims]
    (folder / CONSTANTS_HEADER).write_text(constants_header())  # the native build's generated header
    library = folder / f"rotor_{'_'.join(modules)}.so"
    command = [*toolchain.host_compiler(), *TEST_FLAGS, "-shared", "-I", str(ROTOR_SOURCES),
               "-I", str(native.NATIVE_SRC), "-I", str(folder), *sources,
               str(native.LIBRARY_SOURCES / "python_numbers.c"), "-o", str(library), "-lm"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(f"compiling {', '.join(modules)} failed:\n{done.stderr}")
    return ctypes.CDLL(str(library))


def declare(lib: ctypes.CDLL, signatures: dict[str, tuple]) -> ctypes.CDLL:
    """Sets each named function's ``(restype, argtypes)``; returns ``lib``."""
    for name, (restype, argtypes) in signatures.items():
        function = getattr(lib, name)
        function.restype, function.argtypes = restype, argtypes
    return lib


# ---- rotor.h: the driveline ---------------------------------------------------------------------
#: EndCondition by the Python core's end names.
END_CONDITIONS = {"free": 0, "pinned": 1, "clamped": 2}


class RotorSegment(ctypes.Structure):
    _fields_ = [(name, ctypes.c_double) for name in
                ("length", "outer_diameter", "inner_diameter", "youngs_modulus", "density", "poisson_ratio")] + [
        (name, ctypes.c_int) for name in ("rotary_inertia", "gyroscopic", "shear")]


class RotorMass(ctypes.Structure):
    _fields_ = [("node", ctypes.c_int)] + [(name, ctypes.c_double) for name in
                                           ("mass", "polar_inertia", "diametral_inertia")]


class RotorBearing(ctypes.Structure):
    _fields_ = [("node", ctypes.c_int)] + [(name, ctypes.c_double) for name in
                                           ("kxx", "kyy", "cxx", "cyy", "kxy", "kyx", "cxy", "cyx")]


class RotorHinge(ctypes.Structure):
    _fields_ = [("node", ctypes.c_int), ("bending_stiffness", ctypes.c_double)]


class RotorUnbalance(ctypes.Structure):
    _fields_ = [(name, ctypes.c_double) for name in ("position", "amount", "phase")]


class CDriveline(ctypes.Structure):
    """rotor.h's ``Driveline``."""
    _fields_ = [(name, ctypes.c_int) for name in
                ("n_segments", "n_masses", "n_bearings", "n_hinges", "n_unbalances")] + [
        ("segments", P(RotorSegment)), ("masses", P(RotorMass)), ("bearings", P(RotorBearing)),
        ("hinges", P(RotorHinge)), ("unbalances", P(RotorUnbalance)), ("left", ctypes.c_int), ("right", ctypes.c_int)]


class OnePieceShaft(ctypes.Structure):
    _fields_ = [(name, ctypes.c_double) for name in
                ("L_shaft", "D_outer", "D_inner", "E", "density", "m_joint", "Jp_joint", "Jd_joint", "k_bearing",
                 "c_bearing")] + [("shear", ctypes.c_int)]


#: The signatures of the chain functions (transfer.c) that take a driveline.
CHAIN_SIGNATURES = {
    "chain_new": (ErrorKind, [P(CDriveline), P(ctypes.c_void_p), ctypes.c_char_p, ctypes.c_size_t]),
    "chain_free": (None, [ctypes.c_void_p]),
}


def c_array(kind: type, items: list) -> ctypes.Array:
    """A ctypes array of ``items`` (at least one entry, so that it always has an address)."""
    return (kind * max(len(items), 1))(*items)


def unbalances(items) -> ctypes.Array:
    """The RotorUnbalance array of Python :class:`~driveline.rotor.Unbalance` ``items``."""
    return c_array(RotorUnbalance, [RotorUnbalance(u.position, u.amount, u.phase) for u in items])


def c_driveline(d: Driveline) -> CDriveline:
    """The C twin of ``d``; it keeps the arrays it points into alive as its attribute ``arrays``."""
    assert all(isinstance(joint, Hinge) for joint in d.joints), "rotor.h has hinges as its only joints"
    arrays = (
        c_array(RotorSegment, [RotorSegment(s.length, s.outer_diameter, s.inner_diameter, s.youngs_modulus,
                                            s.density, s.poisson_ratio, int(s.rotary_inertia), int(s.gyroscopic),
                                            int(s.shear)) for s in d.segments]),
        c_array(RotorMass, [RotorMass(m.node, m.mass, m.polar_inertia, m.diametral_inertia) for m in d.masses]),
        c_array(RotorBearing, [RotorBearing(b.node, b.kxx, b.k_yy, b.cxx, b.c_yy, b.kxy, b.kyx, b.cxy, b.cyx)
                               for b in d.bearings]),
        c_array(RotorHinge, [RotorHinge(h.node, h.bending_stiffness) for h in d.joints]),
        unbalances(d.unbalances),
    )
    out = CDriveline(len(d.segments), len(d.masses), len(d.bearings), len(d.joints), len(d.unbalances), *arrays,
                     END_CONDITIONS[d.left.value], END_CONDITIONS[d.right.value])
    out.arrays = arrays
    return out
