"""The result tables of the main job, the sweeps and the system command: the time (or the swept
variable) first, every numeric column headed ``name [unit]`` and every text column ``name`` alone,
every cell a finite number or a text, no row written twice."""

from __future__ import annotations

import csv
import math
import numbers
import re
from collections.abc import Iterable, Sequence
from pathlib import Path

from driveline.variables import ModelSpec

UNIT = re.compile(r" \[[^\[\]]+\]$")
"""A header's unit: `` [unit]`` at its end."""


def headed(name: str, unit: str | None) -> str:
    """``name [unit]``; a quantity without a unit (an integer, a flag, a ratio) counts in ``1``."""
    return f"{name} [{unit or '1'}]"


def unheaded(header: str) -> tuple[str, str | None]:
    """(name, unit) of a header :func:`headed` wrote, (header, None) of a text column's."""
    found = UNIT.search(header)
    return (header, None) if found is None else (header[:found.start()], found.group()[2:-1])


def column(spec: ModelSpec, name: str) -> str:
    """``name [unit]`` of one variable of ``spec``."""
    return headed(name, spec[name].unit)


def unit_of(variable) -> str:
    """The unit of a model description's variable (fmpy's), its own or its declared type's; ``1``
    without one."""
    return variable.unit or (variable.declaredType.unit if variable.declaredType is not None else None) or "1"


def table_errors(header: Sequence[str], rows: Sequence[Sequence[object]]) -> list[str]:
    """What breaks the rules of the main job's tables: a cell that is empty, not finite or of another
    kind than its column's (a number under ``name [unit]``, a text under ``name``)."""
    errors = []
    for k, name in enumerate(header):
        numeric = bool(UNIT.search(name))
        for row in rows:
            cell = row[k]
            if isinstance(cell, numbers.Real) and not isinstance(cell, bool):
                if not numeric:
                    errors.append(f"column {name!r} holds the number {cell!r}: a text column has no unit, a "
                                  "numeric one needs `name [unit]`")
                elif not math.isfinite(cell):
                    errors.append(f"column {name!r} holds {cell!r}: say what it means in a text column")
            elif not (isinstance(cell, str) and cell.strip()):
                errors.append(f"column {name!r} holds an empty cell {cell!r}")
            elif numeric:
                errors.append(f"column {name!r} holds the text {cell!r}: a text column has no unit")
    return errors


def write_csv(path: Path, header: Sequence[str], rows: Iterable[Sequence[object]]) -> Path:
    """Write ``header`` and ``rows``; ValueError if a row repeats an earlier one or a cell breaks
    :func:`table_errors`."""
    rows = [list(row) for row in rows]
    errors = table_errors(header, rows)
    if errors:
        raise ValueError(f"{path.name}: {errors[0]}" + (f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""))
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
