"""An SSP package run whole in libcosim (``libcosimpy``, the ``interop`` extra): the fixed-step
Jacobi master in C++, with no Python per step, the outputs recorded by libcosim's time-series
observer. The sweeps' ``libcosim`` master (:mod:`fmu_harness.runs.system_sweep`); the importers'
step-by-step sessions are :mod:`fmu_harness.checks.importers`."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .start_values import check_start_values, engine_instances

NANOSECONDS = 1_000_000_000
"""libcosim's time unit per second."""


def cosim_run(package: Path, step_size: float, stop_time: float, outputs: list[str]) -> np.ndarray:
    """The SSP ``package`` run whole in libcosim, its start values checked first (libcosim aborts the
    process on one an FMU refuses, docs/hosting.md): ``stop_time / step_size`` steps in one call, the
    ``outputs`` (``"instance.variable"``, Real) recorded; rows of time and ``outputs`` for t_1 ... t_N.
    A refused step raises RuntimeError."""
    check_start_values(engine_instances(ssp=package))
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    steps = int(round(stop_time / step_size))
    execution = CosimExecution.from_ssp_file(ssp_path=str(package), step_size=round(step_size * NANOSECONDS))
    observer = CosimObserver.create_time_series(buffer_size=steps + 1)
    execution.add_observer(observer=observer)
    references = {f"{info.name.decode()}.{variable.name.decode()}": (info.index, variable.reference)
                  for info in execution.slave_infos() for variable in execution.slave_variables(slave_index=info.index)
                  if variable.type == CosimVariableType.REAL.value}
    for name in outputs:
        observer.start_time_series(*references[name], CosimVariableType.REAL)
    if not execution.step(step_count=steps):
        raise RuntimeError(f"libcosim: a step of {package.name} was refused before {stop_time} s")
    columns = []
    for name in outputs:
        _, numbers, values = observer.time_series_real_samples(*references[name], from_step=1, sample_count=steps)
        if len(values) != steps or list(numbers[:1]) != [1]:
            raise RuntimeError(f"libcosim recorded {len(values)} of {steps} steps of {name}")
        columns.append(values)
    return np.column_stack([(np.arange(steps) + 1.0) * step_size, *columns])
