"""Build every FMU of the project: the Python FMUs, FMI 2.0 into ``models/`` and FMI 3.0 into
``models/fmi3/``, and the native (C) FMUs into ``models/native/`` and ``models/native/fmi3/``.

Usage: ``driveline-fmus build [--dest models] [--fmi 2 3] [--no-references] [NAME ...]`` (or
``python build_fmu.py ...``). Every model of ``driveline.catalog.MODELS`` becomes one Python FMU
per FMI version (:mod:`.fmu`) and, with the machine's C compiler (``cc`` or ``$CC``), one native
FMU per FMI version (:mod:`.native`). Then the FMI Cross-Check reference results are written
next to each FMU, Python and native (:mod:`fmu_harness.crosscheck`), and, once its FMI 2.0 FMUs
are there, the driveline system's SSP packages, ``Driveline.ssp`` with the Python FMUs and
``native/Driveline.ssp`` with the native ones (:mod:`fmu_harness.system`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from driveline.catalog import MODELS

from .. import crosscheck, system
from . import native
from .fmu import FMI_VERSIONS, build_all


def main(argv: list[str] | None = None, prog: str | None = None, dest: Path = Path("models")) -> None:
    parser = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0].replace("``", ""))
    parser.add_argument("names", nargs="*", help=f"models to build (default: all of {', '.join(MODELS)})")
    parser.add_argument("--dest", type=Path, default=dest, help=f"folder of the FMI 2.0 FMUs (default {dest})")
    parser.add_argument("--fmi", nargs="+", choices=sorted(FMI_VERSIONS), default=sorted(FMI_VERSIONS),
                        help="FMI versions to build (default: both)")
    parser.add_argument("--no-references", action="store_true", help="skip the cross-check reference results")
    args = parser.parse_args(argv)
    paths = []
    for fmu in build_all(args.dest, args.names or None, tuple(args.fmi)):
        paths += [fmu] + ([] if args.no_references else crosscheck.write(fmu))
    for fmu in native.build_all(args.dest, args.names or None, tuple(args.fmi)):
        paths += [fmu] + ([] if args.no_references else crosscheck.write(fmu))
    driveline = system.driveline()
    for natives in (None, args.dest):  # the Python system, then its native variant
        if all(fmu.exists() for fmu in system.component_fmus(driveline, args.dest, natives).values()):
            paths.append(system.write_ssp(driveline, args.dest, natives))
    here = Path.cwd()
    for path in paths:
        print(path.relative_to(here) if path.is_relative_to(here) else path)
