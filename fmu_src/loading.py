"""The slave base class of an FMU script, imported from the FMU's own folder.

A generated FMU script is one class statement over the base :func:`slave_base` returns. Both
loaders put the FMU's ``resources`` folder on ``sys.path`` and import its packages by name, so
every FMU of this project loaded into one host process shares ``driveline`` and ``fmu_src``:

* an FMU unloaded since (its folder deleted) may have left modules cached from that folder:
  they are dropped, so this FMU imports its own;
* an FMU still loaded may have shipped other modules of the same packages (each FMU ships only
  what its model imports): the packages' search paths gain this FMU's folders.

A host Python without the FMU's dependencies gets a slave whose instantiation fails with the
missing package and the remedy: an exception while the loader imports the script would crash
pythonfmu3's host.
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path
from typing import Any

PROJECT_PACKAGES = ("driveline", __name__.split(".")[0])


def _project_modules(packages: set[str]) -> list[tuple[str, Any]]:
    return [(name, module) for name, module in list(sys.modules.items()) if name.split(".")[0] in packages]


def drop_unloaded(packages: set[str]) -> None:
    """Forget the modules of ``packages`` whose file no longer exists."""
    for name, module in _project_modules(packages):
        if not os.path.exists(getattr(module, "__file__", None) or ""):
            del sys.modules[name]


def extend_search_paths(packages: set[str], folder: Path) -> None:
    """Let the cached packages of ``packages`` find their submodules in ``folder`` too, and no
    longer in folders that were deleted."""
    for name, module in _project_modules(packages):
        search_path = getattr(module, "__path__", None)
        if not isinstance(search_path, list):
            continue
        search_path[:] = [entry for entry in search_path if os.path.isdir(entry)]
        own = folder.joinpath(*name.split("."))
        if own.is_dir() and str(own) not in search_path:
            search_path.append(str(own))


def slave_base(script: str, adapter: str, model: str) -> type:
    """The base of the slave class defined in ``script`` (the FMU script's ``__file__``):
    module ``adapter``'s ``ModelSlave`` running ``model`` ("module:Class")."""
    module_name, class_name = model.split(":")
    packages = {*PROJECT_PACKAGES, module_name.split(".")[0]}
    drop_unloaded(packages)
    extend_search_paths(packages, Path(script).resolve().parent)
    slave = importlib.import_module(adapter).ModelSlave
    try:
        model_class = getattr(importlib.import_module(module_name), class_name)
    except ImportError as missing:
        return missing_dependency(slave, missing)
    return type(f"{class_name}Slave", (slave,), {"model_class": model_class})


def missing_dependency(slave: type, missing: ImportError) -> type:
    """A ``slave`` subclass whose instantiation fails naming the missing package and the remedy."""

    def refuse(self: Any, **kwargs: Any) -> None:
        name = type(self).__name__
        raise ImportError(
            f"FMU {name}: the Python running it cannot import {missing.name!r}. Install the packages in the "
            f"FMU's resources/requirements.txt into that Python, e.g. '{slave.deploy_command} -f {name}.fmu'."
        )

    return type("MissingDependency", (slave,), {"__init__": refuse})
