"""The model tables of docs/native_fmus.md name every native model once, and the directional-derivative
tables say what the binaries give: a model whose C port has the ``jacobian`` hook is "yes", every other
"not yet", and the table of measured errors has a row for exactly the models that give them."""

from __future__ import annotations

import re

import pytest

from fmu_harness.doc_pages.sections import DOCS
from fmu_harness.packaging import native

PAGE = DOCS / "native_fmus.md"


def _table(header: str) -> list[list[str]]:
    """The body rows (cells stripped) of the table whose header line starts with ``header``."""
    lines = PAGE.read_text().splitlines()
    start = [i for i, line in enumerate(lines) if line.startswith(header)]
    assert len(start) == 1, f"{len(start)} tables start with {header!r}"
    rows = []
    for line in lines[start[0] + 2:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip("|").split("|")])
    return rows


def _models(cell: str) -> list[str]:
    return re.findall(r"`(\w+)`", cell)


@pytest.mark.parametrize("header", ["| model | native | Python FMU |", "| model | continuous state |",
                                    "| model | exact directional derivatives |"])
def test_every_native_model_has_one_row(header):
    named = [model for row in _table(header) for model in _models(row[0])]
    assert sorted(named) == sorted(native.native_models())


def test_the_derivative_table_says_what_the_binaries_give():
    for row in _table("| model | exact directional derivatives |"):
        (model,) = _models(row[0])
        given = native.provides_derivatives(model)
        assert row[1].startswith("yes") == given and row[2].startswith("yes") == given, row
        assert given or row[1] == row[2] == "not yet", row


def test_the_measured_errors_cover_the_models_that_give_derivatives():
    rows = _table("| model | FMI | unknowns x knowns | against the FMU's central differences |")
    named = [model for row in rows for model in _models(row[0])]
    assert sorted(named) == sorted(m for m in native.native_models() if native.provides_derivatives(m))
