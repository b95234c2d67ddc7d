"""The bound on one CriticalSpeeds analysis: every stage on the worst inputs the limits allow.

``python -m benchmarks.analysis_work [NATIVE_FMU]`` (default ``models/native/CriticalSpeeds.fmu``, built by
``python build_fmu.py``): the cases of :mod:`fmu_harness.checks.analysis_work`, each in a process of its own
under a limit of CPU time and address space, the Python analysis stage by stage and the native FMU's
whole analysis; prints the table and exits 1 if an accepted case exceeds its budget (Python 30 s and
2 GB, native 5 s and 500 MB) or the issue's layout is accepted.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from benchmarks import report
from fmu_harness.checks.analysis_work import NATIVE_BUDGET, PYTHON_BUDGET, measure, table
from fmu_harness.console import summary


def over_budget(results: dict[str, dict]) -> list[str]:
    """What exceeds its budget, or is accepted though it should be refused."""
    found = []
    for name, result in results.items():
        python, native = result["python"], result.get("native")
        if "failed" in python or (native is not None and "failed" in native):
            found.append(f"{name}: {python.get('failed') or native.get('failed')}")
            continue
        if name.startswith("issue") != (python["refusal"] is not None):
            found.append(f"{name}: refused {python['refusal'] is not None}")
        for stage, (seconds, peak) in python["stages"].items():
            if seconds > PYTHON_BUDGET[0] or peak > PYTHON_BUDGET[1]:
                found.append(f"{name}, {stage}: Python {seconds:.3g} s, {peak / 2**20:.0f} MB")
        if native is not None and (native["seconds"] > NATIVE_BUDGET[0] or native["peak"] > NATIVE_BUDGET[1]):
            found.append(f"{name}: native {native['seconds']:.3g} s, {native['peak'] / 2**20:.0f} MB")
    return found


def main() -> None:
    args = report.critical_speeds_parser(summary(__doc__)).parse_args()
    measurement = report.Measurement()
    with tempfile.TemporaryDirectory() as folder:
        results = measure(Path(folder), args.fmu if args.fmu.exists() else None)
    report.publish("benchmark-analysis-work", measurement.stamp("CPU seconds of each process"), table(results),
                   args.update_docs)
    over = over_budget(results)
    for line in over:
        print(f"over budget: {line}")
    sys.exit(1 if over else 0)


if __name__ == "__main__":
    main()
