"""Cost of the native FMUs' exact derivatives: one directional derivative and one Jacobian, against the
Jacobian a host forms by forward differences without them.

``python -m benchmarks.derivative_cost [NAME ...]``: for each model whose C port gives the ``jacobian`` hook
(or those named) and each FMI version, builds the native FMU and runs it through fmpy's low-level API in continuous-time mode (the
instance of :mod:`benchmarks.model_exchange_cost`). One directional derivative: every unknown (Real
outputs and state derivatives) for one seed on every known (Real inputs and states), one call; one exact
Jacobian: a directional derivative per known with a unit seed (FMI 3.0 also: an adjoint derivative per
unknown); one Jacobian by forward differences: the evaluation at the point and one per state and input
moved, as in :mod:`benchmarks.model_exchange_cost`. CPU time of this process, best of alternating rounds;
FMPy's call overhead is part of every number.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from benchmarks import report
from benchmarks.model_exchange_cost import ROUNDS, ContinuousTime, best_microseconds, instances
from driveline.catalog import MODELS
from fmu_harness.packaging import native
from fmu_harness.console import summary

CALLS = 1000


def costs(model: ContinuousTime, name: str, fmi: str) -> list[float]:
    """Microseconds of one directional derivative, one Jacobian from them, from adjoint ones (FMI 3.0;
    NaN otherwise) and by forward differences."""
    rows, knowns = native.jacobian_references(MODELS[name].spec, fmi)
    seed, units, row_units = [1.0] * len(knowns), np.eye(len(knowns)).tolist(), np.eye(len(rows)).tolist()
    directional = model.fmu.getDirectionalDerivative

    def by_columns() -> None:
        for unit in units:
            directional(rows, knowns, unit)

    def by_rows() -> None:
        for unit in row_units:
            model.fmu.getAdjointDerivative(rows, knowns, unit, len(knowns))

    return [best_microseconds(lambda: directional(rows, knowns, seed), CALLS), best_microseconds(by_columns, CALLS),
            best_microseconds(by_rows, CALLS) if fmi == "3" else float("nan"), best_microseconds(model.jacobian, CALLS)]


def main() -> None:
    providing = [name for name in native.native_models() if native.provides_derivatives(name)]
    parser = report.parser(summary(__doc__))
    parser.add_argument("names", nargs="*", metavar="NAME",
                        help=f"the models to measure (default: all that give the hook: {', '.join(providing)})")
    args = parser.parse_args()
    unknown = [name for name in args.names if name not in providing]
    if unknown:
        parser.error(f"{', '.join(unknown)}: not a model whose native FMU gives derivatives ({', '.join(providing)})")
    if args.names and args.update_docs:
        parser.error("--update-docs writes the table of every model: name none with it")
    measurement = report.Measurement()
    lines = ["| FMU | FMI | unknowns x knowns | one directional derivative µs | one Jacobian, directional µs "
             "| one Jacobian, adjoint µs | one Jacobian, forward differences µs |", "|---|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as folder:
        for name, fmi, model in instances(Path(folder), args.names or providing):
            outputs, columns = native.jacobian_layout(MODELS[name].spec)
            one, directional, adjoint, differences = costs(model, name, fmi)
            shown = "" if np.isnan(adjoint) else f"{adjoint:.2f}"
            lines.append(f"| {name} | {fmi}.0 | {len(outputs) + len(MODELS[name].spec.states)} x {len(columns)} "
                         f"| {one:.2f} | {directional:.2f} | {shown} | {differences:.2f} |")
    stamp = measurement.stamp(f"CPU time through fmpy, best of {ROUNDS} rounds of {CALLS} calls")
    report.publish("benchmark-derivative-cost", stamp, "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
