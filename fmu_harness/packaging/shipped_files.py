"""The project's files an FMU ships: the modules its model and adapter import, and their packages' data.

The imports are found by reading the modules' byte code (:mod:`modulefinder`), following only the
project's own packages: numpy, scipy and the standard library come from the host's Python.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterable
from modulefinder import ModuleFinder
from pathlib import Path


class ProjectModuleFinder(ModuleFinder):
    """A :class:`ModuleFinder` that does not look into top-level packages other than ``packages``."""

    def __init__(self, packages: Iterable[str]) -> None:
        self.packages = set(packages)
        roots = {str(package_root(name)) for name in self.packages}
        super().__init__(path=sorted(roots))

    def find_module(self, name, path, parent=None):  # noqa: ANN001, ANN201  (ModuleFinder's signature)
        if path is None and name not in self.packages:
            raise ImportError(f"{name} is not a project package")
        return super().find_module(name, path, parent)


def package_root(name: str) -> Path:
    """The folder holding top-level package or module ``name`` as imported here."""
    module = importlib.import_module(name)
    location = Path(module.__file__)
    return location.parent.parent if location.name == "__init__.py" else location.parent


#: Sub-folders that hold no data of the Python FMUs: ``fmu_src/native/`` holds the native FMUs' C
#: sources (85 kB more in every Python FMU, and with them a Python FMU of FMI 2.0 followed by one
#: of FMI 3.0 in one process was seen to corrupt the heap of the wrappers' shared host);
#: ``fmu_src/docs`` the repository's doc pages (217 kB), of which ``documentation/`` carries the
#: model's own (:mod:`.documentation`).
NOT_DATA = ("__pycache__", "native", "docs")


def data_files(package: Path) -> list[Path]:
    """Files in the sub-folders of ``package`` that are not packages themselves (e.g. ``data/``)."""
    return sorted(
        path
        for folder in package.iterdir()
        if folder.is_dir() and folder.name not in NOT_DATA and not (folder / "__init__.py").exists()
        for path in folder.rglob("*")
        if path.is_file() and "__pycache__" not in path.parts
    )


def shipped_files(modules: Iterable[str]) -> dict[str, Path]:
    """Archive name (relative to the FMU's ``resources``) -> file, for ``modules`` and all the
    project modules they import, with their packages' data files."""
    modules = list(modules)
    finder = ProjectModuleFinder({name.split(".")[0] for name in modules})
    for name in modules:
        finder.import_hook(name)
    files: dict[str, Path] = {}
    for name, module in finder.modules.items():
        if module.__file__ is None:
            continue
        source = Path(module.__file__)
        root = package_root(name.split(".")[0])
        files[source.relative_to(root).as_posix()] = source
        if module.__path__:
            files.update((path.relative_to(root).as_posix(), path) for path in data_files(source.parent))
    return files
