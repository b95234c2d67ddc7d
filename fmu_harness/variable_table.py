"""Markdown table of a model's variables, from its spec (pasted into README.md, checked by a test)."""

from __future__ import annotations

import sys

from driveline.catalog import MODELS
from driveline.variables import ModelSpec


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
            f"| `{v.name}` | {v.causality} | {unit} | {_cell(v.start)} | {_cell(v.min)} | {_cell(v.max)} | {v.description} |"
        )
    return "\n".join(lines)


if __name__ == "__main__":
    names = sys.argv[1:] or list(MODELS)
    print("\n\n".join(markdown(MODELS[name].spec) for name in names))
