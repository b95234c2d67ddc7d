"""Cost of one structural analysis of the CriticalSpeeds model (what a tunable change costs).

``python -m benchmarks.critical_speeds_analysis``: ``driveline.rotor.model.analyse`` (three
critical speeds, Campbell table of 41 speeds, order resonances 1, 2, 3 up to twice
``omega_max = 1500 rad/s``) for the one-piece tube of the FMU's defaults, the shipped two-piece
example, and the same tube cut into 20 equal segments with a joint mass at every node (the
issue's targets: 50 ms and 0.5 s). Best of three runs after a warm-up.
"""

from __future__ import annotations

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
from driveline.rotor.model import analyse

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
    print(f"One structural analysis of CriticalSpeeds; {machine()}")
    print("| driveline | analysis [s] | target [s] |")
    print("|---|---|---|")
    for name, (build, target) in CASES.items():
        driveline = build()
        analyse(driveline, ORDERS, OMEGA_MAX)  # warm-up
        seconds = best_of(lambda: analyse(driveline, ORDERS, OMEGA_MAX), repeats=3)
        print(f"| {name} | {seconds:.3f} | {'' if target is None else target} |")


if __name__ == "__main__":
    main()
