"""Time to the first three forward critical speeds of a one-piece propshaft: ours vs ROSS.

``python -m benchmarks.critical_speeds_vs_ross``: the tube propshaft of the tests (OD 76.2 mm,
wall 1.65 mm, 1.4 m, 2.5 kg joints, 1e7 N/m bearings), built and solved by the transfer matrix
method and, on the same rotor, by ROSS's ``run_critical_speed`` (24 Rayleigh-beam elements per
metre, forward lateral modes filtered). Both are timed after a warm-up (ROSS compiles with numba
on first use), best of several runs; the results must agree to 0.5 %.
"""

from __future__ import annotations

import numpy as np

from benchmarks import report
from benchmarks.timing import best_of
from driveline.rotor import Driveline, one_piece_shaft
from tests.support.ross_reference import E, RHO, ross_forward_critical_speeds
from fmu_harness.console import summary

AGREEMENT = 5e-3


def tube() -> Driveline:
    """The tube propshaft with a Rayleigh tube (as measured in docs/benchmarks.md)."""
    return one_piece_shaft(1.4, 0.0762, 0.0762 - 2 * 0.00165, E, RHO, 2.5, 0.004, 0.002, 1e7, shear=False)


def ours() -> np.ndarray:
    return tube().critical_speeds(3)


def ross() -> np.ndarray:
    return ross_forward_critical_speeds(tube())


def main() -> None:
    args = report.parser(summary(__doc__)).parse_args()
    measurement = report.Measurement()
    reference, result = ross(), ours()  # warm-up, and the agreement check
    difference = np.abs(result - reference) / reference
    if difference.max() > AGREEMENT:
        raise SystemExit(f"results disagree: ours {result}, ROSS {reference}")
    ours_time, ross_time = best_of(ours, repeats=20), best_of(ross, repeats=3)
    lines = ["| method | time [ms] | critical speeds [rad/s] |", "|---|---|---|",
             f"| transfer matrix (ours) | {ours_time * 1e3:.1f} | {', '.join(f'{w:.2f}' for w in result)} |",
             f"| ROSS run_critical_speed | {ross_time * 1e3:.0f} | {', '.join(f'{w:.2f}' for w in reference)} |",
             f"\nROSS takes {ross_time / ours_time:.0f} times as long; the largest relative difference is "
             f"{difference.max():.1e}."]
    report.publish("benchmark-critical-speeds-vs-ross", measurement.stamp(
        "wall time after a warm-up, ours best of 20, ROSS best of 3"), "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
