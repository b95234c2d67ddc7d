"""What each co-simulation engine does with a refusal, measured: the host table of docs/hosting.md.

Usage: ``python -m fmu_harness.checks.engine_refusals [--models models] [--update docs/hosting.md]``
after ``python build_fmu.py``. Runs ``TripodCoupling`` (FMI 2.0, the Python FMU and the native
one) in each engine, each run a process of its own so that an engine aborting is a result:

* **initialisation**: the parameter ``r = -1 m``, which the FMU refuses at
  ``ExitInitializationMode`` (native: Error; Python: OK, every step refused);
* **step**: the input ``beta = 1.2 rad`` (above its maximum) set once initialisation is over (as a
  start value the FMU refuses it at ``ExitInitializationMode`` already), refused at every step
  (Discard): by fmpy, libcosim and Ecos after a first step at the start values (libcosim
  initialises at its first step), by the project's master before its first step.

The engines: fmpy's ``simulate_fmu``, libcosim and Ecos (:mod:`.importers`, their start-value
check switched off to observe the engine itself) and the project's master
(:func:`fmu_harness.runs.runner.simulate`). Prints the table; ``--update`` rewrites the page's
``engine-refusals`` section (``tests/fmu/test_engine_refusals.py`` measures it again and
compares).
"""

from __future__ import annotations

import importlib.metadata
import importlib.util
import signal
import subprocess
import sys
from pathlib import Path

from ..doc_pages.sections import replace_section
from ..packaging import fmu_path, native
from .worker import answer, answer_in, check_parser
from ..console import summary

RESULT = "engine refusal: "
MODEL = "TripodCoupling"
#: The refusals: the start value that causes each.
#: Refusal -> (start values, inputs set once initialisation is over).
REFUSALS = {"initialisation": ({"r": -1.0}, {}), "step": ({}, {"beta": 1.2})}
STEP_SIZE, STEPS = 1e-3, 3
#: Engine name -> (package it needs, what the table calls it; ``{version}``: the package's version).
ENGINES = {
    "fmpy": ("fmpy", "fmpy {version} `simulate_fmu`"),
    "libcosim": ("libcosimpy", "libcosim (libcosimpy {version})"),
    "libcosim checked": ("libcosimpy", "libcosim through `importers.cosim_session` (start values checked)"),
    "Ecos": ("ecospy", "Ecos (ecospy {version})"),
    "Ecos checked": ("ecospy", "Ecos through `importers.ecos_session` (start values checked)"),
    "master": ("fmpy", "the project's master (`runner.simulate`)"),
}
FAMILIES = ("native", "Python")


def observe(engine: str, path: Path, values: dict[str, float], inputs: dict[str, float]) -> str:
    """Run ``STEPS`` steps of the FMU at ``path`` with start values ``values`` and ``inputs`` set
    after initialisation in ``engine`` and say what the engine did (in the worker process)."""
    if engine == "fmpy":
        import numpy as np
        from fmpy import read_model_description, simulate_fmu
        from fmpy.fmi1 import FMICallException

        # fmpy applies its input table at initialisation too: its first row holds the start values
        start = {v.name: float(v.start) for v in read_model_description(str(path)).modelVariables if v.name in inputs}
        signals = np.array([(0.0, *(start[name] for name in inputs)), (STEP_SIZE / 2, *inputs.values())],
                           dtype=[("time", float)] + [(name, float) for name in inputs]) if inputs else None
        try:
            rows = simulate_fmu(str(path), stop_time=STEPS * STEP_SIZE, output_interval=STEP_SIZE,
                                start_values=values, input=signals)
        except FMICallException as error:
            return f"raises FMICallException: {error}"
        return f"stops at the refusal and returns {len(rows)} of {STEPS + 1} rows, no exception"
    if engine == "master":
        from ..runs.runner import FmuInstance, StepRefused

        try:
            with FmuInstance(path) as instance:
                instance.initialize(values, 0.0)
                instance.run(STEPS * STEP_SIZE, STEP_SIZE, inputs)
        except StepRefused as refused:
            return f"raises StepRefused at {refused.call} ({refused.status}) with the FMU's reason"
        return "runs to the end"
    from . import importers

    from ..runs.start_values import StartValuesRefused

    start = {f"m.{name}": value for name, value in values.items()}
    session_of = importers.cosim_session if engine.startswith("libcosim") else importers.ecos_session
    try:
        session = session_of(STEP_SIZE, {"m": path}, start_values=start, checked=engine.endswith("checked"))
        # libcosim initialises the FMUs at its first step and passes a value set before it as a
        # start value (refused at ExitInitializationMode): an input refused during the run is set
        # after a first step at the start values
        answers = [session.step()] if inputs else []
        session.set({f"m.{name}": value for name, value in inputs.items()})
        answers += [session.step() for _ in range(STEPS - len(answers))]
        session.close()
    except StartValuesRefused as refused:
        return f"raises StartValuesRefused before the engine starts: {refused}"
    except Exception as error:  # noqa: BLE001 - what the engine raises is the result
        return f"raises {type(error).__name__}"
    if engine.startswith("libcosim"):
        return f"`step()` returns {', '.join(map(str, answers))}; the process goes on"
    return f"`step()` advances the time to {answers[-1]:g} s; the process goes on"


def measure(engine: str, path: Path, refusal: str) -> str:
    """:func:`observe` in a process of its own: its answer, or how the process ended."""
    command = [sys.executable, "-m", "fmu_harness.checks.engine_refusals", "--worker", engine, str(path), refusal]
    done = subprocess.run(command, capture_output=True, text=True, errors="replace", timeout=300,
                          cwd=Path(__file__).parents[2])
    result = answer_in(done.stdout, RESULT)
    if result is not None:
        return result
    if done.returncode < 0:
        said = "; ".join(" ".join(line.split()) for line in done.stderr.splitlines()
                         if "terminate called" in line or line.strip().startswith("what():"))
        return f"the process dies of {signal.Signals(-done.returncode).name}" + (f' ("{said}")' if said else "")
    return f"the process exits with {done.returncode}: {(done.stderr.strip().splitlines() or [''])[-1]}"


def table(models: Path, natives: Path | None = None) -> str:
    """The markdown table: one row per engine, one column per refusal and family (the Python FMU
    in ``models``, the native one below ``natives``, default ``models``)."""
    paths = {"Python": fmu_path(models, MODEL, "2"), "native": native.fmu_path(natives or models, MODEL, "2")}
    lines = ["| engine | " + " | ".join(f"refused at {refusal}, {family} FMU" for refusal in REFUSALS
                                        for family in FAMILIES) + " |",
             "|---|" + "---|" * len(REFUSALS) * len(FAMILIES)]
    for engine, (package, name) in ENGINES.items():
        if importlib.util.find_spec(package) is None:
            cells = [f"{package} is not installed"] * (len(REFUSALS) * len(FAMILIES))
        else:
            cells = [measure(engine, paths[family], refusal) for refusal in REFUSALS for family in FAMILIES]
        version = importlib.metadata.version(package) if "{version}" in name else ""
        lines.append(f"| {name.format(version=version)} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    args = check_parser(summary(__doc__), "host table", ("ENGINE", "FMU", "REFUSAL")).parse_args(argv)
    if args.worker:
        engine, path, refusal = args.worker
        answer(RESULT, observe(engine, Path(path), *REFUSALS[refusal]))
    text = table(args.models)
    print(text)
    if args.update:
        replace_section(args.update, "engine-refusals", text)


if __name__ == "__main__":
    main()
