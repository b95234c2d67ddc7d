"""Building the project's FMUs: :func:`build` one model for one FMI version, :func:`build_all`
the catalog, :func:`fmu_path` where they go; :mod:`.native` the native (C) FMUs.

The Python FMUs' builder (pythonfmu and its templates) is imported when one of its names is first
used, so a command that only runs packages does not load it."""

from __future__ import annotations

from typing import Any

__all__ = ["FMI_VERSIONS", "build", "build_all", "fmu_path"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from . import fmu

        return getattr(fmu, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
