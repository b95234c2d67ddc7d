"""The main job's CSV files: the time (or the swept variable) first, every column headed
``name [unit]``, no row written twice."""

from __future__ import annotations

import csv
from collections.abc import Iterable, Sequence
from pathlib import Path

from driveline.variables import ModelSpec


def column(spec: ModelSpec, name: str) -> str:
    """``name [unit]`` of one variable of ``spec``; a variable without a unit (an integer,
    a flag) counts in ``1``."""
    return f"{name} [{spec[name].unit or '1'}]"


def write_csv(path: Path, header: Sequence[str], rows: Iterable[Sequence[object]]) -> Path:
    """Write ``header`` and ``rows``; ValueError if a row repeats an earlier one."""
    written: set[tuple] = set()
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        for row in rows:
            key = tuple(row)
            if key in written:
                raise ValueError(f"{path.name}: row {key} written twice")
            written.add(key)
            writer.writerow(row)
    return path
