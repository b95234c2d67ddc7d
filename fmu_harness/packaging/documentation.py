"""What every FMU carries in ``documentation/``: ``index.html`` (the FMI entry point), rendered
from its model's doc page (``docs/<model>.md``), the page itself, and the project's licence
(``documentation/licenses/``, where FMI 3.0 puts licences; FMI 2.0 FMUs alike).

The rendering is the Markdown the doc pages use, no more: headings (with GitHub's anchors),
paragraphs, lists, tables, fenced and indented code, inline code, bold, italics and links. A link
to a section of the page stays a link; a link to another page of the repository, which the FMU
does not carry, becomes its text followed by the page's path in the repository."""

from __future__ import annotations

import html
import re
from pathlib import Path

import fmu_src

DOCS = Path(fmu_src.__file__).resolve().parent / "docs"  # links to the repository's docs/ (so the wheel has them)
LICENSE = Path(fmu_src.__file__).resolve().parent / "LICENSE"
STYLE = ("body{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.45}"
         "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px}"
         "pre{background:#f4f4f4;padding:6px;overflow-x:auto}code{background:#f4f4f4}")


def snake_case(name: str) -> str:
    """``CardanJoint`` -> ``cardan_joint``: the model's file names."""
    return re.sub(r"(?<!^)(?=[A-Z])", "_", name).lower()


def members(name: str, platforms: str = "") -> dict[str, bytes]:
    """The ``documentation/`` members of model ``name``'s FMU, by their name in the archive (a
    model outside the catalog, such as the benchmarks' twins, has no page: the licence alone);
    ``platforms``, a sentence naming the platforms whose binaries the FMU carries, opens the HTML
    page's text (:func:`with_platforms`)."""
    page = DOCS / f"{snake_case(name)}.md"
    pages = {}
    if page.is_file():
        text = with_platforms(page.read_text(encoding="utf-8"), platforms)
        pages = {"documentation/index.html": to_html(text, page.name).encode(),
                 f"documentation/{page.name}": page.read_bytes()}
    return {**pages, "documentation/licenses/LICENSE.txt": LICENSE.read_bytes()}


PLATFORMS_HEADING = "Platforms of this FMU"


def with_platforms(markdown: str, platforms: str) -> str:
    """The page with a section :data:`PLATFORMS_HEADING` holding ``platforms`` after its title; the page
    as it is without."""
    if not platforms:
        return markdown
    title, _, rest = markdown.partition("\n")
    return f"{title}\n\n## {PLATFORMS_HEADING}\n\nThis FMU carries {platforms}.\n{rest}"


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces as hyphens."""
    return re.sub(r"[^\w\- ]", "", heading).strip().lower().replace(" ", "-")


def _inline(text: str, page: str) -> str:
    """Inline Markdown of ``text`` as HTML: code spans first, then links, bold and italics."""
    spans: list[str] = []

    def keep(markup: str) -> str:
        spans.append(markup)
        return f"\0{len(spans) - 1}\0"

    text = re.sub(r"`([^`]+)`", lambda m: keep(f"<code>{html.escape(m[1], quote=False)}</code>"), text)
    text = html.escape(text, quote=False)
    text = re.sub(r"\[([^\]]+)\]\(([^)\s]+)\)", lambda m: keep(_link(m[1], html.unescape(m[2]), page)), text)
    text = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", text)
    text = re.sub(r"(?<![\w*])\*(?![\s*])(.+?)(?<![\s*])\*(?![\w*])", r"<em>\1</em>", text)
    while "\0" in text:
        text = re.sub(r"\0(\d+)\0", lambda m: spans[int(m[1])], text)
    return text


def _link(text: str, target: str, page: str) -> str:
    """A link of the page: to its own sections or the web as it is, to another page of the
    repository as its text and path (docs/ is the folder of the page)."""
    path, _, section = target.partition("#")
    if target.startswith(("http://", "https://")) or not path or path == page:
        href = f"#{section}" if path == page else target
        return f'<a href="{html.escape(href)}">{text}</a>'
    return f"{text} (<code>{html.escape(str(Path('docs', path).as_posix()))}</code> in the repository)"


BLOCK_START = re.compile(r"(#{1,6} |```|\||[*-] |\d+\. |<!--)")
ITEM = re.compile(r"([*-]|\d+\.) +(.*)")


def to_html(markdown: str, page: str) -> str:
    """The doc page ``markdown`` (file name ``page``) as one self-contained HTML page."""
    lines = markdown.splitlines()
    out: list[str] = []
    title = page
    k = 0
    while k < len(lines):
        line = lines[k]
        if not line.strip() or line.startswith("<!--"):
            k += 1
        elif line.startswith("```"):
            end = next((j for j in range(k + 1, len(lines)) if lines[j].startswith("```")), len(lines))
            out.append(f"<pre><code>{html.escape(chr(10).join(lines[k + 1:end]), quote=False)}</code></pre>")
            k = end + 1
        elif line.startswith("    "):
            end = next((j for j in range(k, len(lines)) if lines[j].strip() and not lines[j].startswith("    ")),
                       len(lines))
            code = "\n".join(text[4:] for text in lines[k:end]).strip("\n")
            out.append(f"<pre><code>{html.escape(code, quote=False)}</code></pre>")
            k = end
        elif match := re.match(r"(#{1,6}) +(.*)", line):
            level, heading = len(match[1]), match[2].strip()
            title = heading if level == 1 and title == page else title
            out.append(f'<h{level} id="{anchor(heading)}">{_inline(heading, page)}</h{level}>')
            k += 1
        elif line.startswith("|"):
            end = next((j for j in range(k, len(lines)) if not lines[j].startswith("|")), len(lines))
            out.append(_table(lines[k:end], page))
            k = end
        elif ITEM.match(line):
            k = _list(lines, k, out, page)
        else:
            end = next((j for j in range(k + 1, len(lines))
                        if not lines[j].strip() or BLOCK_START.match(lines[j])), len(lines))
            out.append(f"<p>{_inline(' '.join(text.strip() for text in lines[k:end]), page)}</p>")
            k = end
    body = "\n".join(out)
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n<title>{html.escape(title)}</title>\n'
            f"<style>{STYLE}</style>\n</head>\n<body>\n{body}\n</body>\n</html>\n")


def _list(lines: list[str], k: int, out: list[str], page: str) -> int:
    """One list from line ``k``: items with their indented continuation lines; the line after it."""
    ordered = lines[k][0].isdigit()
    items: list[str] = []
    while k < len(lines) and (match := ITEM.match(lines[k])) and match[1][0].isdigit() == ordered:
        text = [match[2]]
        k += 1
        while k < len(lines) and lines[k].startswith(" ") and lines[k].strip():
            text.append(lines[k].strip())
            k += 1
        items.append(f"<li>{_inline(' '.join(text), page)}</li>")
        if k + 1 < len(lines) and not lines[k].strip() and ITEM.match(lines[k + 1]):
            k += 1  # a blank line between items of one list
    tag = "ol" if ordered else "ul"
    out.append(f"<{tag}>\n" + "\n".join(items) + f"\n</{tag}>")
    return k


def _cells(row: str) -> list[str]:
    """The cells of a table row, split at the pipes outside code spans."""
    cells, cell, code = [], "", False
    for char in row.strip()[1:]:
        if char == "|" and not code:
            cells.append(cell.strip())
            cell = ""
        else:
            code ^= char == "`"
            cell += char
    return cells


def _table(rows: list[str], page: str) -> str:
    """A pipe table; its second row is the header's rule."""
    cells = [_cells(row) for row in rows]
    head, body = cells[0], cells[2:] if len(cells) > 1 and set("".join(cells[1])) <= set("-: ") else cells[1:]
    lines = ["<table>", "<tr>" + "".join(f"<th>{_inline(cell, page)}</th>" for cell in head) + "</tr>"]
    lines += ["<tr>" + "".join(f"<td>{_inline(cell, page)}</td>" for cell in row) + "</tr>" for row in body]
    return "\n".join([*lines, "</table>"])
