"""README.md stays in step with the variable tables and names the commands CI runs."""

from __future__ import annotations

from pathlib import Path

from driveline.catalog import MODELS
from fmu_harness.variable_table import markdown

README = (Path(__file__).resolve().parents[1] / "README.md").read_text()


def test_variable_tables_match_the_specs():
    for model in MODELS.values():
        assert markdown(model.spec) in README, f"regenerate the {model.spec.name} table"


def test_readme_holds_the_ci_test_command():
    assert 'python -m pip install -e ".[test,interop]" && python -m pytest -q' in README
