"""What every FMU carries in ``documentation/``: its model's doc page (``docs/<model>.md``) and
the project's licence (``documentation/licenses/``, where FMI 3.0 puts licences; FMI 2.0 FMUs
alike)."""

from __future__ import annotations

import re
from pathlib import Path

import fmu_src

DOCS = Path(fmu_src.__file__).resolve().parent / "docs"  # links to the repository's docs/ (so the wheel has them)
LICENSE = Path(fmu_src.__file__).resolve().parent / "LICENSE"


def snake_case(name: str) -> str:
    """``CardanJoint`` -> ``cardan_joint``: the model's file names."""
    return re.sub(r"(?<!^)(?=[A-Z])", "_", name).lower()


def members(name: str) -> dict[str, bytes]:
    """The ``documentation/`` members of model ``name``'s FMU, by their name in the archive (a
    model outside the catalog, such as the benchmarks' twins, has no page: the licence alone)."""
    page = DOCS / f"{snake_case(name)}.md"
    return {**({f"documentation/{page.name}": page.read_bytes()} if page.is_file() else {}),
            "documentation/licenses/LICENSE.txt": LICENSE.read_bytes()}
