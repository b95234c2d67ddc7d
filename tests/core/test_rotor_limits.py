"""Bounds on the work and memory a CriticalSpeeds input can demand, and the plausibility check of
every analysis: each refused quickly with a message naming what was exceeded."""

from __future__ import annotations

import pytest

from driveline.rotor import load_driveline, loads_driveline
from driveline.rotor.loader import MAX_FILE_BYTES, MAX_NESTING, MAX_SEGMENTS
from driveline.rotor.model import MAX_ORDER, MAX_ORDERS, CriticalSpeedsModel, parse_orders
from fmu_harness.checks.robustness_probe import SEGMENT_TABLE, hostile_file


def _refusal(**parameters) -> list[str]:
    model = CriticalSpeedsModel()
    for name, value in parameters.items():
        setattr(model, name, value)
    return model.initialize(0.0)


@pytest.mark.parametrize("orders, fragment", [
    ("99999999999999999999", "is not an integer from 1 to 100"),
    (str(MAX_ORDER + 1), "is not an integer from 1 to 100"),
    (",".join(["1"] * (MAX_ORDERS + 1)), f"more than {MAX_ORDERS} orders"),
    (",".join(["1"] * 100000), f"more than {MAX_ORDERS} orders"),
    ("1,²", "'²' is not an integer"),
    ("0", "'0' is not an integer"),
])
def test_orders_beyond_the_limits_are_refused(orders, fragment):
    with pytest.raises(ValueError, match=fragment):
        parse_orders(orders)


def test_the_limits_still_accept_sixteen_orders_up_to_the_largest():
    assert parse_orders(",".join(["100"] + ["1"] * (MAX_ORDERS - 1)))[0] == 100


@pytest.mark.parametrize("parameters", [
    {"L_shaft": 100.0}, {"L_shaft": 1e6}, {"density": 1e308}, {"E": 1e-300},
    {"omega_in_max": 1e300}, {"orders": "100,99,98,97,96,95,94,93"},
])
def test_analyses_beyond_the_work_limit_are_refused_before_they_start(parameters):
    assert any("shaft modes, more than the 250 accepted" in reason for reason in _refusal(**parameters))


@pytest.mark.parametrize("E", [1e180, 1e250, 1e300])
def test_an_analysis_double_precision_cannot_resolve_is_refused(E):
    """E >= 1e180 once gave critical speeds of 0.06 rad/s with status OK; the finite-element check
    (nearest natural frequency ~1e80 rad/s) refuses it."""
    reasons = _refusal(E=E)
    assert reasons and ("finite-element check" in reasons[0] or "critical speeds below the search limit" in reasons[0])


def test_the_default_and_a_ten_metre_tube_pass_the_checks():
    assert _refusal() == [] and _refusal(L_shaft=10.0, D_inner=0.0) == []


def test_segment_count_is_bounded():
    with pytest.raises(ValueError, match=f"more than the {MAX_SEGMENTS} accepted"):
        loads_driveline(SEGMENT_TABLE * (MAX_SEGMENTS + 1))


def test_deep_nesting_is_refused_before_parsing():
    for text in ("x = " + "[" * 100000 + "]" * 100000, "x = " + "{a = " * (MAX_NESTING + 1) + "1" + "}" * (MAX_NESTING + 1)):
        with pytest.raises(ValueError, match=f"nest deeper than {MAX_NESTING}"):
            loads_driveline(text)


@pytest.mark.parametrize("kind, fragment", [
    ("fifo", "not a regular file"), ("dev zero", "not a regular file"), ("directory", "not a regular file"),
    ("large file", f"larger than {MAX_FILE_BYTES} bytes"), ("many segments", f"more than the {MAX_SEGMENTS} accepted"),
    ("deep nesting", f"nest deeper than {MAX_NESTING}"),
])
def test_only_small_regular_files_are_read(tmp_path, kind, fragment):
    path = tmp_path / "layout.toml"
    hostile_file(path, kind)
    with pytest.raises(ValueError, match=fragment):
        load_driveline(path)


def test_a_file_that_is_not_utf8_is_refused(tmp_path):
    path = tmp_path / "layout.toml"
    path.write_bytes(b"\xff\xfe" + SEGMENT_TABLE.encode())
    with pytest.raises(ValueError, match="not UTF-8"):
        load_driveline(path)


@pytest.mark.parametrize("layout", ["../model", "two_piece_propshaft/../x", "a" * 65, "nul\0"])
def test_shipped_layout_names_cannot_leave_the_data_folder(layout):
    assert any("no shipped example named" in reason for reason in _refusal(layout=layout))
