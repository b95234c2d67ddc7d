"""The work model of the CriticalSpeeds analysis (driveline/rotor/work.py): every stage estimated before
any starts, the worst inputs the limits allow analysed within the budgets, the rest refused at
initialisation with the estimate, in both cores alike."""

from __future__ import annotations

import time

import pytest

from benchmarks.analysis_work import over_budget
from driveline.rotor.loader import example_path, load_driveline, loads_driveline
from driveline.rotor.model import CAMPBELL_POINTS, FE_ELEMENTS, CriticalSpeedsModel
from driveline.rotor.work import MAX_ANALYSIS_SECONDS, estimate
from driveline.rotor.budget import refusal
from fmu_harness.checks.analysis_work import BUDGET_LAYOUT, BUDGET_PARAMETERS, layout_text, measure, worst_cases
from fmu_harness.checks.work_fuzzer import BUDGETS, CASE_LAYOUT, run_limited
from fmu_harness.packaging import native
from fmu_harness.runs.runner import FmuInstance, StepRefused

ISSUE_LAYOUT = layout_text(100, 1.4, 202, 202, 200)  # every loader limit kept; once 566 s native, 16 GB Python


def test_the_propshaft_engineers_shaft_stays_well_inside():
    """A 20-segment two-piece shaft with 10 masses and 6 bearings, and the shipped examples, are
    estimated at most half the limit (measured: a tenth of the budgets, docs/robustness.md)."""
    for driveline in (loads_driveline(layout_text(20, 1.6, 10, 6, 4)), load_driveline(example_path("two_piece_propshaft")),
                      load_driveline(example_path("two_piece_propshaft_hinged"))):
        assert estimate(driveline, (1, 2, 3), 1500.0, CAMPBELL_POINTS, FE_ELEMENTS).total < MAX_ANALYSIS_SECONDS / 2


def test_the_issues_layout_is_refused_at_initialisation_by_both_cores_alike(native_dir, tmp_path, fmi):
    """The layout whose native analysis took 566 s is refused within a second, before any stage, with
    the estimate of every stage in the message, word for word the Python core's."""
    layout = tmp_path / "stations.toml"
    layout.write_text(ISSUE_LAYOUT)
    values = {"layout": str(layout), "omega_in_max": 1e-3, "orders": "1", "omega_in": 0.0}
    core = CriticalSpeedsModel()
    for name, value in values.items():
        setattr(core, name, value)
    errors = core.parameter_errors()
    assert len(errors) == 1 and "the analysis would take about" in errors[0] and "Campbell table" in errors[0]
    with FmuInstance(native.fmu_path(native_dir, "CriticalSpeeds", fmi)) as fmu:
        started = time.perf_counter()
        with pytest.raises(StepRefused) as refused:
            fmu.initialize(values)
        assert time.perf_counter() - started < 1.0
    assert (refused.value.status, refused.value.messages) == ("Error", errors)


def test_the_worst_inputs_the_limits_allow_stay_within_the_budgets(native_dir, tmp_path):
    """Every worst case of fmu_harness.checks.analysis_work (most stations of every kind, most segments,
    shortest segments, stations between nodes, most and highest orders, smallest and largest
    omega_in_max): each Python stage within 30 s and 2 GB, the native analysis within 5 s and 500 MB,
    each in a process under a limit of time and address space; the issue's layout refused."""
    assert set(worst_cases()) >= {"most stations", "most orders", "smallest omega_in_max", "largest omega_in_max"}
    results = measure(tmp_path, native.fmu_path(native_dir, "CriticalSpeeds", "2"))
    assert over_budget(results) == []


def test_an_analysis_beyond_its_budget_is_refused_naming_the_stage_within_the_budget(family):
    """BUDGET_LAYOUT, accepted by the estimate, spends the analysis's budget (driveline/rotor/budget.py) in
    its Campbell table: refused at initialisation with the stage named, in the same words in both
    families (the Python FMUs log it at initialisation and refuse the first step), within the family's
    budget of CPU time (measured 1.4 s native, 5.8 s Python on a busy machine); initialised with the
    shipped two-piece layout instead, the tunable change of layout to it is refused at that step alike.
    Each run in a process under a limit of CPU time and address space."""
    expected = f"driveline: {refusal('Campbell table')}"
    start = {"layout": BUDGET_LAYOUT, "start": BUDGET_PARAMETERS, "changes": []}
    changed = {"layout": BUDGET_LAYOUT, "start": {**BUDGET_PARAMETERS, "layout": "two_piece_propshaft"},
               "changes": [{"layout": CASE_LAYOUT}]}
    seconds, memory = BUDGETS[family.name]
    for case, refused_at in ((start, 0), (changed, 1)):
        run = run_limited(family.path("CriticalSpeeds"), case, BUDGETS[family.name])
        assert [a["status"] == "OK" for a in run["analyses"]] == [True] * refused_at + [False]
        assert expected in run["analyses"][refused_at]["message"]
        assert all(a["seconds"] < seconds for a in run["analyses"]) and run["peak"] < memory
