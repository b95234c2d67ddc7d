"""Generated sections of the docs pages: the text between ``<!-- NAME:start -->`` and ``<!-- NAME:end -->``.

Each model's page is ``docs/<model in snake case>.md`` (``TripodCoupling`` -> ``docs/tripod_coupling.md``)
and ends with its generated ``variables`` section; ``docs/interoperability.md`` holds the ``interop`` one.
"""

from __future__ import annotations

import re
from pathlib import Path

DOCS = Path("docs")


def markers(name: str) -> tuple[str, str]:
    return f"<!-- {name}:start -->", f"<!-- {name}:end -->"


def model_page(model_name: str, docs: Path = DOCS) -> Path:
    """The doc page of the catalog model ``model_name``."""
    return docs / (re.sub(r"(?<!^)(?=[A-Z])", "_", model_name).lower() + ".md")


def section(path: Path, name: str) -> str:
    """The generated text of section ``name`` of ``path`` (without the markers)."""
    start, end = markers(name)
    text = path.read_text()
    if start not in text or end not in text:
        raise ValueError(f"{path} has no {start} ... {end} section")
    return text.split(start, 1)[1].split(end, 1)[0].strip("\n")


def replace_section(path: Path, name: str, body: str) -> None:
    """Rewrite the section ``name`` of ``path`` with ``body``."""
    section(path, name)
    start, end = markers(name)
    head, rest = path.read_text().split(start, 1)
    tail = rest.split(end, 1)[1]
    path.write_text(f"{head}{start}\n{body}\n{end}{tail}")
