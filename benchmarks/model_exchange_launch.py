"""The vehicle launch through the native FMUs' Model Exchange interfaces: CPU time and error per integrator and tolerance.

``python -m benchmarks.model_exchange_launch [--update-docs]`` after ``python build_fmu.py``: 0.1 s of
``models/native/VehicleLaunch.ssp`` in the Model Exchange engine
(:func:`fmu_harness.runs.model_exchange_system.run_model_exchange`), DOP853 and the implicit Radau and
BDF on the exact system Jacobian, each signal's largest difference from the monolithic ODE
(:func:`fmu_harness.runs.launch_reference.reference`, DOP853 at rtol 1e-12) relative to its largest
magnitude, against the project's co-simulation master in Gauss-Seidel order at 1e-4 s. CPU time of
this process (``time.process_time``), the least of alternating rounds.
"""

from __future__ import annotations

import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

from benchmarks import report
from fmu_harness.console import summary
from fmu_harness.runs import launch_reference, ssp_package, system
from fmu_harness.runs.model_exchange_system import run_model_exchange
from fmu_harness.runs.system import run_jacobi

STOP, INTERVAL = 0.1, 2e-3  # s
OPTIONS = (("DOP853", 1e-6), ("DOP853", 1e-8), ("DOP853", 1e-10), ("Radau", 1e-6), ("Radau", 1e-8), ("BDF", 1e-6),
           ("BDF", 1e-8))
CO_SIMULATION_STEP = 1e-4  # s
ROUNDS = 3


def main() -> None:
    args = report.parser(summary(__doc__)).parse_args()
    measurement = report.Measurement()
    package = Path("models/native/VehicleLaunch.ssp")
    if not package.is_file():
        raise SystemExit(f"{package} is missing: run python build_fmu.py first")
    times = np.arange(1, int(round(STOP / INTERVAL)) + 1) * INTERVAL
    monolithic = launch_reference.reference(times, rtol=1e-12)
    found = ssp_package.read(package)
    signals = list(launch_reference.SIGNALS)
    with tempfile.TemporaryDirectory() as scratch:
        with zipfile.ZipFile(package) as archive:
            archive.extractall(Path(scratch) / "package")
        fmus = {c.name: Path(scratch) / "package" / c.source for c in found.components}
        parameters = {c.name: c.parameters for c in found.components}
        parameters["mounts"] = {**parameters["mounts"], "housing_motion": 0}  # the reference's: the housings held

        def exchanged(method: str, rtol: float, round_: int) -> np.ndarray:
            return run_model_exchange(fmus, parameters, found.connections, STOP, INTERVAL, signals,
                                      Path(scratch) / f"{method}{rtol}{round_}", rtol=rtol, method=method)

        def co_simulated(round_: int) -> np.ndarray:
            rows = run_jacobi(fmus, parameters, found.connections, STOP, CO_SIMULATION_STEP, signals,
                              order=system.LAUNCH_ORDER)
            every = int(round(INTERVAL / CO_SIMULATION_STEP))
            return rows[every - 1::every]

        runs = [(f"Model Exchange, {method}", f"rtol {rtol:g}", lambda r, m=method, t=rtol: exchanged(m, t, r))
                for method, rtol in OPTIONS]
        runs.append(("co-simulation, Gauss-Seidel", f"step {CO_SIMULATION_STEP:g} s", co_simulated))
        seconds = [float("inf")] * len(runs)
        results: list[np.ndarray] = [np.empty(0)] * len(runs)
        for round_ in range(ROUNDS):
            for i, (_, _, run) in enumerate(runs):
                start = time.process_time()
                results[i] = run(round_)
                seconds[i] = min(seconds[i], time.process_time() - start)
    lines = ["| engine | setting | CPU s | " + " | ".join(launch_reference.SIGNALS.values()) + " |",
             "|---|---|---|" + "---|" * len(signals)]
    for (engine, setting, _), cpu, rows in zip(runs, seconds, results):
        errors = [np.abs(rows[:, i + 1] - monolithic[name]).max() / np.abs(monolithic[name]).max()
                  for i, name in enumerate(signals)]
        lines.append(f"| {engine} | {setting} | {cpu:.2f} | " + " | ".join(f"{e:.1e}" for e in errors) + " |")
    stamp = measurement.stamp(f"{STOP:g} s of the launch, rows every {INTERVAL:g} s, CPU by time.process_time, least "
                              f"of {ROUNDS} alternating rounds")
    report.publish("benchmark-model-exchange-launch", stamp, "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
