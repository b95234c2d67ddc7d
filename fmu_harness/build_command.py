"""Build every FMU of the project: the Python FMUs, FMI 2.0 into ``models/`` and FMI 3.0 into
``models/fmi3/``, and the native (C) FMUs into ``models/native/`` and ``models/native/fmi3/``.

Usage: ``driveline-fmus build [--dest models] [--fmi 2 3] [--no-references] [--host-only] [--native]
[NAME ...]`` (or ``python build_fmu.py ...``). Every model of ``driveline.catalog.MODELS`` becomes one
Python FMU per FMI version (:mod:`.fmu`). The native (C) FMUs of the models with a C port go to
``native/`` and ``native/fmi3/`` below ``--dest`` (:mod:`.native`), with binaries for the five
platforms when ziglang is installed (``--host-only``: this machine's alone). Without a C compiler
the build says what to install in one line and builds the rest; it fails only with ``--native``.
Then the FMI Cross-Check reference results are written next to each FMU, Python and native
(:mod:`fmu_harness.checks.crosscheck`), and, once their FMI 2.0 FMUs are there, the systems' SSP
packages (``Driveline.ssp``, ``VehicleLaunch.ssp``) with the Python FMUs and under ``native/`` with the
native ones (:mod:`fmu_harness.runs.system`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from driveline.catalog import MODELS

from .checks import crosscheck
from .packaging import native, toolchain
from .packaging.fmu import FMI_VERSIONS, build_all
from .runs import system


def main(argv: list[str] | None = None, prog: str | None = None, dest: Path = Path("models")) -> None:
    parser = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0].replace("``", ""))
    parser.add_argument("names", nargs="*", help=f"models to build (default: all of {', '.join(MODELS)})")
    parser.add_argument("--dest", type=Path, default=dest, help=f"folder of the FMI 2.0 FMUs (default {dest})")
    parser.add_argument("--fmi", nargs="+", choices=sorted(FMI_VERSIONS), default=sorted(FMI_VERSIONS),
                        help="FMI versions to build (default: both)")
    parser.add_argument("--no-references", action="store_true", help="skip the cross-check reference results")
    parser.add_argument("--host-only", action="store_true",
                        help="native binaries for this machine only (default: all five platforms with ziglang)")
    parser.add_argument("--native", action="store_true", help="fail if the native FMUs cannot be built")
    args = parser.parse_args(argv)
    paths = []
    for fmu in build_all(args.dest, args.names or None, tuple(args.fmi)):
        paths += [fmu] + ([] if args.no_references else crosscheck.write(fmu))
    try:
        natives = native.build_all(args.dest, args.names or None, tuple(args.fmi), False if args.host_only else None)
    except toolchain.NoCompiler as missing:
        print(f"native FMUs not built: {missing}", file=sys.stderr)
        natives = []
    for fmu in natives:
        paths += [fmu] + ([] if args.no_references else crosscheck.write(fmu))
    for packaged in system.systems():
        for variant in (None, args.dest) if natives else (None,):  # the Python system, then its native variant
            if all(fmu.exists() for fmu in system.component_fmus(packaged, args.dest, variant).values()):
                paths.append(system.write_ssp(packaged, args.dest, variant))
            else:
                print(f"{system.ssp_path(packaged, args.dest, variant)} not written: not all its FMUs were built",
                      file=sys.stderr)
    here = Path.cwd()
    for path in paths:
        print(path.relative_to(here) if path.is_relative_to(here) else path)
    if args.native and not natives:
        sys.exit(1)
