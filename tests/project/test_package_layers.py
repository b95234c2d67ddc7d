"""The packages' layers: each imports only those below it, so no two of them import each other.

Read from the source (every ``import``, also those inside functions), not from what happens to be
imported at run time.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: Bottom to top; a package may import its own modules and those of the packages before it.
LAYERS = (
    "driveline",
    "fmu_src",
    "fmu_harness.console",  # what the commands show: one-line errors, progress, missing extras
    "fmu_harness.packaging",
    "fmu_harness.doc_pages",
    "fmu_harness.runs",
    "fmu_harness.checks",
    "fmu_harness.studies",
    "fmu_harness",  # the commands on top: build_command, main, cli
)
#: Packages a layer does not import although it sits above them.
KEPT_APART = {"fmu_harness.studies": {"fmu_harness.checks", "fmu_harness.doc_pages"},
              "fmu_harness.doc_pages": {"fmu_harness.packaging"}}


def layer(module: str) -> str | None:
    """The layer of dotted ``module`` (the longest layer name it starts with), None outside the project."""
    owners = [name for name in LAYERS if module == name or module.startswith(f"{name}.")]
    return max(owners, key=len) if owners else None


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path) -> set[str]:
    """Every module ``path`` imports, relative imports resolved."""
    package = module_name(path) if path.name == "__init__.py" else module_name(path).rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            found.update(f"{base}.{alias.name}" for alias in node.names)
    return found


SOURCES = sorted(path for name in ("driveline", "fmu_src", "fmu_harness") for path in (ROOT / name).rglob("*.py"))


def crossings() -> dict[tuple[str, str], list[str]]:
    """(importing layer, imported layer) -> the imports that cross between two different layers."""
    found: dict[tuple[str, str], list[str]] = {}
    for path in SOURCES:
        own = layer(module_name(path))
        for target in imports(path):
            other = layer(target)
            if other is not None and other != own:
                found.setdefault((own, other), []).append(f"{path.relative_to(ROOT)}: {target}")
    return found


def test_the_layer_picture_covers_every_module():
    assert SOURCES and all(layer(module_name(path)) for path in SOURCES)


@pytest.mark.parametrize("importer", LAYERS)
def test_each_layer_imports_only_the_layers_below_it(importer):
    rank = LAYERS.index(importer)
    wrong = {pair: where for pair, where in crossings().items() if pair[0] == importer and (
        LAYERS.index(pair[1]) > rank or pair[1] in KEPT_APART.get(importer, ()))}
    assert not wrong, wrong


def test_the_check_sees_a_crossing():
    """The check finds imports across layers at all (the harness uses the core everywhere)."""
    assert ("fmu_harness.runs", "fmu_harness.packaging") in crossings()
    assert ("fmu_src", "driveline") in crossings()
