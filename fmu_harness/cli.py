"""``driveline-fmus COMMAND [ARGS]``: the everyday commands in one console script.

``driveline-fmus build`` builds the FMUs, ``run`` runs the main job, ``sweep`` a parameter sweep
on Dask, ``map`` the launch shudder map, ``interop`` the importer matrix, ``check`` the start values
of an SSP package or FMU before another engine runs it, ``system`` runs an SSP package, ``container`` makes
one FMU of it; ``driveline-fmus COMMAND --help`` lists a
command's options. Each command is the ``main`` of the module named in :data:`COMMANDS`.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from .console import CommandParser

COMMANDS = {
    "build": ("fmu_harness.build_command", "build the FMUs (FMI 2.0 and 3.0), their reference results and the SSP system"),
    "run": ("fmu_harness.main", "the main job: simulate the FMUs, write CSV files and figures"),
    "sweep": ("fmu_harness.runs.sweep", "a parameter sweep of one FMU or an SSP system on Dask"),
    "map": ("fmu_harness.shudder_map", "the launch shudder map: vehicle launches over bend, torque, friction and phase on Dask, and its figure"),
    "interop": ("fmu_harness.checks.interop", "every FMU in every importer: the interoperability matrix"),
    "check": ("fmu_harness.runs.start_values", "the start values of an SSP package or an FMU, as the FMUs check them"),
    "system": ("fmu_harness.system_command", "run an SSP package, every output of every component to CSV"),
    "container": ("fmu_harness.container_command", "an SSP package as one co-simulation FMU for any host"),
}


def main(argv: list[str] | None = None) -> None:
    parser = CommandParser(
        prog="driveline-fmus",
        description="Build, run, sweep and check the driveline FMUs.",
        epilog="commands:\n" + "".join(f"  {name:<9} {text}\n" for name, (_, text) in COMMANDS.items())
        + "\n'driveline-fmus COMMAND --help' lists the command's options.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("command", choices=COMMANDS, metavar="COMMAND", help=", ".join(COMMANDS))
    parser.add_argument("arguments", nargs=argparse.REMAINDER, help="the command's arguments")
    args = parser.parse_args(argv)
    sys.argv[0] = f"{parser.prog} {args.command}"  # the command's usage line names it
    importlib.import_module(COMMANDS[args.command][0]).main(args.arguments)


if __name__ == "__main__":
    main()
