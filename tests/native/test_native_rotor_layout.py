"""The native rotor library's layout reader (layout.c) and repr (pyrepr.c) against the Python loader:
the same drivelines, field for field and bit for bit, and the same messages."""

from __future__ import annotations

import ctypes
import json
import math
import os
import random
import struct
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from driveline.rotor import loader
from driveline.rotor.loader import load_driveline, loads_driveline, one_piece_shaft
from driveline.rotor.model import load_layout

from support.native_rotor import (ERROR_KIND, CDriveline, ErrorKind, OnePieceShaft, P, RotorBearing, RotorHinge,
                                  RotorMass, RotorSegment, RotorUnbalance, compile_rotor, declare)

DATA = Path(loader.__file__).parent / "data"
ERROR_SIZE = 8192


@pytest.fixture(scope="module")
def lib(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    library = compile_rotor(tmp_path_factory.mktemp("layout"), ["layout", "pyrepr"])
    driveline_p, error, size = P(CDriveline), ctypes.c_char_p, ctypes.c_size_t
    return declare(library, {
        "driveline_length": (ctypes.c_double, [driveline_p]),
        "driveline_from_text": (ErrorKind, [ctypes.c_char_p, size, ctypes.c_char_p, driveline_p, error, size]),
        "driveline_from_layout": (ErrorKind, [ctypes.c_char_p, ctypes.c_char_p, driveline_p, error, size]),
        "driveline_one_piece": (ErrorKind, [P(OnePieceShaft), driveline_p, error, size]),
        "python_str_repr_n": (None, [ctypes.c_char_p, size, size, ctypes.c_char_p, size]),
        "python_float_repr": (None, [ctypes.c_double, ctypes.c_char_p, size]),
    })


def bits(value: float) -> bytes:
    return struct.pack("<d", value)


def native_fields(d: CDriveline) -> dict:
    """The driveline's fields, the numbers as their bits."""
    def rows(pointer, count, names):
        return [tuple(bits(v) if isinstance(v, float) else v for v in (getattr(pointer[i], n) for n in names))
                for i in range(count)]
    return {
        "segments": rows(d.segments, d.n_segments, [f[0] for f in RotorSegment._fields_]),
        "masses": rows(d.masses, d.n_masses, [f[0] for f in RotorMass._fields_]),
        "bearings": rows(d.bearings, d.n_bearings, [f[0] for f in RotorBearing._fields_]),
        "hinges": rows(d.hinges, d.n_hinges, [f[0] for f in RotorHinge._fields_]),
        "unbalances": rows(d.unbalances, d.n_unbalances, [f[0] for f in RotorUnbalance._fields_]),
        "ends": (d.left, d.right),
    }


def python_fields(drv) -> dict:
    ends = ("free", "pinned", "clamped")
    return {
        "segments": [(bits(s.length), bits(s.outer_diameter), bits(s.inner_diameter), bits(s.youngs_modulus),
                      bits(s.density), bits(s.poisson_ratio), int(s.rotary_inertia), int(s.gyroscopic),
                      int(s.shear)) for s in drv.segments],
        "masses": [(m.node, bits(m.mass), bits(m.polar_inertia), bits(m.diametral_inertia)) for m in drv.masses],
        "bearings": [(b.node, *(bits(float(v)) for v in (b.kxx, b.k_yy, b.cxx, b.c_yy, b.kxy, b.kyx, b.cxy, b.cyx)))
                     for b in drv.bearings],
        "hinges": [(h.node, bits(h.bending_stiffness)) for h in drv.joints],
        "unbalances": [(bits(u.position), bits(u.amount), bits(u.phase)) for u in drv.unbalances],
        "ends": (ends.index(drv.left.value), ends.index(drv.right.value)),
    }


def native_result(lib: ctypes.CDLL, call, *args):
    """(fields, length) or the message of a native call (refused as a ValueError, as Python's)."""
    d, error = CDriveline(), ctypes.create_string_buffer(ERROR_SIZE)
    status = call(*args, ctypes.byref(d), error, ERROR_SIZE)
    if status != ERROR_KIND["ERROR_NONE"]:
        assert status == ERROR_KIND["ERROR_VALUE"] and not d.segments and d.n_segments == 0
        return error.value.decode("utf-8", "surrogateescape")
    try:
        return native_fields(d), lib.driveline_length(ctypes.byref(d))
    finally:
        lib.driveline_free(ctypes.byref(d))


def python_result(function, *args):
    try:
        drv = function(*args)
    except ValueError as exc:
        return str(exc)
    return python_fields(drv), drv.length


def from_text(lib: ctypes.CDLL, text: str | bytes, source: str = "<string>"):
    raw = text.encode() if isinstance(text, str) else text
    return native_result(lib, lib.driveline_from_text, raw, len(raw), source.encode())


def from_layout(lib: ctypes.CDLL, layout: str, resources: Path = DATA):
    return native_result(lib, lib.driveline_from_layout, os.fsencode(layout), os.fsencode(resources))


def same(native, python) -> None:
    """Equal drivelines (the length within one ulp) or equal messages (a tomllib one up to its reason)."""
    if isinstance(python, str):
        assert isinstance(native, str), f"native accepted what Python refuses: {python}"
        if "malformed TOML: " in python:
            head = python[:python.index("malformed TOML: ") + len("malformed TOML: ")]
            assert native.startswith(head), (native, python)
        else:
            assert native == python
        return
    assert not isinstance(native, str), f"native refused: {native}"
    assert native[0] == python[0]
    assert abs(native[1] - python[1]) <= math.ulp(python[1])


STEEL = """
[materials.steel]
youngs_modulus = 2.1e11
density = 7850.0
"""

SHIPPED = (DATA / "two_piece_propshaft.toml").read_text()
#: The shipped layout's material and its three segments (0.7 m, 0.1 m, 0.8 m long).
SEGMENTS = SHIPPED[SHIPPED.index("[materials.steel]"):SHIPPED.index("[[masses]]")]

ONE = '[[segments]]\nlength = 1.0\nouter_diameter = 0.05\nyoungs_modulus = 2.1e11\ndensity = 7850.0\n'

VALID = {
    "shipped": SHIPPED,
    "shipped hinged": (DATA / "two_piece_propshaft_hinged.toml").read_text(),
    "positions cut segments": SEGMENTS + """
[[masses]]
position = 0.35
mass = 1.0
[[masses]]
position = 0.35          # the same cut once
mass = 0.5
polar_inertia = 1e-3
[[masses]]
position = 1.2
mass = 2.0
diametral_inertia = 2e-3
[[bearings]]
position = 0.0
stiffness = 1e7
[[bearings]]
position = 0.7000000004  # within NODE_SNAP of node 1
kxx = 2e6
kyy = 1e6
[[bearings]]
position = 1.6000000005  # within NODE_SNAP beyond the right end
stiffness = 1e7
[[hinges]]
position = 0.9
[[hinges]]
node = 2
bending_stiffness = 250.0
[[unbalances]]
phase = -0.5
amount = 1e-4
position = 0.123
[[unbalances]]
amount = 2e-4
node = 3
[[unbalances]]
amount = 0
position = 1.6000000009  # within NODE_SNAP beyond the right end: at the end
""",
    "inline tables and dotted keys": """
name = 'inline'   # literal string
materials = {steel = {youngs_modulus = 2.1e11, density = 7850}, alu.youngs_modulus = 7e10, alu.density = 2700}
segments = [
  {length = 0.5, outer_radius = 0.03, inner_radius = 0.025, material = "alu"},  # a comment
  {length = 1, outer_diameter = 0.04, inner_diameter = 0.0, material = "steel", density = 8000},
]
bearings = [{node = 0, stiffness = 1e7, damping = 250},
            {node = 2, kxx = 1e7, kyy = 2e7, cxx = 10, cyy = 20, kxy = -1e5, kyx = 1e5, cxy = -0.5, cyx = 0.5}]
masses.label = "ignored"
""".replace("masses.label = \"ignored\"\n", ""),
    "dotted keys in sections": """
materials.steel.youngs_modulus = 2.1e11
materials.steel.density = 7850.0
left_end = "pinned"
right_end = "clamped"
[[segments]]
length = 2.0
outer_diameter = 0.1
material = "steel"
rotary_inertia = false
gyroscopic = false
shear = false
label.text = "first"
label.more = [1, 2.5, "x", true, {a = 1}]
[[segments]]
length = 1_000.5e-3
outer_radius = 5e-2
wall_thickness = 5e-3
material = "steel"
poisson_ratio = 0
[[segments]]
"length" = +0.25
'outer_diameter' = 0.05
youngs_modulus = 2e11
density = 7.8e3
poisson_ratio = 0.25
[[masses]]
node = 0x1
mass = 3
[[masses]]
node = 0o2
mass = 1.5e0
[[masses]]
node = 0b11
mass = 0.0
[[hinges]]
node = 1
[[unbalances]]
node = 0
amount = 1E-3
phase = -0.0
""",
    "escapes and strings": (
        'name = "tab\\t quote\\" backslash\\\\ unicode\\u00e9\\U0001F600 \\b\\f\\r\\n"\n'
        + ONE
        + 'label = """\nmulti "line" \\\n    continued ""quotes"" """""\n'
        + "[[bearings]]\nnode = 0\nstiffness = 1e7\n"
        + "label = \'\'\'\nraw \\n 'text' \'\'\'\'\'\n"
        + "[[bearings]]\nnode = 1\nstiffness = 1e7\n"
        + "label = [\"a\", 'b', \"\"\"c\"\"\", \'\'\'d\'\'\', [[], [1]], ]\n"
    ),
    "CRLF line ends": (ONE + "[[bearings]]\nnode = 0\nstiffness = 1e7\n").replace("\n", "\r\n"),
    "array of tables below a table": ONE + """
[[bearings]]
node = 0
stiffness = 1e7
[bearings.label]
x = 1
[[bearings]]
node = 1
stiffness = 2e7
[bearings.label]
x = 2
""",
    "integers and floats": ONE + """
[[masses]]
node = 1
mass = 1_2
polar_inertia = 1e-3_0
diametral_inertia = 0.000_1
[[unbalances]]
position = 1
amount = 5e-324
phase = 1e300
[[bearings]]
node = 0
stiffness = 1.7976931348623157e308
damping = 4.9e-324
""",
    "sums that round": """
[[segments]]
length = 0.1
outer_diameter = 0.05
youngs_modulus = 2.1e11
density = 7850.0
[[segments]]
length = 0.2
outer_diameter = 0.05
youngs_modulus = 2.1e11
density = 7850.0
[[segments]]
length = 0.3
outer_diameter = 0.05
youngs_modulus = 2.1e11
density = 7850.0
[[masses]]
position = 0.15
mass = 1
[[unbalances]]
position = 0.6000000000000001
amount = 1
""",
}


def random_layout(seed: int) -> str:
    """Segments with positions everywhere: cuts, snaps, repeats."""
    rng = random.Random(seed)
    lengths = [rng.choice([0.1, 0.2, 0.3, 0.7, 1 / 3, rng.uniform(0.05, 1.0)]) for _ in range(rng.randint(1, 6))]
    total = sum(lengths)
    parts = [STEEL]
    for length in lengths:
        parts.append(f"[[segments]]\nlength = {length!r}\nouter_diameter = 0.05\nmaterial = 'steel'\n")
    ends = [sum(lengths[:k]) for k in range(len(lengths) + 1)]

    def where() -> str:
        choice = rng.random()
        if choice < 0.3:
            return f"node = {rng.randrange(len(lengths) + 1)}"
        if choice < 0.5:
            return f"position = {rng.choice(ends) + rng.choice([0.0, 4e-10, -4e-10]):.17g}"
        return f"position = {rng.uniform(0.0, total):.17g}"

    for kind, body in (("masses", "mass = 1.0"), ("bearings", "stiffness = 1e7"), ("unbalances", "amount = 1e-3")):
        for _ in range(rng.randint(0, 8)):
            parts.append(f"[[{kind}]]\n{where()}\n{body}\n")
    for k in range(1, len(lengths)):
        if rng.random() < 0.4:
            parts.append(f"[[hinges]]\nnode = {k}\n")
    if rng.random() < 0.5 and total > 0.2:
        parts.append(f"[[hinges]]\nposition = {rng.uniform(0.1, total - 0.1):.17g}\n")
    return "".join(parts)


@pytest.mark.parametrize("name", VALID)
def test_valid_layouts_give_the_same_driveline(lib, name):
    python = python_result(loads_driveline, VALID[name])
    assert not isinstance(python, str), python
    same(from_text(lib, VALID[name]), python)


def test_random_layouts_give_the_same_driveline(lib):
    accepted = 0
    for seed in range(150):
        text = random_layout(seed)
        python = python_result(loads_driveline, text)
        same(from_text(lib, text), python)
        accepted += not isinstance(python, str)
    assert accepted > 100


M = "[[masses]]\nnode = 0\nmass = 1.0\n"
B = "[[bearings]]\nnode = 0\nstiffness = 1e7\n"
U = "[[unbalances]]\nnode = 0\namount = 1e-3\n"


def seg(body: str) -> str:
    return STEEL + "[[segments]]\n" + body + "\n"


TWO = ONE + ONE.replace("length = 1.0", "length = 0.5")

INVALID = [
    # loads_driveline: nesting, TOML, top level
    "x = " + "[" * 17 + "]" * 17 + "\n" + ONE,
    'name = "' + "{" * 17 + '"\n' + ONE,
    "[" * 9 + "a" + "]" * 9,
    ONE + "length = 2.0\n",
    ONE + "[segments]\n",
    STEEL + STEEL + ONE,
    ONE + 'name = "bad \\q escape"\n',
    ONE + 'name = "unterminated\n',
    ONE + "name = 'a' 'b'\n",
    ONE + "x = @\n",
    ONE + "x = {a = 1,\n b = 2}\n",
    ONE + "x = [{a = 1,\n b = 2}]\n",
    ONE + "x = {a = 1,}\n",
    ONE + "x = [1, 2\n",
    ONE + "x = 1__0\n",
    ONE + "x = 01\n",
    ONE + 'x = "\\ud800"\n',
    ONE + "x.y = 1\n[x]\n",
    ONE + "x = {a = 1}\nx.b = 2\n",
    ONE + "x = [1]\n[[x]]\n",
    ONE + "= 1\n",
    ONE + "x = 1\nx.y = 2\n",
    ONE + "[a.b]\n[a]\nb.c = 1\n",
    ONE + "x = {a = 1, a = 2}\n",
    ONE + 'x = "\x01"\n',
    ONE + "# comment \x7f\n",
    ONE + 'x = """abc',
    ONE + "x = 1.\n",
    ONE + "x = .5\n",
    ONE + "x = 1e\n",
    ONE + "x = truex\n",
    ONE + "x = +0x10\n",
    ONE + '"""a""" = 1\n',
    "foo = 1\nbar = 2\n" + ONE,
    "name = 5\n" + ONE,
    "name = [1, 'two']\n" + ONE,
    "left_end = 'loose'\n" + ONE,
    "right_end = 3\n" + ONE,
    "left_end = {a = 'free'}\n" + ONE,
    "materials = 3\n" + ONE,
    "materials = {steel = 5}\n" + ONE,
    "[materials.steel]\ndensity = 1\nyoungs_modulus = 1\ncolour = 'grey'\n" + ONE,
    "[materials.steel]\nyoungs_modulus = 2e11\n" + ONE,
    "[materials.steel]\ndensity = 7850\n" + ONE,
    "[materials.steel]\ndensity = 7850\nyoungs_modulus = -2e11\n" + ONE,
    "[materials.steel]\ndensity = 0\nyoungs_modulus = 2e11\n" + ONE,
    "[materials.steel]\ndensity = inf\nyoungs_modulus = 2e11\n" + ONE,
    "[materials.steel]\ndensity = 1\nyoungs_modulus = '2e11'\n" + ONE,
    "segments = 5\n",
    "segments = [1]\n",
    "[segments]\nlength = 1\n",
    "segments = []\n",
    "name = 'no segments'\n",
    ONE * 101,
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'steel'\ncolour = 'red'\nzeta = 1"),
    seg("outer_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = 'long'\nouter_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = true\nouter_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = [1]\nouter_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = {a = 1, b = [2, 'x']}\nouter_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = nan\nouter_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = -inf\nouter_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = 0\nouter_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = -0.0\nouter_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = 1\nmaterial = 'steel'"),
    seg("length = 1\nouter_diameter = 0.05\nouter_radius = 0.025\nmaterial = 'steel'"),
    seg("length = 1\nouter_radius = -0.025\nmaterial = 'steel'"),
    seg("length = 1\nouter_radius = 1e308\nmaterial = 'steel'"),
    seg("length = 1\nouter_diameter = 0.05\ninner_radius = 0.01\nwall_thickness = 0.001\nmaterial = 'steel'"),
    seg("length = 1\nouter_diameter = 0.05\ninner_diameter = -0.01\nmaterial = 'steel'"),
    seg("length = 1\nouter_diameter = 0.05\nwall_thickness = 0\nmaterial = 'steel'"),
    seg("length = 1\nouter_diameter = 0.05\nwall_thickness = 0.03\nmaterial = 'steel'"),
    seg("length = 1\nouter_diameter = 1.0\nwall_thickness = 1e-17\nmaterial = 'steel'"),
    seg("length = 1\nouter_diameter = 0.05\ninner_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = 1\nouter_radius = 0.025\ninner_radius = 3\nmaterial = 'steel'"),
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'iron'"),
    "[[segments]]\nlength = 1\nouter_diameter = 0.05\nmaterial = 'iron'\n",
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 7"),
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'steel'\nyoungs_modulus = 0"),
    seg("length = 1\nouter_diameter = 0.05\ndensity = 1"),
    seg("length = 1\nouter_diameter = 0.05\nyoungs_modulus = 1"),
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'steel'\nrotary_inertia = 1"),
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'steel'\ngyroscopic = 'yes'"),
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'steel'\nshear = 0.0"),
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'steel'\npoisson_ratio = 0.5"),
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'steel'\npoisson_ratio = -1"),
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'steel'\npoisson_ratio = true"),
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'steel'\npoisson_ratio = nan"),
    seg("length = 1\nouter_diameter = 0.05\nmaterial = 'steel'\npoisson_ratio = '0.3'"),
    # point elements: stations and the cut
    ONE + "[[masses]]\nnode = 0\nposition = 0.0\nmass = 1\n",
    ONE + "[[masses]]\nmass = 1\n",
    ONE + "[[masses]]\nnode = 1.0\nmass = 1\n",
    ONE + "[[masses]]\nnode = -1\nmass = 1\n",
    ONE + "[[masses]]\nnode = true\nmass = 1\n",
    ONE + "[[masses]]\nnode = 2\nmass = 1\n",
    ONE + "[[masses]]\nposition = -0.5\nmass = 1\n",
    ONE + "[[masses]]\nposition = 'left'\nmass = 1\n",
    ONE + "[[masses]]\nposition = 1.5\nmass = 1\n",
    ONE + "[[bearings]]\nposition = 3\nstiffness = 1\n",
    ONE + "[[masses]]\nposition = 1.0000000015\nmass = 1\n",
    ONE + "[[unbalances]]\nposition = 1.0000000015\namount = 1\n",
    TWO + "[[hinges]]\nposition = 1.50000001\n",
    ONE + "[[masses]]\nnode = 0\nmass = 1\nspin = 2\n",
    ONE + "[[masses]]\nnode = 0\n",
    ONE + "[[masses]]\nnode = 0\nmass = -1\n",
    ONE + "[[masses]]\nnode = 0\nmass = 1\npolar_inertia = 'x'\n",
    ONE + "[[masses]]\nnode = 0\nmass = 1\ndiametral_inertia = -1e-3\n",
    ONE + "masses = 5\n",
    ONE + "masses = [{node = 0, mass = 1}, 3]\n",
    ONE + M * 203,
    ONE + B * 203,
    ONE + "[[bearings]]\nnode = 0\nstiffness = 1\nkxx = 1\n",
    ONE + "[[bearings]]\nnode = 0\nstiffness = 1\nkyy = 1\n",
    ONE + "[[bearings]]\nnode = 0\n",
    ONE + "[[bearings]]\nnode = 0\nkyy = 1\n",
    ONE + "[[bearings]]\nnode = 0\nkxx = 0\n",
    ONE + "[[bearings]]\nnode = 0\nkxx = 1\nkyy = -1\n",
    ONE + "[[bearings]]\nnode = 0\nstiffness = 1\ndamping = 1\ncxx = 2\n",
    ONE + "[[bearings]]\nnode = 0\nstiffness = 1\ncyy = 2\n",
    ONE + "[[bearings]]\nnode = 0\nstiffness = 1\ncxx = -2\n",
    ONE + "[[bearings]]\nnode = 0\nstiffness = 1\ndamping = -2\n",
    ONE + "[[bearings]]\nnode = 0\nstiffness = 1\nkxy = inf\n",
    ONE + "[[bearings]]\nnode = 0\nstiffness = 1\ncyx = 'x'\n",
    ONE + "[[bearings]]\nnode = 0\nstiffness = 1\nmass = 1\n",
    TWO + "[[hinges]]\nnode = 0\n",
    TWO + "[[hinges]]\nnode = 2\n",
    TWO + "[[hinges]]\nposition = 0.0\n",
    TWO + "[[hinges]]\nposition = 0\n",
    TWO + "[[hinges]]\nposition = 1.5\n",
    TWO + "[[hinges]]\nnode = 1\nbending_stiffness = -1\n",
    TWO + "[[hinges]]\nnode = 1\nstiffness = 1\n",
    TWO + "hinges = [[]]\n",
    # unbalances
    ONE + "[[unbalances]]\nnode = 0\namount = 1\nmass = 2\n",
    ONE + "[[unbalances]]\namount = 1\n",
    ONE + "[[unbalances]]\nnode = 5\namount = 1\n",
    ONE + "[[unbalances]]\nposition = 1.01\namount = 1\n",
    ONE + "[[unbalances]]\nposition = 1\n",
    ONE + "[[unbalances]]\nposition = 1\namount = -1\n",
    ONE + "[[unbalances]]\nposition = 1\namount = 1\nphase = inf\n",
    ONE + "[[unbalances]]\nposition = 1\namount = 1\nphase = 'east'\n",
    ONE + "unbalances = 'many'\n",
    ONE + U * 203,
    # elements and Driveline.__post_init__ beyond the loader's checks
    ONE.replace("1.0", "0.1") + ONE.replace("1.0", "0.2") + ONE.replace("1.0", "0.3") + "[[unbalances]]\nnode = 3\namount = 1\n",
    ONE.replace("1.0", "1e308") * 2 + "[[unbalances]]\nnode = 2\namount = 1\n",
    # messages that show keys and values with escapes
    ONE + "\"we\\u00efrd\\tkey\" = 1\n",
    "left_end = \"it's\"\n" + ONE,
    "left_end = 'say \"hi\"'\n" + ONE,
    "left_end = \"both ' and \\\"\"\n" + ONE,
    "left_end = \"\\u0000\\u001f\\u007f\\u00a0\\u00ad\\u2028\\u00e9\\U0001F600\"\n" + ONE,
    seg("length = [1, 2.5, -0.0, 1e16, 1e-5, true, 'x', {}, [], {a = {b = 1}}]\nouter_diameter = 0.05"),
    seg("length = 1e400\nouter_diameter = 0.05\nmaterial = 'steel'"),
    seg("length = {" + ".".join(["k"] * 55) + " = [[[1]], {}], z = 2}\nouter_diameter = 0.05"),
    "[left_end" + ".t" * 60 + "]\nx = [[1, [2]], {a = 'b'}]\n" + ONE,
    seg("length = 0x7fffffffffffffff\nouter_diameter = 0.05\nmaterial = 'steel'\npoisson_ratio = -9223372036854775808"),
]


#: What the native reader refuses as malformed TOML where Python reads on: datetimes and integers beyond
#: 64 bits (which Python shows as another message, or accepts where a layout ignores the key).
DEPARTURES = [
    ONE + "label = 1979-05-27\n",
    ONE + "label = 1979-05-27T07:32:00Z\n",
    ONE + "label = 07:32:00\n",
    ONE + "label = 99999999999999999999\n",
    ONE + "label = -9223372036854775809\n",
    ONE + "label = 0x10000000000000000\n",
    ONE + "label." + ".".join(["k"] * 70) + " = 1\n",
    ONE + "[segments.label" + ".t" * 70 + "]\n",
]


def test_departures_are_malformed_toml(lib):
    for text in DEPARTURES:
        assert not isinstance(python_result(loads_driveline, text), str)
        assert from_text(lib, text).startswith("<string>: malformed TOML: ")
    assert not isinstance(from_text(lib, ONE + "label = [9223372036854775807, -9223372036854775808]\n"), str)


@pytest.mark.parametrize("index", range(len(INVALID)))
def test_invalid_layouts_give_the_same_message(lib, index, tmp_path):
    text = INVALID[index]
    python = python_result(loads_driveline, text)
    assert isinstance(python, str), "the case must be invalid"
    same(from_text(lib, text), python)
    path = tmp_path / "layout.toml"
    path.write_text(text)
    same(from_layout(lib, str(path)), python_result(load_driveline, path))


def test_the_invalid_corpus_covers_every_message(lib):
    """At least 60 invalid cases, and every message template of the loader, the elements and the
    driveline among their messages."""
    messages = {python_result(loads_driveline, text) for text in INVALID}
    assert len(INVALID) >= 60
    templates = [
        "brackets nest deeper", "malformed TOML", "unknown key", "name must be a string", "is not one of",
        "materials must be a table of named", "must be a table", "missing key 'density'",
        "missing key 'youngs_modulus'", "must be a number, got", "must be finite, got", "must be > 0, got",
        "must be >= 0, got", "must be an array of tables", "tables are more than the",
        "at least one [[segments]]", "missing key 'length'", "give exactly one of 'outer_diameter'",
        "give at most one of", "wall_thickness must be > 0", "exceeds half the outer diameter",
        "must be smaller than the outer size", "is not a defined material (steel)",
        "is not a defined material (none defined)", "(or a 'material')", "must be true or false",
        "must be a number in (-1, 0.5)", "inner_diameter (1.0) must be smaller than outer_diameter",
        "outer_diameter must be a finite number > 0", "give exactly one of 'node' or 'position'",
        "node must be an integer >= 0", "is out of range: nodes are", "lies beyond the right end",
        "missing key 'mass'", "give either 'stiffness' or", "missing key 'stiffness' (or 'kxx')",
        "'cyy' needs 'cxx'", "must be an inner node", "missing key 'amount'",
        "position must be a finite number >= 0", "unbalances[0].position = 0.6000000000000001 m",
    ]
    for template in templates:
        assert any(template in message for message in messages), template


def test_file_checks(lib, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "dir.toml").mkdir()
    os.mkfifo(tmp_path / "fifo.toml")
    os.symlink(os.devnull, tmp_path / "device.toml")  # a character device: refused unread
    (tmp_path / "big.toml").write_text(ONE + "#" * (64 * 1024))
    (tmp_path / "limit.toml").write_text(ONE + "#" * (64 * 1024 - len(ONE) - 1) + "\n")
    bad_bytes = {
        "start.toml": b"\x80",
        "continuation.toml": b"name = '\xc3('\n",
        "surrogate.toml": b"# \xed\xa0\x80\n",
        "overlong.toml": b"# \xe0\x80\x80\n",
        "truncated.toml": ONE.encode() + b"# \xf0\x9f\x98",
        "high.toml": b"# \xf4\x90\x80\x80",
        "ff.toml": b"# \xff",
    }
    for name, raw in bad_bytes.items():
        (tmp_path / name).write_bytes(raw)
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "good.toml").write_text(ONE)
    (tmp_path / "sub" / "bad.toml").write_text(ONE + "[[masses]]\nnode = 7\nmass = 1\n")
    (tmp_path / "sub" / "malformed.toml").write_text(ONE + "x = \n")
    layouts = ["missing.toml", "dir.toml", "fifo.toml", "device.toml", "big.toml", "limit.toml", *bad_bytes, "a" * 295 + ".toml",
               "./sub//good.toml", "sub/./bad.TOML".replace("TOML", "toml"), ".//sub/../sub/malformed.toml",
               str(tmp_path) + "//sub/./good.toml", "sub/nothing/../good.toml", "SUB.TOML",
               "/" + str(tmp_path) + "/sub/bad.toml", "//" + str(tmp_path) + "/sub/bad.toml"]
    messages = []
    for layout in layouts:
        python = python_result(load_layout, layout)
        native = from_layout(lib, layout)
        same(native, python)
        messages.append(python)
    text = " ".join(m for m in messages if isinstance(m, str))
    for expected in ("No such file or directory", "is not a regular file", "is larger than 65536 bytes",
                     "File name too long", "invalid start byte", "invalid continuation byte",
                     "unexpected end of data", str(tmp_path / "sub" / "bad.toml") + ": masses[0].node = 7",
                     str(tmp_path / "sub" / ".." / "sub" / "malformed.toml") + ": malformed TOML",
                     "/" + str(tmp_path / "sub" / "bad.toml") + ": masses[0]"):
        assert expected in text, expected


SWAPPED_LOADS = """
import ctypes, json, sys
from support.native_rotor import CDriveline
lib = ctypes.CDLL(sys.argv[1])
outcomes = set()
for _ in range(int(sys.argv[3])):
    d, error = CDriveline(), ctypes.create_string_buffer(512)
    kind = lib.driveline_from_layout(sys.argv[2].encode(), b"", ctypes.byref(d), error, ctypes.c_size_t(512))
    outcomes.add(error.value.decode().rsplit("' ", 1)[-1] if kind else "loaded")
    if not kind:
        lib.driveline_free(ctypes.byref(d))
print(json.dumps(sorted(outcomes)))
"""


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs are POSIX's")
def test_a_fifo_swapped_in_while_loading_is_refused_without_blocking(lib, tmp_path):
    """The file is opened without blocking and its type asked of the open file, as the Python
    loader does: a FIFO renamed over the layout between a look at the path and its opening would
    block the host's thread forever in the open (20,000 loads with the names swapping hung within
    2,000 when the type was asked of the path first; they take about 0.2 s)."""
    path, fifo, regular, link = (tmp_path / name for name in ("swapped.toml", "fifo", "regular", "link"))
    regular.write_text(ONE)
    os.mkfifo(fifo)
    os.link(regular, path)
    loading = True

    def swap() -> None:
        while loading:
            for source in (fifo, regular):
                link.unlink(missing_ok=True)
                os.link(source, link)
                os.replace(link, path)

    # the script imports the tests' support package: the tests folder goes first on its PYTHONPATH
    tests_on_path = {**os.environ, "PYTHONPATH": os.pathsep.join(
        filter(None, (str(Path(__file__).parents[1]), os.environ.get("PYTHONPATH"))))}
    swapper = threading.Thread(target=swap, daemon=True)
    swapper.start()
    try:
        done = subprocess.run([sys.executable, "-c", SWAPPED_LOADS, lib._name, str(path), "20000"],
                              env=tests_on_path, capture_output=True, text=True, timeout=30)
    finally:
        loading = False
        swapper.join()
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == ["is not a regular file", "loaded"]


def test_shipped_names(lib, tmp_path):
    for name in ("two_piece_propshaft", "two_piece_propshaft_hinged", "../../../etc/passwd", "%s%n", "a" * 64,
                 "a" * 65, "b" * 100, "no_such_layout", "with space", "é", "x\ny", "it's", "two_piece_propshaft.tom"):
        same(from_layout(lib, name), python_result(load_layout, name))
    # a layout folder of the FMU's own: the shipped name looks there only
    (tmp_path / "mine.toml").write_text(ONE)
    assert not isinstance(from_layout(lib, "mine", tmp_path), str)
    assert from_layout(lib, "two_piece_propshaft", tmp_path) == "no shipped example named 'two_piece_propshaft'"
    (tmp_path / "folder.toml").mkdir()
    assert from_layout(lib, "folder", tmp_path) == "no shipped example named 'folder'"


def str_repr(lib, text: str | bytes, cut: int = 0, size: int = 4096) -> str:
    raw = text.encode("utf-8", "surrogatepass") if isinstance(text, str) else text
    out = ctypes.create_string_buffer(size)
    lib.python_str_repr_n(raw, len(raw), cut, out, size)
    return out.value.decode("utf-8")


def test_python_str_repr(lib):
    rng = random.Random(7)
    samples = ["", "plain", "it's", 'say "hi"', "both ' and \"", "back\\slash", "\t\n\r", "\x00\x01\x1f\x7f",
               "\x80\x9f\xa0\xad\xff", "é ñ ü ß", "\u2028\u2029\u200b\ufeff\ue000", "😀 \U0001F600", 
               "日本語", "\ufffe\uffff", "\U000e0001\U000e0100", "\u0600\u061c\u180e"]
    alphabet = "ab'\"\\\t\n\x00\x7f\x85é€😀\u00a0\u3000\u2060\ufdd0"
    samples += ["".join(rng.choice(alphabet) for _ in range(rng.randint(0, 12))) for _ in range(300)]
    for text in samples:
        assert str_repr(lib, text) == repr(text)
        for cut in (1, 2, 5):
            assert str_repr(lib, text, cut) == repr(text[:cut])
    assert str_repr(lib, b"a\x00b") == repr("a\x00b")
    assert str_repr(lib, b"a\xffb") == repr("a\udcffb")
    assert str_repr(lib, "x" * 100, 0, 10) == "'xxxxxxxx"
    # every assigned code point of the Basic Multilingual Plane and a sample beyond
    import unicodedata
    chars = [chr(c) for c in list(range(0x80, 0x10000)) + list(range(0x10000, 0x110000, 97))
             if not 0xD800 <= c < 0xE000 and unicodedata.category(chr(c)) != "Cn"]
    for start in range(0, len(chars), 1000):
        text = "".join(chars[start:start + 1000])
        assert str_repr(lib, text, 0, 20000) == repr(text)


def float_repr(lib, value: float) -> str:
    out = ctypes.create_string_buffer(64)
    lib.python_float_repr(value, out, 64)
    return out.value.decode()


def test_python_float_repr(lib):
    rng = random.Random(11)
    values = [0.0, -0.0, math.inf, -math.inf, math.nan, 5e-324, 1.7976931348623157e308, 2.2250738585072014e-308,
              0.1, 0.3, 1 / 3, 1e16, 1e15, 9999999999999998.0, 1e-4, 1e-5, 0.0001234, 123.0, 1e22, 1e23, 2.0 ** 63,
              9007199254740993.0, 5e-5, 0.5, 100.0, 1234567890123456789.0]
    values += [2.0 ** e for e in range(-1074, 1024)]
    values += [struct.unpack("<d", struct.pack("<Q", rng.getrandbits(64)))[0] for _ in range(20000)]
    values += [rng.uniform(-1e3, 1e3) for _ in range(5000)] + [float(f"{rng.random():.{rng.randint(1, 17)}g}")
                                                               for _ in range(5000)]
    for value in values:
        assert float_repr(lib, value) == repr(value)


def test_one_piece_shaft(lib):
    good = dict(L_shaft=1.5, D_outer=0.08, D_inner=0.075, E=2.1e11, density=7850.0, m_joint=2.5, Jp_joint=4e-3,
                Jd_joint=2e-3, k_bearing=1e7, c_bearing=300.0)
    cases = [good, {**good, "D_inner": 0.0, "c_bearing": 0.0}, {**good, "D_inner": -0.0, "m_joint": 0.0}]
    for key in good:
        cases += [{**good, key: math.nan}, {**good, key: math.inf}, {**good, key: -1.0}, {**good, key: 0.0}]
    cases += [{**good, "D_inner": 0.08}, {**good, "D_inner": 0.1}, {**good, "E": -0.0}]
    for params in cases:
        for shear in (True, False):
            native = native_result(lib, lib.driveline_one_piece, ctypes.byref(OnePieceShaft(**params, shear=shear)))
            same(native, python_result(lambda: one_piece_shaft(**params, shear=shear)))


#: TOML documents whose ``left_end`` the loader shows as its repr: the reader's values and tables.
TOML_CASES = [
    "left_end = {}", "left_end = []", "left_end = [[], [[]], {}]", "left_end = [1, 2, ]", "left_end = [\n1, # one\n2\n]",
    "left_end = [1, [2, [3, {a = [4]}]]]", "left_end = {a.b.c = 1, a.b.d = 2, a.e = 3}", "left_end = {a = 1, a.b = 2}",
    "left_end = {a = {b = 1}, a.c = 2}", "left_end = {'quoted key' = 1, \"esc\\tkey\" = 2, '' = 3}",
    "left_end.a = 1\nleft_end.b.c = 2\nleft_end.b.d = 3", "[left_end]\na = 1\n[left_end.b]\nc = 2",
    "[left_end.b]\nc = 2\n[left_end]\na = 1", "[left_end]\n[left_end]", "[left_end]\na.b = 1\n[left_end.a]",
    "[left_end]\na.b = 1\n[left_end.a.c]", "[left_end.a.b]\n[left_end]\na.c = 1", "[left_end.a.b]\n[left_end]\na.b.c = 1",
    "[[left_end.x]]\na = 1\n[[left_end.x]]\nb = 2\n[left_end.x.sub]\nc = 3",
    "[[left_end.x]]\n[left_end.x]", "[left_end.x]\n[[left_end.x]]", "left_end.x = [1]\n[[left_end.x]]",
    "left_end.x = {a = 1}\n[left_end.x.b]", "left_end.x = {a = 1}\n[left_end.x]", "left_end = 1\n[left_end.x]",
    "[[left_end.x]]\ny.z = 1\n[[left_end.x]]\ny.z = 2", "[[left_end.x]]\n[[left_end.x.y]]\na = 1\n[[left_end.x.y]]",
    "[left_end]\nx.y = 1\nx.z = 2\n[left_end.w]\n", "[ left_end . 'a b' . \"c\" ]\nk = 1",
    "[[ left_end.x ]]\nk = 1", "[left_end\n]", "[[left_end.x]\n", "[left_end.x]]", "[left_end] x = 1",
    "left_end = 1 # comment\n# another", "left_end = 1 \\", "left_end =", "left_end = \n1",
    "left_end = 'literal \\n'", "left_end = \"\\u00e9\\U0001F600\\\\\\\"\"", "left_end = \"\\x41\"",
    "left_end = \"\\u12\"", "left_end = \"\\U00110000\"", "left_end = \"\\uDFFF\"", "left_end = 'tab\there'",
    "left_end = \"\"\"\none\ntwo\"\"\"", "left_end = \"\"\"a\\\n\n   b\"\"\"", "left_end = \"\"\"a\\   \n  b\"\"\"",
    "left_end = \"\"\"a\\ b\"\"\"", "left_end = \"\"\"\"\"\"", "left_end = \"\"\"\"a\"\"\"\"", "left_end = '''''''",
    "left_end = ''''a''''", "left_end = '''\n'''", "left_end = '''a''''''", "left_end = \"\"\"a\"\"\"\"\"\"",
    "left_end = \"a\"\"", "left_end = \"\"\"\\\"\"\"\"", "left_end = \"\"\"tab\tand\u00e9\"\"\"",
    "left_end = 0", "left_end = -0", "left_end = +17", "left_end = 1_000", "left_end = 0xDEAD_beef", "left_end = 0o17",
    "left_end = 0b1010", "left_end = 0x", "left_end = 0X10", "left_end = 0b2", "left_end = -0x1", "left_end = 00",
    "left_end = 9223372036854775807", "left_end = -9223372036854775808", "left_end = 1.5", "left_end = -0.0",
    "left_end = +0.0", "left_end = 1e3", "left_end = 1E-3", "left_end = 1e+03", "left_end = 6.626e-34",
    "left_end = 1_0.0_1e1_0", "left_end = 1.e3", "left_end = 1.0e", "left_end = 1e3.5", "left_end = 0.1_",
    "left_end = inf", "left_end = +inf", "left_end = -inf", "left_end = nan", "left_end = -nan", "left_end = +nan",
    "left_end = Inf", "left_end = infinity", "left_end = true", "left_end = false", "left_end = True",
    "left_end = [true,false]", "left_end = {a=true}", "left_end = 1.7976931348623157e308", "left_end = 1e309",
    "left_end = 4.9e-324", "left_end = 2.4e-324", "left_end = 0.30000000000000004", "left_end = 123456789012345678",
    "left_end = 1 = 2", "left_end = [1 2]", "left_end = [,]", "left_end = {,}", "left_end = {a = 1 b = 2}",
    "left_end = {a = 1}}", "left_end = [1]]", "left_end.\"a\".'b' = 1", "left_end . a = 1", "left_end.a. = 1",
    "left_end..a = 1", "left-end = 1", "left_end = 1\r\n", "left_end = 1\r", "left_end = \"a\rb\"",
    "left_end = [\r\n1]", "\ufeffleft_end = 1", "left_end = 'ü' # ü", "left_end = 1\nleft_end = 2",
    "left_end = \"\x00\"", "left_end = [1] # \x00", "left_end.a = 1\nleft_end.a.b = 2",
]


def toml_message(lib, text: str) -> tuple[str, str]:
    return from_text(lib, text), python_result(loads_driveline, text)


@pytest.mark.parametrize("index", range(len(TOML_CASES)))
def test_toml_values_read_as_tomllib_reads_them(lib, index):
    native, python = toml_message(lib, TOML_CASES[index])
    same(native, python)


def random_value(rng: random.Random, depth: int = 0) -> str:
    kind = rng.randrange(10 if depth < 3 else 7)
    if kind == 0:
        return rng.choice(["0", "-0", "+5", "1_000", "0x1F", "0o7", "0b101", "42", "-17", "9_223_372"])
    if kind == 1:
        return rng.choice(["1.5", "-0.0", "1e10", "6.02e+23", "1E-7", "3_1.4_1", "inf", "-nan", "1e-320", "0.1"])
    if kind == 2:
        return rng.choice(["true", "false"])
    if kind == 3:
        body = "".join(rng.choice(["a", " ", "'", "\\\"", "\\\\", "\\t", "\\n", "\\u00e9", "é", "\\U0001F600", "\\b"])
                       for _ in range(rng.randrange(6)))
        return f'"{body}"'
    if kind == 4:
        return "'" + "".join(rng.choice(["a", " ", '"', "\\", "é", "\t"]) for _ in range(rng.randrange(6))) + "'"
    if kind == 5:
        return '"""' + "".join(rng.choice(["a", "\n", '"', '""', "\\\n  ", "\\t"]) for _ in range(rng.randrange(5))) + '"""'
    if kind == 6:
        return "'''" + "".join(rng.choice(["a", "\n", "'", "''", "\\"]) for _ in range(rng.randrange(5))) + "'''"
    if kind in (7, 8):
        items = [random_value(rng, depth + 1) for _ in range(rng.randrange(4))]
        sep = rng.choice([", ", ",\n", " , ", ",  # note\n"])
        return "[" + sep.join(items) + rng.choice(["", ",", "\n"]) + "]"
    keys = rng.sample(["a", "b", "c.d", "c.e", "'q k'", '"x"', "f.g.h"], rng.randrange(4))
    return "{" + ", ".join(f"{k} = {random_value(rng, depth + 1)}" for k in keys) + "}"


def mutate(rng: random.Random, text: str) -> str:
    at = rng.randrange(len(text) + 1)
    choice = rng.randrange(3)
    if choice == 0 and at < len(text):
        return text[:at] + text[at + 1:]
    insert = rng.choice(["'", '"', "[", "]", "{", "}", ",", "=", ".", "\n", " ", "#", "\\", "_", "e", "0", "x"])
    return text[:at] + insert + text[at + (choice == 1):]


def test_random_toml_reads_as_tomllib_reads_it(lib):
    rng = random.Random(3)
    read = 0
    for _ in range(3000):
        lines = []
        for _ in range(rng.randint(1, 4)):
            if rng.random() < 0.3:
                lines.append(rng.choice(["[left_end]", "[left_end.t]", "[[left_end.l]]", "[left_end.t.u]"]))
            key = rng.choice(["v", "w.x", "w.y", "'z'", "t.k", "l"])
            lines.append(f"{key} = {random_value(rng)}")
        text = "\n".join(lines)
        if rng.random() < 0.5 and not text.startswith("["):
            text = "left_end." + text
        elif not text.startswith("["):
            text = "[left_end]\n" + text
        if rng.random() < 0.5:
            text = mutate(rng, text)
        native, python = toml_message(lib, text)
        same(native, python)
        read += "malformed" not in python
    assert read > 1000
