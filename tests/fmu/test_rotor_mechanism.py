"""A shaft that is a mechanism (driveline.rotor.mechanism) and the FMU parameter ``shear`` with a
layout: both refused by the core and by both FMU families with the same words.

Independent check of the mechanism test: the finite-element model's stiffness (fem.py) is
singular exactly for the layouts refused, so its lowest natural frequency is zero there."""

from __future__ import annotations

import numpy as np
import pytest

from driveline.rotor import example_path, load_driveline
from driveline.rotor.loader import loads_driveline
from driveline.rotor.mechanism import MECHANISM_HINGE, MECHANISM_RIGID, mechanism_error
from driveline.rotor.model import SHEAR_CONFLICT, natural_frequencies
from fmu_harness.packaging import native
from fmu_harness.runs.runner import StepRefused, simulate

TUBE = """
[[segments]]
length = {first}
outer_diameter = 0.05
wall_thickness = 0.002
youngs_modulus = 2.1e11
density = 7850.0
{shear}
[[segments]]
length = {second}
outer_diameter = 0.05
wall_thickness = 0.002
youngs_modulus = 2.1e11
density = 7850.0
{shear}
"""


def layout(ends: str = "free", hinge: str = "node = 1", bearings: tuple[float, ...] = (), shear: str = "",
           first: float = 0.4, second: float = 0.6) -> str:
    """A 1 m tube of two segments (node 1 at 0.4 m) with ``ends`` at both ends, a hinge and bearings."""
    text = f'left_end = "{ends}"\nright_end = "{ends}"\n' + TUBE.format(first=first, second=second, shear=shear)
    if hinge:
        text += f"[[hinges]]\n{hinge}\n"
    for position in bearings:
        text += f"[[bearings]]\nposition = {position}\nkxx = 1e7\n"
    return text


PINNED = layout("pinned")  # the first layout: the hinge at 0.4 L between pinned ends
BEARINGS_OUTSIDE = layout(bearings=(0.05, 0.95))  # free ends, a bearing near each end, the hinge between
MECHANISMS = {
    "pinned-pinned, hinge at 0.4 L": (PINNED, MECHANISM_HINGE.format(index=0, node=1)),
    "free ends, bearings near them": (BEARINGS_OUTSIDE, MECHANISM_HINGE.format(index=0, node=2)),
    "one bearing, no hinge": (layout(hinge="", bearings=(0.5,)), MECHANISM_RIGID),
    "a third bearing on the hinge": (layout(bearings=(0.05, 0.4)), MECHANISM_HINGE.format(index=0, node=2)),
}
HELD = {
    "a third bearing beside the hinge": layout(bearings=(0.05, 0.6, 0.95)),
    "clamped ends": layout("clamped"),
    "a hinge with bending stiffness": layout("pinned", hinge="node = 1\nbending_stiffness = 5e3"),
    "bearings at the ends and beside the hinge": layout(bearings=(0.0, 0.3, 1.0)),
}


@pytest.mark.parametrize("name", MECHANISMS)
def test_a_mechanism_is_named_by_its_hinge_and_has_a_zero_frequency(name):
    text, message = MECHANISMS[name]
    driveline = loads_driveline(text)
    assert mechanism_error(driveline) == message
    natural = np.sort(natural_frequencies(driveline))
    assert natural[0] < 1e-5 * natural[1]  # measured 0.7e-3 to 1.9e-3 rad/s (round-off) against 1.1e3-3.0e3 rad/s


@pytest.mark.parametrize("name", HELD)
def test_a_held_shaft_is_accepted_and_has_no_zero_frequency(name):
    driveline = loads_driveline(HELD[name])
    assert mechanism_error(driveline) is None
    assert np.sort(natural_frequencies(driveline))[0] > 100.0  # measured 310-1770 rad/s


def test_the_shipped_layouts_are_held():
    for name in ("two_piece_propshaft", "two_piece_propshaft_hinged"):
        assert mechanism_error(load_driveline(example_path(name))) is None


def _families(fmu_path, native_dir, fmi: str):
    return {"python": fmu_path("CriticalSpeeds", fmi), "native": native.fmu_path(native_dir, "CriticalSpeeds", fmi)}


def _refusal(path, start_values: dict) -> list[str]:
    with pytest.raises(StepRefused) as refused:
        simulate(path, 0.02, 0.01, start_values=start_values)
    return refused.value.messages


@pytest.mark.parametrize("name", ["pinned-pinned, hinge at 0.4 L", "free ends, bearings near them"])
def test_both_fmus_refuse_a_mechanism_naming_the_hinge(fmu_path, native_dir, fmi, tmp_path, name):
    """Before: omega_crit_1 = 1729.5 (1476.4) rad/s, count 3, no warning (the issue's report)."""
    text, message = MECHANISMS[name]
    (tmp_path / "mechanism.toml").write_text(text)
    for family, path in _families(fmu_path, native_dir, fmi).items():
        messages = _refusal(path, {"layout": str(tmp_path / "mechanism.toml")})
        assert any(f"driveline: {message}" in m for m in messages), (family, messages)


def test_shear_false_with_a_layout_that_keeps_shear_is_refused(fmu_path, native_dir, fmi, tmp_path):
    """The rule: a layout's segments decide shear themselves (default true); the parameter applies
    to the one-piece tube. A layout with shear = false in every segment agrees with the parameter
    false; the parameter's start value true accepts any layout."""
    (tmp_path / "sheared.toml").write_text(layout(bearings=(0.05, 0.6, 0.95)))
    (tmp_path / "rayleigh.toml").write_text(layout(bearings=(0.05, 0.6, 0.95), shear="shear = false"))
    for family, path in _families(fmu_path, native_dir, fmi).items():
        messages = _refusal(path, {"layout": str(tmp_path / "sheared.toml"), "shear": False})
        assert any(f"driveline: {SHEAR_CONFLICT}" in m for m in messages), (family, messages)
        rayleigh = simulate(path, 0.02, 0.01, start_values={"layout": str(tmp_path / "rayleigh.toml"), "shear": False})
        sheared = simulate(path, 0.02, 0.01, start_values={"layout": str(tmp_path / "sheared.toml")})
        assert rayleigh["omega_crit_1"][-1] > sheared["omega_crit_1"][-1]  # shear deformation softens the tube
