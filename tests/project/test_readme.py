"""README.md and the docs pages stay in step with the code: generated variable tables and links
that lead somewhere (the CI command: ``test_constraints.py``)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from driveline.catalog import MODELS
from fmu_harness.runs import system
from fmu_harness.packaging import documentation
from fmu_harness.doc_pages.sections import model_page, replace_section, section
from fmu_harness.doc_pages.variable_table import markdown

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
PAGES = sorted((ROOT / "docs").glob("*.md"))


@pytest.mark.parametrize("name", MODELS)
def test_each_model_page_ends_with_its_generated_variable_table(name):
    page = model_page(name, ROOT / "docs")
    assert section(page, "variables") == markdown(MODELS[name].spec), (
        f"regenerate {page.name}: python -m fmu_harness.doc_pages.variable_table --update docs"
    )
    assert page.read_text().rstrip().endswith("<!-- variables:end -->")


def test_a_stale_table_is_found_and_regenerated(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("# Body\n\n<!-- variables:start -->\n| old |\n<!-- variables:end -->\n")
    assert section(page, "variables") == "| old |"
    replace_section(page, "variables", "| new |")
    assert page.read_text() == "# Body\n\n<!-- variables:start -->\n| new |\n<!-- variables:end -->\n"
    with pytest.raises(ValueError, match="interop"):
        section(page, "interop")


def test_readme_connects_the_models_as_the_ssp_system_does():
    driveline = system.driveline()
    model = {component.name: component.model for component in driveline.components}
    text = README.read_text()
    for connection in driveline.connections:
        (start, output), (end, input_) = connection.start, connection.end
        assert f"| `{model[start]}.{output}` | `{model[end]}.{input_}`" in text
    assert "`models/Driveline.ssp`" in text and "`models/native/Driveline.ssp`" in text


def test_readme_stays_short():
    assert len(README.read_text().splitlines()) <= 140


@pytest.mark.parametrize("page", [README, *PAGES], ids=lambda p: p.name)
def test_relative_links_lead_to_files_and_headings(page):
    text = page.read_text()
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if "://" in target:
            continue
        path, _, anchor = target.partition("#")
        linked = (page.parent / path).resolve() if path else page
        assert linked.exists(), f"{page.name} links to missing {path}"
        if anchor and linked.suffix == ".md":
            assert anchor in _anchors(linked.read_text()), f"{page.name} links to missing heading {target}"


def _anchors(markdown_text: str) -> set[str]:
    """GitHub's heading anchors: lower case, punctuation dropped, spaces as hyphens."""
    return {documentation.anchor(h) for h in re.findall(r"^#+ (.+)$", markdown_text, flags=re.MULTILINE)}
