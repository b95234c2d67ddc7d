"""CPU time of one 4 s vehicle launch per engine in one run: the package's container, the project's master,
libcosim and the Model Exchange engine.

Usage: ``python -m benchmarks.launch_cost [--package models/native/VehicleLaunch.ssp] [--stop-time 4]
[--repeat 3] [--update-docs]`` after ``python build_fmu.py``. Not part of the test suite. Each engine runs
the launch in this process as a sweep runs it (:func:`fmu_harness.runs.system_sweep.run_system`: the
outputs of the sweep's metrics recorded at every step, instantiation included; the container built once
beforehand, as the sweep's client does, and extracted once, as each worker does); the container FMU as built
(Jacobi at 1e-4 s) also through ``fmpy.simulate_fmu`` recording vehicle speed, halfshaft torques and pitch
acceleration, at every step and at fmpy's own output interval, and recording what fmpy records by default
(every output): of the shipped FMU (``--package`` with ``.fmu``: the launch's selection) and of the container
with every component output; the Model Exchange engine (DOP853 at rtol
1e-8, rows every 1 ms as ``driveline-fmus system`` writes them) records the sweep's outputs, its integrator
steps and right-hand sides counted. CPU by ``time.process_time`` (every
thread of the process: libcosim's workers count), the least of ``--repeat`` alternating measurements (other
load only adds), Model Exchange measured once. The last column divides by the container's cost at the same
step and order.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from benchmarks import report
from benchmarks.launch_throughput import launch_arguments
from fmpy import extract, read_model_description, simulate_fmu

from fmu_harness.runs.model_exchange_system import run_model_exchange
from fmu_harness.runs.runner import StepRefused
from fmu_harness.runs.system_sweep import SystemInterface, UnpackedSystem, container_of, run_system

GOAL = 0.3
"""CPU seconds per 4 s launch in the shudder map (issue 43)."""
ENGINES = (("container", "jacobi", 1e-4), ("master", "jacobi", 1e-4), ("libcosim", "libcosim", 1e-4),
           ("container", "gauss-seidel", 2e-4), ("master", "gauss-seidel", 2e-4))
"""(engine, scheme, step): the package's step by Jacobi (the FMU as built), the map's Gauss-Seidel at 2e-4 s."""
MODEL_EXCHANGE_INTERVAL = 1e-3
"""The Model Exchange engine's rows: ``driveline-fmus system``'s default output interval."""
FMPY_OUTPUTS = ("drive.v_x", "drive.T_load_left", "drive.T_load_right", "mounts.pitch_ddot")
FMPY_INTERVALS = (1e-4, None)
"""fmpy's output interval, its communication step: every container step, and fmpy's own choice (None: the
FMU's step doubled until at most 1000 rows)."""
FMPY_RUNS = tuple((outputs, interval, shipped) for outputs, shipped in ((FMPY_OUTPUTS, False), (None, True))
                  for interval in FMPY_INTERVALS) + ((None, 1e-4, False),)
"""fmpy's runs: (outputs recorded, None: fmpy's default, every output; output interval; the shipped FMU, else
the container with every component output)."""


def main() -> None:
    args = launch_arguments(__doc__)
    measurement = report.Measurement()
    interface = SystemInterface.of(args.package)
    with tempfile.TemporaryDirectory(prefix="launch-cost-") as folder:
        scratch = Path(folder)
        data = args.package.read_bytes()
        unpacked = {("master", None): UnpackedSystem.write(data, scratch / "package", interface)}
        for engine, scheme, step in ENGINES:
            if engine == "container":
                unpacked[engine, scheme] = UnpackedSystem.write(data, scratch / scheme, interface,
                                                                container_of(args.package, interface, step, scheme))

        def cpu(engine: str, scheme: str, step: float) -> float:
            start = time.process_time()
            run_system(interface, unpacked.get((engine, scheme), unpacked["master", None]), {}, args.stop_time,
                       step, scheme, scratch)
            return time.process_time() - start

        _, every_output, _ = unpacked["container", "jacobi"].container
        shipped = extract(str(args.package.with_suffix(".fmu")), unzipdir=scratch / "shipped")
        columns = {True: len(read_model_description(shipped).outputs),
                   False: len(read_model_description(every_output).outputs)}

        def fmpy_cpu(outputs: tuple[str, ...] | None, interval: float | None, as_shipped: bool) -> float:
            start = time.process_time()
            simulate_fmu(shipped if as_shipped else every_output, stop_time=args.stop_time, output_interval=interval,
                         output=outputs and list(outputs))
            return time.process_time() - start

        measured = [[cpu(*engine) for engine in ENGINES] + [fmpy_cpu(*run) for run in FMPY_RUNS]
                    for _ in range(args.repeat)]
        least = list(map(min, zip(*measured)))
        best = dict(zip(ENGINES, least))
        through_fmpy = dict(zip(FMPY_RUNS, least[len(ENGINES):]))
        counts: dict[str, int] = {}
        package = unpacked["master", None]
        start = time.process_time()
        try:
            run_model_exchange(package.fmus, {c.name: c.parameters for c in interface.package.components},
                               interface.package.connections, args.stop_time, MODEL_EXCHANGE_INTERVAL,
                               interface.recorded(), scratch / "model_exchange", counts=counts)
            refused = None
        except StepRefused as error:
            refused = f"refused at t = {error.time:.4g} s ({error.status}: {error.call.split(' of ')[0]})"
        model_exchange = time.process_time() - start
    lines = ["| engine | scheme | step [s] | CPU per launch [s] | CPU per step [us] | of the map's goal | "
             "against the container |", "|---|---|---|---|---|---|---|"]
    for (engine, scheme, step), seconds in best.items():
        steps = round(args.stop_time / step)
        container = best["container", scheme if scheme != "libcosim" else "jacobi", step]
        lines.append(f"| {engine} | {scheme} | {step:g} | {seconds:.2f} | {1e6 * seconds / steps:.1f} | "
                     f"{seconds / (GOAL * args.stop_time / 4.0):.2f} | {seconds / container:.1f} |")
    steps = round(args.stop_time / 1e-4)
    for (outputs, interval, as_shipped), seconds in through_fmpy.items():
        rows = f"rows every {interval:g} s" if interval else "fmpy's output interval"
        recorded = (f"{len(outputs)} outputs named" if outputs else
                    f"fmpy's default: {columns[as_shipped]} outputs of the "
                    f"{'FMU as shipped' if as_shipped else 'container of every output'}")
        lines.append(f"| container in fmpy.simulate_fmu, {recorded}, {rows} | jacobi | 0.0001 | {seconds:.2f} | "
                     f"{1e6 * seconds / steps:.1f} | {seconds / (GOAL * args.stop_time / 4.0):.2f} | "
                     f"{seconds / best['container', 'jacobi', 1e-4]:.1f} |")
    if refused:
        lines.append(f"| Model Exchange: {refused} | DOP853, rtol 1e-08 | rows every {MODEL_EXCHANGE_INTERVAL:g} | "
                     f"{model_exchange:.1f} until then | | | |")
    else:
        lines.append(f"| Model Exchange: {counts['steps']} steps, {counts['right-hand sides']} right-hand sides | "
                     f"DOP853, rtol 1e-08 | rows every {MODEL_EXCHANGE_INTERVAL:g} | {model_exchange:.1f} | "
                     f"{1e6 * model_exchange / counts['right-hand sides']:.0f} per right-hand side | "
                     f"{model_exchange / (GOAL * args.stop_time / 4.0):.0f} | "
                     f"{model_exchange / best['container', 'jacobi', 1e-4]:.0f} |")
    report.publish("benchmark-launch-cost", measurement.stamp(
        f"{args.stop_time:g} s launches of {args.package.stem} (native FMUs), one process, CPU by "
        f"time.process_time, least of {args.repeat} alternating measurements (Model Exchange: one)"),
        "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
