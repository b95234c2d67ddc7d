"""Cost of one structural analysis of the CriticalSpeeds model (what a tunable change costs).

``python -m benchmarks.critical_speeds_analysis``: ``driveline.rotor.model.analyse`` (three
critical speeds and the finite-element check, Campbell table from 41 speeds, order resonances
1, 2, 3 up to twice ``omega_max = 1500 rad/s``) and its parts, for the one-piece tube of the
FMU's defaults, the shipped two-piece example, and the same tube cut into 20 equal segments with
a joint mass at every node (the issue's targets: 50 ms and 0.5 s). A change of ``orders`` costs
the resonances alone, one of ``omega_max`` the whirl table and the resonances. CPU time of the
process, best of five runs after a warm-up.
"""

from __future__ import annotations

import os
import time

from benchmarks.timing import best_of, machine
from driveline.rotor import (
    Bearing,
    ConcentratedMass,
    Driveline,
    ShaftSegment,
    example_path,
    load_driveline,
    one_piece_shaft,
)
from driveline.rotor.model import analyse, analyse_structure, resonances, whirl_table

ORDERS, OMEGA_MAX = (1, 2, 3), 1500.0


def one_piece() -> Driveline:
    return one_piece_shaft(1.4, 0.0762, 0.0729, 2.1e11, 7850.0, 2.5, 0.004, 0.002, 1e7)


def twenty_segments() -> Driveline:
    segments = [ShaftSegment(1.4 / 20, 0.0762, 0.0729)] * 20
    masses = [ConcentratedMass(node, 0.1, 0.0002, 0.0001) for node in range(21)]
    return Driveline(segments, masses, [Bearing(0, 1e7), Bearing(20, 1e7)])


CASES = {
    "one-piece tube": (one_piece, 0.05),
    "two-piece example": (lambda: load_driveline(example_path("two_piece_propshaft")), None),
    "20 segments": (twenty_segments, 0.5),
}


def main() -> None:
    print(f"One structural analysis of CriticalSpeeds (CPU time [s]); {machine()}, "
          f"load average {os.getloadavg()[0]:.1f}")
    print("| driveline | structure | whirl table | resonances | analysis | target |")
    print("|---|---|---|---|---|---|")
    for name, (build, target) in CASES.items():
        driveline = build()
        structure = analyse_structure(driveline)
        parts = (lambda: analyse_structure(driveline), lambda: whirl_table(structure, OMEGA_MAX),
                 lambda: resonances(driveline, ORDERS, OMEGA_MAX), lambda: analyse(driveline, ORDERS, OMEGA_MAX))
        seconds = []
        for part in parts:
            part()  # warm-up
            seconds.append(best_of(part, repeats=5, clock=time.process_time))
        print(f"| {name} | " + " | ".join(f"{s:.3f}" for s in seconds) + f" | {'' if target is None else target} |")


if __name__ == "__main__":
    main()
