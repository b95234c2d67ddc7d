"""Drive FMUs and SSP systems in third-party co-simulation importers with one small interface.

* ``ecospy`` (Ecos, fmi4c): FMI 1.0, 2.0 and 3.0, single FMUs and SSP archives. Its shared
  libraries need ``libtbb.so.12``; the pip package ``tbb`` installs it into ``<prefix>/lib``,
  which is on no library search path, so :func:`ecos_session` loads it first
  (``RTLD_GLOBAL``) and no ``LD_LIBRARY_PATH`` is needed.
* ``libcosimpy`` (libcosim, FMI Library): FMI 1.0 and 2.0, single FMUs and SSP archives. It
  initialises the FMUs on the first step, so the outputs at the start time cannot be read.

A :class:`Session` addresses variables as ``"instance.variable"``. Both sessions first check the
start values (the SSP's parameter bindings included) with the models' own validation
(:func:`fmu_harness.runs.start_values.check_start_values`) and raise ``StartValuesRefused`` with
the FMU's reason before the engine starts: libcosim aborts the process on a parameter the FMU
refuses at initialisation (docs/hosting.md).
"""

from __future__ import annotations

import ctypes
import sys
from collections.abc import Callable, Iterable, Mapping
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..runs.libcosim_run import NANOSECONDS
from ..runs.start_values import check_start_values, engine_instances


@dataclass
class Session:
    """A started simulation in some importer: set real values, step, read real values."""

    set: Callable[[Mapping[str, float]], None]
    get: Callable[[Iterable[str]], list[float]]
    step: Callable[[], object]  # libcosim: whether the step was taken; Ecos: the new time
    resources: ExitStack = field(default_factory=ExitStack)

    def close(self) -> None:
        self.resources.close()


def record(
    session: Session,
    steps: int,
    step_size: float,
    outputs: list[str],
    inputs: Callable[[float], Mapping[str, float]] = lambda t: {},
) -> np.ndarray:
    """Set ``inputs(t_k)``, step, read ``outputs`` at ``t_k + h``; rows of time and outputs for
    t_1 ... t_steps (t_k = k h)."""
    rows = []
    for k in range(steps):
        session.set(inputs(k * step_size))
        session.step()
        rows.append([(k + 1) * step_size, *session.get(outputs)])
    return np.array(rows)


def _ecos_name(name: str) -> str:
    return name.replace(".", "::", 1)


def _load_tbb() -> None:
    library = Path(sys.prefix) / "lib" / "libtbb.so.12"
    if library.exists():
        ctypes.CDLL(str(library), mode=ctypes.RTLD_GLOBAL)


def ecos_session(step_size: float, fmus: Mapping[str, Path] | None = None, ssp: Path | None = None,
                 start_values: Mapping[str, float] | None = None, parameter_set: str | None = None,
                 checked: bool = True) -> Session:
    """Ecos running the FMUs ``{instance: path}`` (unconnected) or an SSP archive, initialised
    with ``start_values`` and the SSP's ``parameter_set`` (Ecos applies none unless named);
    ``checked=False`` skips the check of the start values (to observe the engine itself)."""
    if checked:
        check_start_values(engine_instances(fmus, ssp, start_values))
    _load_tbb()
    from ecospy import EcosSimulation, EcosSimulationStructure

    resources = ExitStack()
    if ssp is None:
        structure = resources.enter_context(EcosSimulationStructure())
        for instance, path in (fmus or {}).items():
            structure.add_model(instance, str(path))
        simulation = resources.enter_context(EcosSimulation(structure=structure, step_size=step_size))
    else:
        simulation = resources.enter_context(EcosSimulation(ssp_path=str(ssp), step_size=step_size))

    def set_values(values: Mapping[str, float]) -> None:
        for name, value in values.items():
            simulation.set_real(_ecos_name(name), float(value))

    set_values(start_values or {})
    simulation.init(parameter_set=parameter_set)
    return Session(
        set_values,
        lambda names: [simulation.get_real(_ecos_name(name)) for name in names],
        simulation.step,
        resources,
    )


def cosim_session(step_size: float, fmus: Mapping[str, Path] | None = None, ssp: Path | None = None,
                  start_values: Mapping[str, float] | None = None, checked: bool = True) -> Session:
    """libcosim running the FMUs ``{instance: path}`` (unconnected) or an SSP archive, with
    ``start_values`` as initial values; ``checked=False`` as for :func:`ecos_session`."""
    if checked:
        check_start_values(engine_instances(fmus, ssp, start_values))
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    ticks = round(step_size * NANOSECONDS)
    slaves = []
    if ssp is None:
        execution = CosimExecution.from_step_size(step_size=ticks)
        slaves = [CosimLocalSlave(fmu_path=str(path), instance_name=instance) for instance, path in (fmus or {}).items()]
        for slave in slaves:
            execution.add_local_slave(local_slave=slave)
    else:
        execution = CosimExecution.from_ssp_file(ssp_path=str(ssp), step_size=ticks)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer=observer)
    manipulator = CosimManipulator.create_override()
    execution.add_manipulator(manipulator=manipulator)
    references: dict[str, tuple[int, int]] = {}
    for info in execution.slave_infos():
        for variable in execution.slave_variables(slave_index=info.index):
            if variable.type == CosimVariableType.REAL.value:
                references[f"{info.name.decode()}.{variable.name.decode()}"] = (info.index, variable.reference)
    started = False

    def set_values(values: Mapping[str, float]) -> None:
        for name, value in values.items():
            index, reference = references[name]
            if started:
                manipulator.slave_real_values(index, [reference], [float(value)])
            else:
                execution.real_initial_value(index, reference, float(value))

    def step() -> bool:
        """True when libcosim took the step (False: an FMU refused it)."""
        nonlocal started
        taken = execution.step()
        started = True
        return taken

    def get_values(names: Iterable[str]) -> list[float]:
        return [observer.last_real_values(references[name][0], [references[name][1]])[0] for name in names]

    set_values(start_values or {})
    session = Session(set_values, get_values, step)
    session.resources.callback(slaves.clear)  # the slaves live as long as the session
    return session

