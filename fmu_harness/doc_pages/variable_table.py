"""Markdown tables of the models' variables, from their specs.

``python -m fmu_harness.doc_pages.variable_table`` prints them; ``--update docs`` rewrites the part of each
model's page (:func:`fmu_harness.doc_pages.sections.model_page`) between its ``variables:start`` and
``variables:end`` markers.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from driveline.catalog import MODELS
from driveline.variables import ModelSpec

from .sections import DOCS, model_page, replace_section
from ..console import summary


def _escaped(text: str) -> str:
    """A table cell's text with its pipes escaped (|omega| would end the cell)."""
    return text.replace("|", "\\|")


def _cell(value: object) -> str:
    return "" if value is None else f"{value:.6g}" if isinstance(value, float) else str(value)


def _bound(value: float | None, exclusive: bool, sign: str) -> str:
    """A min or max cell; an exclusive bound is marked ``> 0`` or ``< 90``."""
    return f"{sign} {_cell(value)}" if exclusive else _cell(value)


def constraints(spec: ModelSpec) -> str:
    """The sentence under a table: the declared relations, and how exclusive bounds reach the FMU."""
    relations = ", ".join(f"`{r}`" + (f" ({r.reason})" if r.reason else "") for r in spec.relations)
    exclusive = any(v.min_exclusive or v.max_exclusive for v in spec.variables)
    parts = [f"Relations the model enforces: {relations}." if relations else ""]
    if exclusive:
        parts.append("Bounds marked `>` or `<` are exclusive: the model refuses the bound itself, the model "
                     "description carries it as FMI's inclusive min or max.")
    return " ".join(part for part in parts if part)


def markdown(spec: ModelSpec) -> str:
    lines = [
        "| name | causality | unit (display) | start | min | max | description |",
        "|---|---|---|---|---|---|---|",
    ]
    for v in spec.variables:
        unit = (v.unit or "") + (f" ({v.display_unit})" if v.display_unit else "")
        low, high = _bound(v.min, v.min_exclusive, ">"), _bound(v.max, v.max_exclusive, "<")
        lines.append(
            f"| `{v.name}` | {v.causality} | {unit} | {_cell(v.start)} | {low} | {high} | {_escaped(v.description)} |"
        )
    note = constraints(spec)
    return "\n".join(lines + (["", _escaped(note)] if note else []))


def all_tables() -> str:
    return "\n\n".join(f"#### {model.spec.name}\n\n{markdown(model.spec)}" for model in MODELS.values())


def update(docs: Path = DOCS) -> None:
    for name, model in MODELS.items():
        replace_section(model_page(name, docs), "variables", markdown(model.spec))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--update", type=Path, metavar="DOCS", help="docs folder whose model pages to rewrite")
    args = parser.parse_args()
    if args.update:
        update(args.update)
    else:
        print(all_tables())
