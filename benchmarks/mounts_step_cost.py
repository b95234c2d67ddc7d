"""Cost of a native PowertrainMounts step from a C host, what the step does apart from its inputs and outputs.

``python -m benchmarks.mounts_step_cost``: builds the native PowertrainMounts FMU (FMI 2.0 and 3.0)
and times it with ``benchmarks/native_step_timer.c`` (as :mod:`benchmarks.native_step_cost`: CPU
time, best of its rounds, the default step of 1 ms, the default layout's three mounts, the inputs at
their start values) in four loops: ``doStep`` alone; with one batched set of the Real inputs before it
(the 19 loads and their 19 rates); with one batched get of the outputs a host wiring the powertrain
reads after it (the six displacements and the three mounts' forces: 15); with the get of every Real
output (99) instead. The target (issue 28): at most 1 µs for the step with its inputs set and the
outputs a host reads.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from benchmarks import report
from benchmarks.native_step_cost import C_ROUNDS, C_STEPS, c_host_cost, compile_timer
from driveline.catalog import MODELS
from driveline.mounts.layout import load_layout, shipped_layout
from driveline.mounts.rigid_body import COORDINATES
from driveline.mounts.spec import AXES, SHARED_LAYOUT
from fmu_harness.packaging import native
from fmu_harness.console import summary

NAME = "PowertrainMounts"
TARGET_NS = 1000.0


def loops() -> list[tuple[str, list[str], list[str] | None]]:
    """(what is timed, the inputs set, the outputs read; None: every Real output) of each loop."""
    spec = MODELS[NAME].spec
    inputs = [v.name for v in spec.of("input") if v.type == "Real"]
    mounts = len(load_layout(shipped_layout(SHARED_LAYOUT)).mounts)
    read = [*COORDINATES, *(f"F_{axis}_mount{i}" for i in range(1, mounts + 1) for axis in AXES)]
    every = [v.name for v in spec.of("output") if v.type == "Real"]
    return [("doStep alone", [], []),
            (f"set {len(inputs)} inputs, doStep", inputs, []),
            (f"set {len(inputs)} inputs, doStep, get {len(read)} outputs (displacements, mount forces)", inputs, read),
            (f"set {len(inputs)} inputs, doStep, get all {len(every)} Real outputs", inputs, None)]


def main() -> None:
    args = report.parser(summary(__doc__)).parse_args()
    measurement = report.Measurement()
    lines = ["| FMI | loop | ns per step |", "|---|---|---|"]
    typical = []
    with tempfile.TemporaryDirectory() as folder:
        dest = Path(folder)
        timer = compile_timer(dest)
        for fmi in ("2", "3"):
            fmu = native.build(NAME, dest, fmi, release=False)
            for k, (what, inputs, outputs) in enumerate(loops()):
                cost = c_host_cost(timer, fmu, fmi, dest / f"c_{fmi}_{k}", {}, inputs, outputs)
                typical += [cost] if k == 2 else []
                lines.append(f"| {fmi}.0 | {what} | {cost:.0f} |")
    lines.append(f"\nWith its inputs set and the displacements and mount forces read a step costs "
                 f"{min(typical):.0f} to {max(typical):.0f} ns (target: at most {TARGET_NS:.0f} ns).")
    report.publish("benchmark-mounts-step-cost", measurement.stamp(
        f"CPU time from C, best of {C_ROUNDS} rounds of {C_STEPS} steps"), "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
