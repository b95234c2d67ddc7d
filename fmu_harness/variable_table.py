"""Markdown tables of the models' variables, from their specs.

``python -m fmu_harness.variable_table`` prints them; ``--update README.md`` rewrites the
part of that file between the ``variables:start`` and ``variables:end`` markers.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from driveline.catalog import MODELS
from driveline.variables import ModelSpec

from .readme import replace_section


def _escaped(text: str) -> str:
    """A table cell's text with its pipes escaped (|omega| would end the cell)."""
    return text.replace("|", "\\|")


def _cell(value: object) -> str:
    return "" if value is None else f"{value:.6g}" if isinstance(value, float) else str(value)


def markdown(spec: ModelSpec) -> str:
    lines = [
        f"#### {spec.name}",
        "",
        "| name | causality | unit (display) | start | min | max | description |",
        "|---|---|---|---|---|---|---|",
    ]
    for v in spec.variables:
        unit = (v.unit or "") + (f" ({v.display_unit})" if v.display_unit else "")
        lines.append(
            f"| `{v.name}` | {v.causality} | {unit} | {_cell(v.start)} | {_cell(v.min)} | {_cell(v.max)} | {_escaped(v.description)} |"
        )
    return "\n".join(lines)


def all_tables() -> str:
    return "\n\n".join(markdown(model.spec) for model in MODELS.values())


def update(path: Path) -> None:
    replace_section(path, "variables", all_tables())


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--update", type=Path, help="file whose marked variables section to rewrite")
    args = parser.parse_args()
    if args.update:
        update(args.update)
    else:
        print(all_tables())
