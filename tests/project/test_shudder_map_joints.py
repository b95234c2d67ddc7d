"""The shudder map's joint type as a swept dimension (fmu_harness.shudder_map): its axis, its option's
one-line refusals and the figure's panels, a row per joint, from a table written without running a launch."""

from __future__ import annotations

import argparse

import pyarrow
import pytest

from fmu_harness import shudder_map


def test_the_joints_are_an_axis_of_their_own_unless_the_plain_tripod_alone():
    plain = shudder_map.axes(2)
    assert shudder_map.JOINT not in plain and len(plain) == 3
    swept = shudder_map.axes(2, [0, 1, 2])
    assert list(swept) == [shudder_map.JOINT, *plain] and swept[shudder_map.JOINT] == [0, 1, 2]


@pytest.mark.parametrize("text", ["", "3", "0,0", "a,1", "1.5"])
def test_the_joints_option_refuses_what_is_no_tripod_type(text):
    with pytest.raises(argparse.ArgumentTypeError, match="distinct tripod types among 0, 1, 2"):
        shudder_map.joint_types(text)
    assert shudder_map.joint_types("2,0") == [2, 0]


def test_the_figure_has_a_row_of_panels_per_joint(tmp_path):
    """Three joints and two friction coefficients (one launch failed): six panels, titled by joint and mu."""
    axes = shudder_map.axes(2, [0, 1, 2])
    rows = [point | {"status": "ok", "reason": "", shudder_map.PEAK: 1.0 + point[shudder_map.MU]}
            for point in shudder_map.sweep.grid(axes)]
    rows[-1] |= {"status": "failed", shudder_map.PEAK: None}
    table = pyarrow.Table.from_pylist(rows)
    titles = [ax.get_title() for ax in shudder_map.map_figure(table).axes if ax.get_title()]
    assert titles == [f"{joint}, mu = {mu}" for joint in ("plain tripod", "single roller", "double roller")
                      for mu in ("0.02", "0.1")]
    assert shudder_map.draw(table, tmp_path / "map.png").stat().st_size > 10_000
