"""The CPU time of one unit of the CriticalSpeeds work budget (driveline/rotor/budget.py), in each core.

``python -m benchmarks.unit_rates [NATIVE_FMU]`` (default ``models/native/CriticalSpeeds.fmu``, built by
``python build_fmu.py --fmi 2 CriticalSpeeds``): the analysis of ``BUDGET_LAYOUT``
(fmu_harness/checks/analysis_work.py), which spends the whole budget before its refusal, in the Python
core and the native FMU; CPU seconds divided by the budget's units, best of the rounds. With
``--update-docs`` it also writes the rates with their stamp into ``driveline/rotor/unit_rates.py``, from
which the refusal's "about N s" and the docs follow.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from benchmarks import report
from driveline.rotor import budget, model
from driveline.rotor.model import parse_orders
from fmu_harness.checks.analysis_work import BUDGET_LAYOUT, BUDGET_PARAMETERS, native_analysis
from fmu_harness.console import summary

RATES = Path(__file__).resolve().parents[1] / "driveline" / "rotor" / "unit_rates.py"
ROUNDS = 3


def python_seconds(path: Path) -> float:
    """CPU seconds of the Python core's analysis of ``path`` until its refusal."""
    driveline = model.build_driveline(str(path), {})
    started = time.process_time()
    try:
        model.analyse(driveline, parse_orders(BUDGET_PARAMETERS["orders"]), BUDGET_PARAMETERS["omega_in_max"])
    except budget.BudgetSpent:
        return time.process_time() - started
    raise RuntimeError("the budget layout was analysed within its budget: it no longer measures a unit")


def native_seconds(fmu: Path, path: Path) -> float:
    """CPU seconds of the native FMU's analysis of ``path`` until its refusal."""
    result = native_analysis(str(fmu), str(path), BUDGET_PARAMETERS)
    if "work budget" not in " ".join(result["message"]):
        raise RuntimeError(f"the native FMU did not spend its budget: {result['status']}")
    return result["seconds"]


def rates_module(stamp: str, native: float, python: float) -> str:
    """The text of ``driveline/rotor/unit_rates.py`` with these rates (two significant digits)."""
    parts = stamp.removeprefix("Measured ").rstrip(".").split("; ")
    when = "\n            ".join(repr(part + ("; " if i < len(parts) - 1 else "")) for i, part in enumerate(parts))
    return f'''"""The measured CPU time of one work-budget unit (:mod:`.budget`), in each core: written by
``python -m benchmarks.unit_rates --update-docs`` (the analysis of ``BUDGET_LAYOUT``, which spends the
whole budget, divided by its units), not by hand. The refusal's "about N s" and the docs follow from it.
"""

#: When, where and under what load the rates below were measured.
MEASURED = ({when})
#: Native CPU seconds of one unit.
NATIVE_SECONDS_PER_UNIT = {float(f"{native:.2g}")!r}
#: Python core CPU seconds of one unit.
PYTHON_SECONDS_PER_UNIT = {float(f"{python:.2g}")!r}
'''


def main() -> None:
    args = report.critical_speeds_parser(summary(__doc__)).parse_args()
    measurement = report.Measurement()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "budget_layout.toml"
        path.write_text(BUDGET_LAYOUT)
        native = min(native_seconds(args.fmu, path) for _ in range(ROUNDS)) / budget.UNITS
        python = min(python_seconds(path) for _ in range(ROUNDS)) / budget.UNITS
    stamp = measurement.stamp(f"CPU time of the budget layout's analysis over {budget.UNITS} units, "
                              f"best of {ROUNDS} rounds")
    table = ("| core | ns per unit | whole budget, s | limit, s |\n|---|---|---|---|\n"
             f"| native | {native * 1e9:.0f} | {native * budget.UNITS:.1f} | 5 |\n"
             f"| Python | {python * 1e9:.0f} | {python * budget.UNITS:.1f} | 30 |\n\n"
             f"An analysis that would exceed the budget is refused in both families with\n\n"
             f"    driveline: {budget.refusal('Campbell table', native * budget.UNITS)}")
    report.publish("benchmark-unit-rates", stamp, table, args.update_docs)
    if args.update_docs:
        RATES.write_text(rates_module(stamp, native, python))


if __name__ == "__main__":
    main()
