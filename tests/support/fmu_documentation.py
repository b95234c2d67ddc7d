"""What an FMU's ``documentation/`` must hold, Python or native: ``index.html`` rendered from the
model's doc page, the page, the licence, and no other page of the repository anywhere in the FMU;
every link of ``index.html`` leads to a section of it or to the web; a native FMU's page names the
platforms whose binaries it carries."""

from __future__ import annotations

import html
import re
import zipfile
from html.parser import HTMLParser
from pathlib import Path

from fmu_harness.packaging.documentation import snake_case
from fmu_harness.packaging.toolchain import PLATFORMS, platforms_sentence

ROOT = Path(__file__).resolve().parents[2]
VOID = {"meta", "br", "hr", "img"}


class PageOutline(HTMLParser):
    """Ids, links and the tags left open of one HTML page."""

    def __init__(self) -> None:
        super().__init__()
        self.ids: set[str] = set()
        self.links: list[str] = []
        self.open: list[str] = []
        self.mismatched: list[str] = []

    def handle_starttag(self, tag, attrs):  # noqa: ANN001, ANN201  (HTMLParser's signature)
        found = dict(attrs)
        if "id" in found:
            self.ids.add(found["id"])
        if tag == "a":
            self.links.append(found.get("href", ""))
        if tag not in VOID:
            self.open.append(tag)

    def handle_endtag(self, tag):  # noqa: ANN001, ANN201
        if not self.open or self.open.pop() != tag:
            self.mismatched.append(tag)


def outline(page: str) -> PageOutline:
    parsed = PageOutline()
    parsed.feed(page)
    parsed.close()
    return parsed


def assert_documentation(fmu: Path, model: str) -> None:
    page = f"{snake_case(model)}.md"
    with zipfile.ZipFile(fmu) as archive:
        names = archive.namelist()
        documentation = sorted(name for name in names if name.startswith("documentation/"))
        assert documentation == sorted(["documentation/index.html", "documentation/licenses/LICENSE.txt",
                                        f"documentation/{page}"])
        assert archive.read(f"documentation/{page}") == (ROOT / "docs" / page).read_bytes()
        assert archive.read("documentation/licenses/LICENSE.txt") == (ROOT / "LICENSE").read_bytes()
        index = archive.read("documentation/index.html").decode()
    others = {path.name for path in (ROOT / "docs").glob("*.md")} - {page}
    assert not [name for name in names if Path(name).name in others], "other doc pages shipped"
    parsed = outline(index)
    assert parsed.open == [] and parsed.mismatched == []
    assert "## Variables" not in index and "](" not in index  # every heading and link rendered
    assert "variables" in parsed.ids
    for link in parsed.links:
        assert link.startswith(("https://", "http://")) or link[1:] in parsed.ids, link
    if any(name.startswith("sources/") and name.endswith(".c") for name in names):
        assert_platforms_named(index, names)


def assert_platforms_named(index: str, names: list[str]) -> None:
    """The native FMU's page says, after its title, which platforms it carries binaries for: those of
    its ``binaries/`` folders, each named, and none it lacks named as carried."""
    text = html.unescape(re.sub(r"<[^>]+>", "", index))
    sentence = platforms_sentence(names).replace("`", "")
    assert f"This FMU carries {sentence}." in text
    carried = sentence.split(" only;")[0]
    for platform in PLATFORMS:
        inside = any(name.startswith(f"binaries/{folder}/") for name in names
                     for folder in (platform.fmi2, platform.tuple))
        assert (platform.name in carried) == inside, platform.name
