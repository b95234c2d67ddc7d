"""The host table of docs/hosting.md is what the engines do: each cell measured again, each run in
a process of its own (an engine that aborts is a result, not a crash of the test session)."""

from __future__ import annotations

from pathlib import Path

from fmu_harness.checks import engine_refusals
from fmu_harness.doc_pages.sections import section

HOSTING = Path(__file__).resolve().parents[2] / "docs" / "hosting.md"


def test_the_host_table_is_what_each_engine_does(fmi2_dir, native_dir):
    assert engine_refusals.table(fmi2_dir, native_dir) == section(HOSTING, "engine-refusals")

