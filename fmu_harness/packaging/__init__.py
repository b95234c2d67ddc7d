"""Building the project's FMUs: :func:`build` one model for one FMI version, :func:`build_all`
the catalog, :func:`fmu_path` where they go; :mod:`.native` the native (C) FMUs."""

from .fmu import FMI_VERSIONS, build, build_all, fmu_path

__all__ = ["FMI_VERSIONS", "build", "build_all", "fmu_path"]
