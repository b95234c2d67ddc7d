"""Build every FMU of the project: the Python FMUs, FMI 2.0 into ``models/`` and FMI 3.0 into
``models/fmi3/``, and the native (C) FMUs into ``models/native/`` and ``models/native/fmi3/``.

Usage: ``driveline-fmus build [--dest models] [--fmi 2 3] [--no-references] [--all-platforms] [--native]
[NAME ...]`` (or ``python build_fmu.py ...``). Every model of ``driveline.catalog.MODELS`` becomes one
Python FMU per FMI version (:mod:`.fmu`). The native (C) FMUs of the models with a C port go to
``native/`` and ``native/fmi3/`` below ``--dest`` (:mod:`.native`), with a binary for this machine
(``--all-platforms``: for the five platforms, with ziglang; the release set, several minutes more
the first time, while zig builds each target's C library into its cache). Without a C compiler
the build says what to install in one line and builds the rest; it fails only with ``--native``.
Then the FMI Cross-Check reference results are written next to each FMU, Python and native
(:mod:`fmu_harness.checks.crosscheck`), and, once their FMI 2.0 FMUs are there, the systems' SSP
packages (``Driveline.ssp``, ``VehicleLaunch.ssp``) with the Python FMUs and under ``native/`` with the
native ones (:mod:`fmu_harness.runs.system`), and each native package as one co-simulation FMU next to it
(``native/VehicleLaunch.fmu``, FMI 3.0 in ``native/fmi3/``: :mod:`fmu_harness.runs.container`). Each stage
shows its progress on standard error.
"""

from __future__ import annotations

import difflib
import sys
from pathlib import Path

from driveline.catalog import MODELS

from .checks import crosscheck
from .console import CommandParser, Progress
from .packaging import native, toolchain
from .packaging.fmu import FMI_VERSIONS, build
from .runs import system


def unknown_model(name: str) -> str:
    """The one-line refusal of a name that is no catalog model, with the nearest one."""
    near = difflib.get_close_matches(name, MODELS, n=1, cutoff=0.0)
    return f"no model {name!r} (did you mean {near[0]}? the models: {', '.join(MODELS)})"


def _containers(packaged: system.System, dest: Path, fmi: list[str], natives: list[Path]) -> list[Path]:
    """The native package of ``packaged`` as one FMU per FMI version built, where all its FMUs are native."""
    written = []
    for version in fmi if natives else ():
        fmus = [native.fmu_path(dest, c.model, version) for c in packaged.components]
        if system.ssp_path(packaged, dest, dest).exists() and all(fmu in natives for fmu in fmus):
            written.append(system.write_container(packaged, dest, version))
    return written


def main(argv: list[str] | None = None, prog: str | None = None, dest: Path = Path("models")) -> None:
    parser = CommandParser(prog=prog, description=__doc__.split("\n\n")[0].replace("``", ""))
    parser.add_argument("names", nargs="*", help=f"models to build (default: all of {', '.join(MODELS)})")
    parser.add_argument("--dest", type=Path, default=dest, help=f"folder of the FMI 2.0 FMUs (default {dest})")
    parser.add_argument("--fmi", nargs="+", choices=sorted(FMI_VERSIONS), default=sorted(FMI_VERSIONS),
                        help="FMI versions to build (default: both)")
    parser.add_argument("--no-references", action="store_true", help="skip the cross-check reference results")
    platforms = parser.add_mutually_exclusive_group()
    platforms.add_argument("--all-platforms", action="store_true",
                           help="native binaries for the five platforms (needs ziglang; default: this machine's)")
    platforms.add_argument("--host-only", action="store_true", help="native binaries for this machine (the default)")
    parser.add_argument("--native", action="store_true", help="fail if the native FMUs cannot be built")
    args = parser.parse_args(argv)
    for name in args.names:
        if name not in MODELS:
            parser.error(unknown_model(name))
    names = list(dict.fromkeys(args.names)) or list(MODELS)
    fmi = sorted(set(args.fmi))
    paths = []
    with Progress("Python FMUs", len(fmi) * len(names)) as shown:
        for version in fmi:
            for name in names:
                paths.append(build(name, args.dest, version))
                shown.advance(f"{name} FMI {FMI_VERSIONS[version].version}")
    try:
        natives = native.build_all(args.dest, names, tuple(fmi), args.all_platforms, show_progress=True)
    except toolchain.NoCompiler as missing:
        print(f"native FMUs not built: {missing}", file=sys.stderr)
        natives = []
    paths += natives
    if not args.no_references:
        fmus = list(paths)
        with Progress("reference results", len(fmus)) as shown:
            for fmu in fmus:
                paths += crosscheck.write(fmu)
                shown.advance(fmu.name)
    for packaged in system.systems():
        for variant in (None, args.dest) if natives else (None,):  # the Python system, then its native variant
            if all(fmu.exists() for fmu in system.component_fmus(packaged, args.dest, variant).values()):
                paths.append(system.write_ssp(packaged, args.dest, variant))
            else:
                print(f"{system.ssp_path(packaged, args.dest, variant)} not written: not all its FMUs were built",
                      file=sys.stderr)
        paths += _containers(packaged, args.dest, fmi, natives)
    here = Path.cwd()
    for path in paths:
        print(path.relative_to(here) if path.is_relative_to(here) else path)
    if args.native and not natives:
        sys.exit(1)
