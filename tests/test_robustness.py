"""The robustness suite (fmu_harness.robustness): every hostile input and misuse of issue 14's
classes, each in its own host process with a time limit, through fmpy (FMI 2.0 and 3.0) and a
subset in libcosim and Ecos. Every column of the table must stay at zero; a departure that the
Python wrappers force is a defined outcome, checked as documented in docs/robustness.md."""

from __future__ import annotations

from pathlib import Path

import pytest

from fmu_harness import build, robustness

CLASSES = {"non-finite values", "out-of-range values", "step sizes", "call sequence misuse",
           "state round trips and corrupt state", "instances and threads", "hostile layout values",
           "work, memory and resolution limits", "outputs at a start time other than 0",
           "model failures outside its checks"}


@pytest.fixture(scope="module")
def paths(fmu_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> robustness.FmuPath:
    """The catalog's FMUs, and those of the failing model in a folder of their own."""
    return robustness.with_failing_model(lambda model, fmi: build.fmu_path(fmu_dir, model, fmi),
                                         tmp_path_factory.mktemp("failing"))


def _report(results: list[robustness.Result]) -> str:
    return robustness.table(results) + "".join(
        f"\n- {r.verdict}: FMI {r.case.fmi} {r.case.kind} / {r.case.name}: {r.detail}" for r in robustness.failures(results))


@pytest.fixture(scope="module")
def results(paths: robustness.FmuPath) -> list[robustness.Result]:
    return robustness.run_all(robustness.cases(paths))


def test_no_case_crashes_hangs_or_gets_a_wrong_status_or_output(results):
    assert not robustness.failures(results), _report(results)


def test_the_suite_covers_every_class_in_both_fmi_versions(results):
    for fmi in ("2", "3"):
        assert {r.case.kind for r in results if r.case.fmi == fmi} >= CLASSES


@pytest.mark.slow
def test_every_variable_value_and_model_and_a_long_soak(paths: robustness.FmuPath, results):
    """The cases the default run samples, and 100,000 bad/good alternations per FMI version with
    resident memory bounded."""
    sampled = {(r.case.fmi, r.case.kind, r.case.name) for r in results}
    rest = [c for c in robustness.cases(paths, slow=True) if (c.fmi, c.kind, c.name) not in sampled]
    slow_results = robustness.run_all(rest)
    assert not robustness.failures(slow_results), _report(slow_results)
