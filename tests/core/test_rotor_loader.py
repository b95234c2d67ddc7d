"""TOML loader, one-piece constructor and their error messages."""

from __future__ import annotations

import numpy as np
import pytest

from driveline.rotor import (
    Bearing,
    Driveline,
    EndCondition,
    Hinge,
    example_path,
    load_driveline,
    loads_driveline,
    one_piece_shaft,
    Unbalance,
)

GOOD = """
name = "test"
left_end = "free"
right_end = "pinned"

[materials.steel]
youngs_modulus = 2.1e11
density = 7850.0

[[segments]]
length = 0.7
outer_diameter = 0.0762
wall_thickness = 0.00165
material = "steel"

[[segments]]
length = 0.5
outer_radius = 0.02
inner_radius = 0.01
youngs_modulus = 2.0e11
density = 7800.0
gyroscopic = false

[[masses]]
node = 0
mass = 2.5
polar_inertia = 0.004
diametral_inertia = 0.002

[[bearings]]
node = 0
stiffness = 1.0e7

[[bearings]]
node = 1
kxx = 2.0e6
kyy = 1.0e6
"""


def test_good_file_round_trip():
    d = loads_driveline(GOOD)
    assert d.name == "test" and d.left is EndCondition.FREE and d.right is EndCondition.PINNED
    s0, s1 = d.segments
    assert s0.inner_diameter == pytest.approx(0.0762 - 2 * 0.00165, rel=1e-15)  # one subtraction
    assert (s1.outer_diameter, s1.inner_diameter, s1.youngs_modulus, s1.gyroscopic) == (0.04, 0.02, 2.0e11, False)
    assert d.masses[0].polar_inertia == 0.004
    assert d.bearings[1].kxx == 2e6 and d.bearings[1].k_yy == 1e6 and not d.is_isotropic


def test_shipped_example_loads_and_solves():
    d = load_driveline(example_path("two_piece_propshaft"))
    assert len(d.segments) == 3 and len(d.bearings) == 3
    cs = d.critical_speeds(3)
    assert cs.size == 3 and np.all(np.diff(cs) > 0)


def test_one_piece_constructor_matches_explicit_toml():
    d1 = one_piece_shaft(1.4, 0.0762, 0.0729, 2.1e11, 7850.0, 2.5, 0.004, 0.002, 1e7)
    text = """
[[segments]]
length = 1.4
outer_diameter = 0.0762
inner_diameter = 0.0729
youngs_modulus = 2.1e11
density = 7850.0
[[masses]]
node = 0
mass = 2.5
polar_inertia = 0.004
diametral_inertia = 0.002
[[masses]]
node = 1
mass = 2.5
polar_inertia = 0.004
diametral_inertia = 0.002
[[bearings]]
node = 0
stiffness = 1e7
[[bearings]]
node = 1
stiffness = 1e7
"""
    d2 = loads_driveline(text)
    assert np.array_equal(d1.critical_speeds(3), d2.critical_speeds(3))


def _replace(old: str, new: str) -> str:
    assert old in GOOD
    return GOOD.replace(old, new, 1)


@pytest.mark.parametrize(
    "text,fragment",
    [
        (_replace("length = 0.7", "length = -0.7"), "segments[0].length"),
        (_replace("length = 0.7", "length = 0.0"), "segments[0].length"),
        (_replace("length = 0.7", 'length = "0.7"'), "segments[0].length"),
        (_replace("length = 0.7", "length = true"), "segments[0].length"),
        (_replace("length = 0.7", "length = nan"), "segments[0].length"),
        (_replace("inner_radius = 0.01", "inner_radius = 0.02"), "segments[1].inner_radius"),
        (_replace("inner_radius = 0.01", "inner_radius = 0.03"), "segments[1].inner_radius"),
        (_replace("wall_thickness = 0.00165", "wall_thickness = 0.05"), "segments[0].wall_thickness"),
        (_replace("wall_thickness = 0.00165", "wall_thickness = 0.0"), "segments[0].wall_thickness"),
        (_replace("density = 7850.0", "density = 0.0"), "materials.steel.density"),
        (_replace("density = 7800.0", "density = 0"), "segments[1].density"),
        (_replace("youngs_modulus = 2.0e11", "youngs_modulus = -2.0e11"), "segments[1].youngs_modulus"),
        (_replace('material = "steel"', 'material = "alu"'), "segments[0].material"),
        (_replace("length = 0.7", "lenght = 0.7"), "unknown key 'lenght'"),
        (_replace("outer_radius = 0.02", "outer_radius = 0.02\nouter_diameter = 0.04"), "segments[1]"),
        (_replace("mass = 2.5", "mass = -2.5"), "masses[0].mass"),
        (_replace("polar_inertia = 0.004", "polar_inertia = -1"), "masses[0].polar_inertia"),
        (_replace("diametral_inertia = 0.002", "diametral_inertia = -1"), "masses[0].diametral_inertia"),
        (_replace("node = 0\nmass", "node = 7\nmass"), "masses[0].node"),
        (_replace("node = 0\nmass", "node = -1\nmass"), "masses[0].node"),
        (_replace("node = 0\nmass", "node = 1.5\nmass"), "masses[0].node"),
        (_replace("stiffness = 1.0e7", "stiffness = -1.0e7"), "bearings[0].stiffness"),
        (_replace("stiffness = 1.0e7", "stiffness = 1.0e7\nkxx = 1.0"), "bearings[0]"),
        (_replace("kyy = 1.0e6", "kyy = 0.0"), "bearings[1].kyy"),
        (_replace("kyy = 1.0e6", "kzz = 1.0e6"), "unknown key 'kzz'"),
        (_replace('right_end = "pinned"', 'right_end = "welded"'), "right_end"),
        (_replace('name = "test"', "name = 3"), "name"),
        (_replace('name = "test"', 'name = "test"\ncolour = "red"'), "unknown key 'colour'"),
        (GOOD + "\n[[segments]\n", "malformed TOML"),
        ("left_end = 'free'\n", "segments"),
        (_replace("[materials.steel]", "[materials.steel]\ncolour = 1"), "materials.steel"),
    ],
)
def test_bad_values_raise_value_error_naming_them(text, fragment):
    with pytest.raises(ValueError) as exc:
        loads_driveline(text)
    assert fragment in str(exc.value)


def test_unreadable_file(tmp_path):
    with pytest.raises(ValueError, match="cannot read"):
        load_driveline(tmp_path / "missing.toml")


def test_file_errors_name_the_file(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[[segments]\n", encoding="utf-8")
    with pytest.raises(ValueError, match="bad.toml: malformed TOML"):
        load_driveline(p)


def test_unknown_example():
    with pytest.raises(ValueError, match="no shipped example"):
        example_path("does_not_exist")


ARGS = {"L_shaft": 1.4, "D_outer": 0.0762, "D_inner": 0.0729, "E": 2.1e11, "density": 7850.0,
        "m_joint": 2.5, "Jp_joint": 0.004, "Jd_joint": 0.002, "k_bearing": 1e7}


@pytest.mark.parametrize(
    "name,value",
    [("L_shaft", -1.0), ("L_shaft", 0.0), ("D_outer", 0.0), ("D_inner", -0.01), ("D_inner", 0.0762),
     ("D_inner", 0.09), ("E", 0.0), ("density", 0.0), ("density", float("nan")), ("m_joint", -1.0),
     ("Jp_joint", -1e-3), ("Jd_joint", -1e-3), ("k_bearing", 0.0), ("k_bearing", float("inf"))],
)
def test_one_piece_errors_name_the_parameter(name, value):
    with pytest.raises(ValueError, match=name):
        one_piece_shaft(**{**ARGS, name: value})


def test_driveline_validation():
    d = one_piece_shaft(**ARGS)
    with pytest.raises(ValueError, match="out of range"):
        Driveline(d.segments, d.masses, [*d.bearings, type(d.bearings[0])(5, 1e6)])
    with pytest.raises(ValueError, match="left end condition"):
        Driveline(d.segments, left="glued")
    with pytest.raises(ValueError, match="at least one"):
        Driveline([])


SHAFT = """
[[segments]]
length = 0.6
outer_diameter = 0.0762
inner_diameter = 0.0729
youngs_modulus = 2.1e11
density = 7850.0

[[segments]]
length = 0.8
outer_diameter = 0.0762
inner_diameter = 0.0729
youngs_modulus = 2.1e11
density = 7850.0

[[bearings]]
node = 0
stiffness = 1.0e7

[[bearings]]
position = 1.4
stiffness = 1.0e7
"""


def test_elements_placed_by_position_cut_the_segments():
    # A mass at 0.35 m and a centre bearing at 1.0 m: the loader cuts both segments; the
    # same layout written with nodes gives the same numbers (cut lengths are differences of
    # positions, exact to round-off: 1e-12).
    by_position = loads_driveline(SHAFT + "[[masses]]\nposition = 0.35\nmass = 3.0\n"
                                  "[[bearings]]\nposition = 1.0\nstiffness = 5e5\n")
    assert [s.length for s in by_position.segments] == pytest.approx([0.35, 0.25, 0.4, 0.4], rel=1e-15)
    assert (by_position.masses[0].node, by_position.bearings[1].node, by_position.bearings[2].node) == (1, 4, 3)
    by_node = loads_driveline(
        SHAFT.replace("length = 0.6", "length = 0.35", 1).replace("length = 0.8", "length = 0.25", 1)
        .replace("position = 1.4", "node = 4")
        + "[[segments]]\nlength = 0.4\nouter_diameter = 0.0762\ninner_diameter = 0.0729\n"
          "youngs_modulus = 2.1e11\ndensity = 7850.0\n" * 2
        + "[[masses]]\nnode = 1\nmass = 3.0\n[[bearings]]\nnode = 3\nstiffness = 5e5\n")
    np.testing.assert_allclose(by_position.critical_speeds(3), by_node.critical_speeds(3), rtol=1e-12)


def test_cutting_a_bare_segment_changes_nothing():
    # H(l1 + l2) = H(l2) H(l1): a node without elements leaves the roots alone (1e-12).
    whole = loads_driveline(SHAFT)
    cut = loads_driveline(SHAFT + "[[masses]]\nposition = 0.9\nmass = 0.0\n")
    assert len(cut.segments) == 3
    np.testing.assert_allclose(cut.critical_speeds(3), whole.critical_speeds(3), rtol=1e-12)


@pytest.mark.parametrize("table, fragment", [
    ("[[masses]]\nposition = 1.5\nmass = 1.0\n", "masses[0].position = 1.5 m lies beyond the right end"),
    ("[[masses]]\nposition = -0.1\nmass = 1.0\n", "masses[0].position must be >= 0"),
    ("[[masses]]\nnode = 1\nposition = 0.6\nmass = 1.0\n", "masses[0]: give exactly one of 'node' or 'position'"),
    ("[[hinges]]\nposition = 0.0\n", "hinges[0].position = 0.0 m must be an inner node"),
    ("[[hinges]]\nnode = 0\n", "hinges[0].node = 0 must be an inner node"),
    ("[[hinges]]\nnode = 2\n", "hinges[0].node = 2 must be an inner node"),
    ("[[hinges]]\nnode = 1\nbending_stiffness = -1.0\n", "hinges[0].bending_stiffness"),
    ("[[hinges]]\nnode = 1\nstiff = 1.0\n", "unknown key 'stiff'"),
    ("[[hinges]]\nbending_stiffness = 1.0\n", "hinges[0]: give exactly one of 'node' or 'position'"),
    ("[[bearings]]\nnode = 0\nstiffness = 1e7\ndamping = -1.0\n", "bearings[2].damping must be >= 0"),
    ("[[bearings]]\nnode = 0\nstiffness = 1e7\ndamping = 1.0\ncyy = 2.0\n",
     "bearings[2]: give either 'damping' or 'cxx'/'cyy', not both"),
    ("[[bearings]]\nnode = 0\nstiffness = 1e7\ncyy = 2.0\n", "bearings[2]: 'cyy' needs 'cxx'"),
    ("[[bearings]]\nnode = 0\nstiffness = 1e7\ncxx = 'x'\n", "bearings[2].cxx must be a number"),
    ("[[bearings]]\nnode = 0\nstiffness = 1e7\nkxy = inf\n", "bearings[2].kxy must be finite"),
    ("[[unbalances]]\nposition = 1.5\namount = 1e-4\n", "unbalances[0].position = 1.5 m lies beyond the right end"),
    ("[[unbalances]]\nnode = 3\namount = 1e-4\n", "unbalances[0].node = 3 is out of range"),
    ("[[unbalances]]\nnode = 1\n", "unbalances[0]: missing key 'amount'"),
    ("[[unbalances]]\nnode = 1\namount = -1e-4\n", "unbalances[0].amount must be >= 0"),
    ("[[unbalances]]\nnode = 1\namount = 1e-4\nphase = 'up'\n", "unbalances[0].phase must be a number"),
    ("[[unbalances]]\nnode = 1\nmass = 1e-4\n", "unbalances[0]: unknown key 'mass'"),
])
def test_bad_point_tables_are_refused(table, fragment):
    with pytest.raises(ValueError) as refused:
        loads_driveline(SHAFT + table)
    assert fragment in str(refused.value)


def test_damping_and_unbalance_tables_load():
    d = loads_driveline(SHAFT + """
[[bearings]]
node = 0
stiffness = 1e7
damping = 300.0

[[bearings]]
position = 0.4
kxx = 1e7
kyy = 2e6
cxx = 100.0
cyy = 50.0
kxy = -1e5
cyx = 20.0

[[unbalances]]
node = 1
amount = 2e-4
phase = -0.5

[[unbalances]]
position = 0.3
amount = 1e-4
""")
    assert d.bearings[2:] == (Bearing(0, 1e7, None, 300.0), Bearing(1, 1e7, 2e6, 100.0, 50.0, kxy=-1e5, cyx=20.0))
    assert d.unbalances == (Unbalance(0.6, 2e-4, -0.5), Unbalance(0.3, 1e-4))  # node 1 of the file: 0.6 m


def test_hinge_table_loads():
    d = loads_driveline(SHAFT + "[[hinges]]\nnode = 1\nbending_stiffness = 50.0\n")
    assert d.joints == (Hinge(1, 50.0),)
