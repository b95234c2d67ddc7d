"""The benchmarks' generated docs sections: each is written by a benchmark that ``benchmarks/run
--update-docs`` runs, sits in one docs page, and starts with its stamp (date, machine, load), so
that no measured number there is undated and the generator and the pages cannot drift apart."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from benchmarks.report import PREFIX, STAMP, Measurement, page_of
from fmu_harness.doc_pages.sections import section

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
RUN = ROOT / "benchmarks" / "run"


def published() -> dict[str, str]:
    """The sections the benchmarks run by ``benchmarks/run --update-docs`` write, by the module writing each."""
    modules = re.findall(r'python -m benchmarks\.(\w+) "\$\{update\[@\]\}"', RUN.read_text())
    names = {}
    for module in modules:
        found = re.findall(r'publish\(\s*"([\w-]+)"', (ROOT / "benchmarks" / f"{module}.py").read_text())
        assert found, f"benchmarks/run passes --update-docs to {module}, which writes no section"
        names |= dict.fromkeys(found, module)
    return names


def unstamped(docs: Path, names: list[str]) -> list[str]:
    """The sections among ``names`` that no page of ``docs`` holds exactly once, or that do not start with a stamp."""
    problems = []
    for name in names:
        try:
            page = page_of(name, docs)
        except ValueError as error:
            problems.append(str(error))
            continue
        first = section(page, name).split("\n", 1)[0]
        if not STAMP.fullmatch(first):
            problems.append(f"{page.name}, section {name}: no stamp line but {first!r}")
    return problems


def test_benchmark_run_passes_update_docs_to_every_benchmark():
    invoked = re.findall(r"python -m benchmarks\.(\w+)([^;]*)", RUN.read_text())
    assert len(invoked) >= 8
    assert [module for module, rest in invoked if '"${update[@]}"' not in rest] == []


def test_every_section_the_benchmarks_write_is_in_one_page_and_stamped():
    names = published()
    assert len(names) >= 9
    assert unstamped(DOCS, sorted(names)) == [], "run: benchmarks/run --update-docs"


def test_every_benchmark_section_in_the_docs_has_its_benchmark():
    in_pages = {name for page in DOCS.glob("*.md")
                for name in re.findall(rf"<!-- ({PREFIX}[\w-]+):start -->", page.read_text())}
    assert in_pages - published().keys() == set()


def test_a_missing_stamp_or_section_is_found(tmp_path):
    stamp = Measurement().stamp("best of 7 rounds")
    assert STAMP.fullmatch(stamp)
    table = "| FMU | µs/step |\n|---|---|\n| SpeedSource | 9.2 |"
    (tmp_path / "page.md").write_text(f"<!-- {PREFIX}a:start -->\n{stamp}\n\n{table}\n<!-- {PREFIX}a:end -->\n"
                                      f"<!-- {PREFIX}b:start -->\n{table}\n<!-- {PREFIX}b:end -->\n")
    problems = unstamped(tmp_path, [f"{PREFIX}a", f"{PREFIX}b", f"{PREFIX}c"])
    assert len(problems) == 2
    assert "section benchmark-b: no stamp line" in problems[0]
    assert "0 pages" in problems[1] and "benchmark-c" in problems[1]


@pytest.mark.parametrize("line", ["Measured 2026-11-26 on a laptop.", "| FMU | µs/step |",
                                  "Measured 2026-11-26 17:50 UTC on x86_64, 2 cores, Python 3.11.7; load 4."])
def test_a_hand_written_date_is_no_stamp(line):
    assert not STAMP.fullmatch(line)
