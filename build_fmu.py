"""Build every FMU of the project into ``models/`` next to this file (FMI 3.0 into ``models/fmi3/``,
the native ones into ``models/native/`` and ``models/native/fmi3/``).

Usage: ``python build_fmu.py [--dest models] [--fmi 2 3] [--no-references] [NAME ...]``, the same
as ``driveline-fmus build``; the build itself is :mod:`fmu_harness.packaging`.
"""

from pathlib import Path

from fmu_harness.build_command import main

if __name__ == "__main__":
    main(dest=Path(__file__).resolve().parent / "models")
