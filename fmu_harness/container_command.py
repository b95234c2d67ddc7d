"""Build one co-simulation FMU from an SSP package: its components, connections and parameter set inside FMU
Manipulation Toolbox's container, for any host that imports FMUs.

``driveline-fmus container PACKAGE.ssp [--step 1e-4] [--fmi 2|3] [--gauss-seidel] [--out NAME.fmu]`` writes
``NAME.fmu`` (default: the package's name next to it). Every parameter and unconnected input of a component
becomes the FMU's ``component.variable`` with the package's binding as its start value, every output an
output (:mod:`fmu_harness.runs.container`). The container steps its components every ``--step`` by Jacobi, as
``driveline-fmus system``'s default master, or with ``--gauss-seidel`` one after the other in the package's
order. A package with Python FMUs, a binding or connection the container cannot carry, or a step above a
``VehicleDriveline``'s limit for a Jacobi coupling is refused in one line.
"""

from __future__ import annotations

import math
import sys
import tempfile
import zipfile
from pathlib import Path

from .console import CommandParser, summary
from .runs import container, ssp_package
from .runs.ssp_package import PackageError

DEFAULT_STEP = 1e-3  # as driveline-fmus system's


def main(argv: list[str] | None = None) -> None:
    parser = CommandParser(description=summary(__doc__))
    parser.add_argument("package", type=Path, help="the SSP package (.ssp)")
    parser.add_argument("--step", type=float, default=DEFAULT_STEP,
                        help=f"the container's communication step between its components [s] (default {DEFAULT_STEP:g})")
    parser.add_argument("--fmi", choices=("2", "3"), default="2", help="FMI version of the container (default 2)")
    parser.add_argument("--gauss-seidel", action="store_true",
                        help="step the components one after the other in the package's order (default: Jacobi)")
    parser.add_argument("--out", type=Path, help="the FMU to write (default: the package's name with .fmu)")
    args = parser.parse_args(argv)
    if not (math.isfinite(args.step) and args.step > 0.0):
        parser.error(f"--step {args.step!r}: need a finite step above 0")
    out = args.out or args.package.with_suffix(".fmu")
    if not out.parent.is_dir():
        parser.error(f"--out {out}: no folder {out.parent}")
    try:
        system = ssp_package.read(args.package)
        with tempfile.TemporaryDirectory(prefix="driveline-container-") as scratch:
            with zipfile.ZipFile(args.package) as archive:
                archive.extractall(scratch)
            fmus = {c.name: Path(scratch) / c.source for c in system.components}
            if not args.gauss_seidel:
                reason = _step_limit(system, fmus, args.step)
                if reason:
                    parser.error(reason)
            container.build(system, fmus, out, args.step, int(args.fmi), sequential=args.gauss_seidel)
    except PackageError as error:
        parser.error(str(error))
    print(out)


def _step_limit(system: ssp_package.SspSystem, fmus: dict[str, Path], step: float) -> str | None:
    """Why ``step`` is too long for a Jacobi coupling of the package (a ``VehicleDriveline``'s limit)."""
    from .runs.system import step_limit_error

    models = {name: d.get("modelName", "") for name, d in container.model_descriptions(system, fmus).items()}
    return step_limit_error(system, models, step)


if __name__ == "__main__":
    main(sys.argv[1:])
