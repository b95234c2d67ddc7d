"""The work budget's per-unit rates (driveline/rotor/unit_rates.py) are the measured ones, and what the
refusal and the docs say follows from them: the rates and the docs' table are written by one run of
``benchmarks/unit_rates.py --update-docs``, so the page, the declaration and the message cannot drift apart."""

from __future__ import annotations

import re
from pathlib import Path

from benchmarks.report import STAMP
from driveline.rotor import budget, unit_rates
from driveline.rotor.model import CriticalSpeedsModel
from fmu_harness.doc_pages.sections import section

PAGE = Path(__file__).resolve().parents[2] / "docs" / "critical_speeds.md"
#: The limits the whole budget must stay within, at the measured rates (CPU seconds).
NATIVE_LIMIT, PYTHON_LIMIT = 5.0, 30.0


def test_the_whole_budget_stays_within_its_limits_at_the_measured_rates():
    assert budget.UNITS * unit_rates.NATIVE_SECONDS_PER_UNIT < NATIVE_LIMIT
    assert budget.UNITS * unit_rates.PYTHON_SECONDS_PER_UNIT < PYTHON_LIMIT


def test_the_refusal_states_the_budget_at_the_measured_native_rate_in_both_families():
    seconds = budget.UNITS * unit_rates.NATIVE_SECONDS_PER_UNIT
    assert f"(about {seconds:.1f} s)" in budget.refusal("Campbell table")
    assert CriticalSpeedsModel.native_constants["BUDGET_REFUSAL"] == budget.refusal("%s")


def test_the_docs_table_is_the_declared_measurement():
    text = section(PAGE, "benchmark-unit-rates")
    stamp = text.split("\n", 1)[0]
    assert STAMP.fullmatch(stamp)
    assert stamp.removeprefix("Measured ").rstrip(".") == unit_rates.MEASURED
    rows = dict(re.findall(r"^\| (native|Python) \| (\d+) \|", text, re.MULTILINE))
    assert rows == {"native": f"{unit_rates.NATIVE_SECONDS_PER_UNIT * 1e9:.0f}",
                    "Python": f"{unit_rates.PYTHON_SECONDS_PER_UNIT * 1e9:.0f}"}
    assert f"driveline: {budget.refusal('Campbell table')}" in text
