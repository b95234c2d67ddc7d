"""The benchmarks' tables as generated sections of the docs, each stamped with its date, machine and load.

A benchmark run with ``--update-docs`` writes its table into the docs section ``benchmark-...``
(:mod:`fmu_harness.doc_pages.sections`), found in whichever page of ``docs/`` holds it. The section
starts with the stamp line of :meth:`Measurement.stamp`, matched by :data:`STAMP`, so that no number
there is undated.
"""

from __future__ import annotations

import argparse
import os
import re
from datetime import datetime, timezone
from pathlib import Path

from benchmarks.timing import machine
from fmu_harness.doc_pages.sections import DOCS, markers, replace_section

PREFIX = "benchmark-"
STAMP = re.compile(r"Measured \d{4}-\d\d-\d\d \d\d:\d\d UTC on .+, \d+ cores, Python \d+\.\d+\.\d+; "
                   r"load average \(1 min\) \d+\.\d\d at start, \d+\.\d\d at end(; .+)?\.")


class Measurement:
    """Date and load of one benchmark run, from its start (creation) to its stamp."""

    def __init__(self) -> None:
        self.date = datetime.now(timezone.utc)
        self.load = os.getloadavg()[0]

    def stamp(self, note: str = "") -> str:
        """The stamp line: date (UTC), machine, the 1-minute load average at the start and now, ``note``."""
        return (f"Measured {self.date:%Y-%m-%d %H:%M} UTC on {machine()}; load average (1 min) "
                f"{self.load:.2f} at start, {os.getloadavg()[0]:.2f} at end{f'; {note}' if note else ''}.")


def parser(description: str) -> argparse.ArgumentParser:
    """Command-line parser of a benchmark, with ``--update-docs``."""
    result = argparse.ArgumentParser(description=description)
    result.add_argument("--update-docs", action="store_true",
                        help="also write the tables into their generated sections of the docs pages")
    return result



def critical_speeds_parser(description: str) -> argparse.ArgumentParser:
    """:func:`parser` with the native CriticalSpeeds FMU as an optional argument."""
    result = parser(description)
    result.add_argument("fmu", nargs="?", type=Path, default=Path("models/native/CriticalSpeeds.fmu"),
                        help="the native CriticalSpeeds FMU")
    return result

def page_of(name: str, docs: Path = DOCS) -> Path:
    """The one docs page holding the section ``name``."""
    pages = [page for page in sorted(docs.glob("*.md")) if markers(name)[0] in page.read_text()]
    if len(pages) != 1:
        raise ValueError(f"{len(pages)} pages of {docs} hold the section {name}, not one")
    return pages[0]


def publish(name: str, stamp: str, table: str, update_docs: bool) -> None:
    """Print ``table`` under ``stamp``; with ``update_docs``, write both into the section ``name``."""
    if not name.startswith(PREFIX):
        raise ValueError(f"a benchmark's section is named {PREFIX}...: {name}")
    body = f"{stamp}\n\n{table}"
    print(body, flush=True)
    if update_docs:
        replace_section(page_of(name), name, body)
