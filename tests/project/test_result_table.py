"""The main job's CSV files hold what an engineer can read without a guess: a number under
``name [unit]``, a text under ``name``, no empty or not-finite cell, no row twice."""

from __future__ import annotations

import math

import pytest

from fmu_harness.runs.result_table import write_csv


@pytest.mark.parametrize("header, row, words", [
    (("mode [1]", "peak [rad/s]"), (1, math.nan), "column 'peak [rad/s]' holds nan: say what it means"),
    (("mode [1]", "order [1]"), (1, ""), "column 'order [1]' holds an empty cell"),
    (("mode [1]", "dominant [1]"), (1, "pitch"), "column 'dominant [1]' holds the text 'pitch'"),
    (("mode [1]", "frequency"), (1, 2.5), "column 'frequency' holds the number 2.5"),
    (("mode [1]", "peak [rad/s]"), (1, None), "column 'peak [rad/s]' holds an empty cell None"),
])
def test_a_cell_that_breaks_the_rules_is_refused_before_the_file_is_written(header, row, words, tmp_path):
    with pytest.raises(ValueError) as refused:
        write_csv(tmp_path / "table.csv", header, [row])
    assert str(refused.value).startswith(f"table.csv: {words}")
    assert not (tmp_path / "table.csv").exists()


def test_numbers_under_units_and_texts_without_are_written(tmp_path):
    path = write_csv(tmp_path / "table.csv", ("mode [1]", "dominant", "f [Hz]"), [(1, "pitch", 2.5), (2, "yaw", 3)])
    assert path.read_text().splitlines() == ["mode [1],dominant,f [Hz]", "1,pitch,2.5", "2,yaw,3"]
