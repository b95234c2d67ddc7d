"""The work fuzzer's long run: many random CriticalSpeeds inputs, no analysis beyond its budget.

``python -m benchmarks.work_fuzzer [--cases N] [--seed S]`` (default 200 cases, seed 1): the cases of
:mod:`fmu_harness.checks.work_fuzzer` (the issue's layout first, then random layouts of extreme
materials with ``omega_in_max`` near the estimate's edge and two tunable changes), each in a process of its
own under a limit of CPU time and address space, on the Python FMU ``models/CriticalSpeeds.fmu`` and the
native one ``models/native/CriticalSpeeds.fmu`` (``python build_fmu.py --fmi 2 CriticalSpeeds``); prints the
table per family and exits 1 if any analysis exceeds its budget (Python 30 s and 2 GB, native 5 s and
500 MB), a process does not end, or the families' verdicts on a case differ.
"""

from __future__ import annotations

import sys
from pathlib import Path

from benchmarks import report
from fmu_harness.checks.work_fuzzer import exit_on_findings, fuzz, summary
from fmu_harness.console import summary

FMUS = {"python": Path("models/CriticalSpeeds.fmu"), "native": Path("models/native/CriticalSpeeds.fmu")}


def main() -> None:
    arguments = report.parser(summary(__doc__))
    arguments.add_argument("--cases", type=int, default=200, help="cases per family (default 200)")
    arguments.add_argument("--seed", type=int, default=1, help="seed of the random cases (default 1)")
    args = arguments.parse_args()
    fmus = {family: path for family, path in FMUS.items() if path.exists()}
    if not fmus:
        arguments.exit(2, "no CriticalSpeeds FMU in models/: python build_fmu.py --fmi 2 CriticalSpeeds\n")
    measurement = report.Measurement()
    results = fuzz(fmus, args.cases, args.seed,
                   lambda done, total: print(f"case {done}/{total}", file=sys.stderr, flush=True))
    note = f"CPU seconds of each analysis, {args.cases} cases from seed {args.seed}"
    report.publish("benchmark-work-fuzzer", measurement.stamp(note), summary(results), args.update_docs)
    exit_on_findings(results)


if __name__ == "__main__":
    main()
