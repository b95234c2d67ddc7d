"""Robustness suite: hostile inputs and misuse of the FMUs, each case in a process of its own with a
time limit, through fmpy (FMI 2.0 and 3.0) and, for a subset, libcosim and Ecos.

Usage: ``python -m fmu_harness.checks.robustness [--models models] [--family python|native] [--slow]
[--workers 2]`` after building the FMUs (``python build_fmu.py``). Prints per family of FMUs
(the Python FMUs, the native ones; both unless ``--family`` names one) and class of case: cases,
crashes (the host process died), hangs (it did not end within the time limit), wrong statuses
and wrong outputs (outputs wrong with status OK), the cases whose defined outcome is a
documented departure from the standard (the Python wrappers', or a host's; docs/robustness.md)
and the cases skipped because an FMU they need was not built (a model without a C port has no
native FMU). The procedures are in :mod:`fmu_harness.checks.robustness_probe`.

The cases are described once: :func:`cases` takes a function ``(model name, FMI version) -> FMU
path`` and the family, which decides the defined outcomes (the native FMUs have none of the
wrappers' departures), so another build of the same models runs the same suite with one more call.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import os
import queue
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from contextlib import ExitStack
from dataclasses import dataclass, replace
from pathlib import Path

from driveline.catalog import MODELS

from .failing_model import FAILURES, FailingModel, build_failing_fmus
from .robustness_probe import (DISTINCT_TEXTS_LEAK, ECOS_IGNORES_DISCARD, FMI2_DISCARD, NO_GUID_CHECK,
                                STATUS_OK_LOGGED, VERDICT, WRAPPER_DEPARTURES)
from ..console import summary

ROOT = Path(__file__).resolve().parents[1]
#: Seconds a case may take; every case needs a few seconds at most (a host process start included).
TIME_LIMIT = 60.0
#: The soak takes about 20 s of CPU per FMI version.
SOAK_TIME_LIMIT = 600.0
NON_FINITE = (math.nan, math.inf, -math.inf)
FmuPath = Callable[[str, str], Path]
#: The Python FMUs (pythonfmu, pythonfmu3) and the native (C) ones.
FAMILIES = ("python", "native")


@dataclass(frozen=True)
class Case:
    """One run: ``procedure(*arguments)`` of :mod:`.robustness_probe` in a fresh process, its
    outcome checked with ``departures`` from the standard (none: the standard's outcome)."""

    kind: str
    name: str
    procedure: str
    arguments: tuple
    fmi: str
    departures: tuple[str, ...] = ()
    time_limit: float = TIME_LIMIT
    family: str = "python"

    @property
    def fmus(self) -> list[Path]:
        """The FMUs the case loads (its arguments that name one)."""
        return [Path(a) for a in self.arguments if isinstance(a, str) and a.endswith(".fmu")]


@dataclass(frozen=True)
class Result:
    case: Case
    verdict: str  # ok, crash, hang, wrong status, wrong output, skipped
    detail: str
    seconds: float


def _departures(procedure: str, fmi: str) -> tuple[str, ...]:
    """A bad parameter is refused at initialisation: the wrappers answer OK there (the reasons
    logged) and refuse later steps with fmi2Discard for fmi2Error."""
    return _refusing(fmi, STATUS_OK_LOGGED) if procedure == "bad_parameter" else ()


def _variables(model: str, causality: str) -> list[str]:
    return [v.name for v in MODELS[model].spec.of(causality) if v.type == "Real"]


def _non_finite(fmu_path: FmuPath, fmi: str, slow: bool) -> list[Case]:
    """Every Real input of every model and two parameters of each, one non-finite value each;
    when slow, every Real parameter too and all three values."""
    found, index = [], 0
    for model in MODELS:
        for causality, procedure in (("input", "bad_input"), ("parameter", "bad_parameter")):
            names = _variables(model, causality)
            for name in names if slow or causality == "input" else names[:2]:
                values = NON_FINITE if slow else (NON_FINITE[index % 3],)
                index += 1
                found += [Case("non-finite values", f"{model}.{name} = {v}", procedure,
                               (str(fmu_path(model, fmi)), name, v), fmi, _departures(procedure, fmi))
                          for v in values]
    return found


def _out_of_range(fmu_path: FmuPath, fmi: str, slow: bool) -> list[Case]:
    """Bounded Real parameters and inputs just beyond their bounds: all when slow, else one per model."""
    found = []
    for model, cls in MODELS.items():
        of_model = []
        for v in cls.spec.variables:
            if v.type != "Real" or v.causality not in ("input", "parameter"):
                continue
            procedure = "bad_input" if v.causality == "input" else "bad_parameter"
            for beyond in ([v.min - 1.0] if v.min is not None else []) + ([v.max + 1.0] if v.max is not None else []):
                of_model.append(Case("out-of-range values", f"{model}.{v.name} = {beyond:g}", procedure,
                                     (str(fmu_path(model, fmi)), v.name, beyond), fmi, _departures(procedure, fmi)))
        found += of_model if slow else of_model[:1]
    return found


def _step_sizes(fmu_path: FmuPath, fmi: str, slow: bool) -> list[Case]:
    sizes = (0.0, -1e-3, 5e-324, 1e-300, 1e300, math.nan, math.inf, -math.inf)
    return [Case("step sizes", f"{model} h = {h!r}", "step_size", (str(fmu_path(model, fmi)), h), fmi)
            for model in (MODELS if slow else ("SpeedSource",)) for h in sizes]


MISUSE = ("step before initialisation", "step in initialisation mode", "step after terminate",
          "set after terminate", "nan time", "-inf time", "time going backwards", "unknown value reference",
          "string on a real",
          "set an output", "fixed parameter after initialisation", "enter initialisation twice", "wrong guid",
          "nan start time")


#: Misuse the wrappers log and answer with OK instead of Error.
LOGGED_WITH_OK = ("set after terminate", "unknown value reference", "string on a real", "set an output",
                  "fixed parameter after initialisation", "enter initialisation twice", "nan start time")


def _refusing(fmi: str, *departures: str) -> tuple[str, ...]:
    """``departures`` of a case whose later steps are refused: with fmi2Discard for fmi2Error in FMI 2.0."""
    return departures + ((FMI2_DISCARD,) if fmi == "2" else ())


def _misuse(fmu_path: FmuPath, fmi: str) -> list[Case]:
    found = []
    for kind in MISUSE:
        model = "TripodCoupling" if kind == "fixed parameter after initialisation" else "CardanJoint"
        if kind == "wrong guid":
            departures = (NO_GUID_CHECK,)
        else:
            departures = _refusing(fmi, STATUS_OK_LOGGED) if kind in LOGGED_WITH_OK else _refusing(fmi)
        found.append(Case("call sequence misuse", kind, "misuse", (str(fmu_path(model, fmi)), kind), fmi, departures))
    return found


STATE_KINDS = ("round trip", "pickle running a command", "truncated", "one bit flipped", "empty", "another model's state")


def _states(fmu_path: FmuPath, fmi: str) -> list[Case]:
    return [Case("state round trips and corrupt state", kind, "state",
                 (str(fmu_path("CardanJoint", fmi)), kind, str(fmu_path("SpeedSource", fmi))), fmi,
                 () if kind == "round trip" else _refusing(fmi, STATUS_OK_LOGGED))
            for kind in STATE_KINDS]


def _instances(fmu_path: FmuPath, fmi: str, slow: bool) -> list[Case]:
    return [Case("instances and threads", f"{model}, {'threads' if threads else 'interleaved'}", "instances",
                 (str(fmu_path(model, fmi)), threads), fmi)
            for model in (("CardanJoint", "TripodCoupling") if slow else ("CardanJoint",)) for threads in (False, True)]


#: (layout value, file to prepare under the FMU's folder, fragment of the expected message)
LAYOUTS = (
    ("%s%s%s%s%s%s.toml", "", "%s%s%s%s%s%s.toml"),
    ("%x%x%x%x%n.toml", "", "%x%x%x%x%n.toml"),
    ("fifo.toml", "fifo", "not a regular file"),
    ("zero.toml", "dev zero", "not a regular file"),
    ("folder.toml", "directory", "not a regular file"),
    ("segments.toml", "many segments", "[[segments]] tables are more than the 100 accepted"),
    ("nested.toml", "deep nesting", "brackets nest deeper than 16 levels"),
    ("large.toml", "large file", "is larger than 65536 bytes"),
    ("stations.toml", "many stations", "the analysis would"),  # with the default omega_in_max: 875 shaft modes
    ("missing.toml", "", "No such file or directory"),
    ("../../../etc/passwd", "", "no shipped example named"),
    ("x" * 300 + ".toml", "", "File name too long"),
)


#: The same for PowertrainMounts' layouts, read by the same rules (driveline/layout_files.py).
MOUNT_LAYOUTS = (
    ("fifo.toml", "fifo", "not a regular file"),
    ("zero.toml", "dev zero", "not a regular file"),
    ("folder.toml", "directory", "not a regular file"),
    ("mounts.toml", "many mounts", "9 [[mounts]] tables are more than the 8 accepted"),
    ("line.toml", "mounts on a line", "leave a rigid-body motion unrestrained"),
    ("nested.toml", "deep nesting", "brackets nest deeper than 16 levels"),
    ("large.toml", "large file", "is larger than 65536 bytes"),
    ("missing.toml", "", "No such file or directory"),
    ("../../../etc/passwd", "", "no shipped layout named"),
)


def _layouts(fmu_path: FmuPath, fmi: str) -> list[Case]:
    path = str(fmu_path("CriticalSpeeds", fmi))
    found = [Case("hostile layout values", f"layout {value[:24]!r}", "layout", (path, value, fragment, prepare), fmi,
                  _departures("bad_parameter", fmi)) for value, prepare, fragment in LAYOUTS]
    mounts = str(fmu_path("PowertrainMounts", fmi))
    found += [Case("hostile layout values", f"PowertrainMounts layout {value[:24]!r}", "layout",
                   (mounts, value, fragment, prepare), fmi, _departures("bad_parameter", fmi))
              for value, prepare, fragment in MOUNT_LAYOUTS]
    found.append(Case("hostile layout values", "layout of 10^5 characters", "long_string",
                      (path, "layout", 100000), fmi, _refusing(fmi, STATUS_OK_LOGGED)))
    return found


#: (parameter, value, fragment of the expected message): work, memory and resolution limits
LIMITS = (
    ("orders", "99999999999999999999", "is not an integer from 1 to 100"),
    ("orders", ",".join(["1"] * 1000), "more than 16 orders"),
    ("L_shaft", 100.0, "more than the 250 accepted"),
    ("L_shaft", 1e6, "more than the 250 accepted"),
    ("density", 1e308, "more than the 250 accepted"),
    ("E", 1e-300, "more than the 250 accepted"),
    ("E", 1e180, "finite-element check"),
    ("omega_in_max", 1e300, "more than the 250 accepted"),
)


def _limits(fmu_path: FmuPath, fmi: str) -> list[Case]:
    path = str(fmu_path("CriticalSpeeds", fmi))
    return [Case("work, memory and resolution limits", f"{name} = {str(value)[:24]}", "parameter_limit",
                 (path, name, value, fragment), fmi, _departures("bad_parameter", fmi))
            for name, value, fragment in LIMITS]


#: (model, input or tunable parameter, value every later step refuses, fragment of the message)
PERSISTENT = (
    ("CardanJoint", "beta", 1.6, "beta"),
    ("TripodCoupling", "beta", 1.2, "beta"),
    ("UniversalReducer", "intersection_angle", 4.0, "intersection_angle"),
    ("CriticalSpeeds", "layout", "nosuch", "no shipped example named 'nosuch'"),
)


def _output_bounds(fmu_path: FmuPath, fmi: str) -> list[Case]:
    """The reducer at intersection_angle = intersection_angle_max = pi - 1e-12: eq 21 once gave stresses of
    3.2e19 Pa with OK. As start values they are refused at initialisation like a bad parameter."""
    angle = math.pi - 1e-12
    return [Case("outputs beyond a physical bound", "UniversalReducer at intersection_angle = pi - 1e-12", "bounded_output",
                 (str(fmu_path("UniversalReducer", fmi)), {"intersection_angle_max": angle, "intersection_angle": angle},
                  "is above its maximum 10000000000.0 Pa"), fmi, _departures("bad_parameter", fmi))]


def _persistent(fmu_path: FmuPath, fmi: str) -> list[Case]:
    return [Case("refusals that end a run", f"{model}.{name} = {value!r}", "persistent_refusal",
                 (str(fmu_path(model, fmi)), name, value, fragment), fmi)
            for model, name, value, fragment in PERSISTENT]


def _start_time(fmu_path: FmuPath, fmi: str) -> list[Case]:
    return [Case("outputs at a start time other than 0", "SpeedSource at t0 = 1 s", "start_time",
                 (str(fmu_path("SpeedSource", fmi)), 1.0), fmi)]


def _engines(fmu_path: FmuPath, versions: Iterable[str]) -> list[Case]:
    """Refused steps in the co-simulation engines installed, in the ``versions`` each of them imports."""
    found = []
    for engine, package, imports in (("libcosim", "libcosimpy", ("2",)), ("Ecos", "ecospy", ("2", "3"))):
        if importlib.util.find_spec(package) is None:
            continue
        for fmi in [version for version in versions if version in imports]:
            for model, name in (("CardanJoint", "omega_in"), ("TripodCoupling", "beta")):
                found.append(Case(f"refused steps in {engine}", f"{model}.{name} = nan", "engine_refusal",
                                  (str(fmu_path(model, fmi)), engine, name, math.nan), fmi,
                                  (ECOS_IGNORES_DISCARD,) if engine == "Ecos" else ()))
    return found


def _model_failures(fmu_path: FmuPath, fmi: str) -> list[Case]:
    """The FMUs of :class:`.failing_model.FailingModel` (skipped where ``fmu_path`` has none)."""
    path = fmu_path(FailingModel.spec.name, fmi)
    return [Case("model failures outside its checks", name, "model_failure", (str(path), failure, name), fmi,
                 () if name == "OverflowError" else _refusing(fmi))
            for failure, name in FAILURES.items()]


def with_failing_model(fmu_path: FmuPath, folder: Path) -> FmuPath:
    """``fmu_path`` plus the failing model's FMUs, built into ``folder``."""
    from ..packaging import fmu_path as built_path

    build_failing_fmus(folder)
    return lambda model, fmi: built_path(folder, model, fmi) if model == FailingModel.spec.name else fmu_path(model, fmi)


def _soak(fmu_path: FmuPath, fmi: str) -> list[Case]:
    return [Case("soak", "100,000 bad/good alternations", "soak", (str(fmu_path("CardanJoint", fmi)), "beta", 100000),
                 fmi, (DISTINCT_TEXTS_LEAK,), time_limit=SOAK_TIME_LIMIT)]


def cases(fmu_path: FmuPath, slow: bool = False, versions: Iterable[str] = ("2", "3"),
          family: str = "python") -> list[Case]:
    """The suite for the FMUs ``fmu_path(model, fmi)`` of ``family``; ``slow`` adds every variable,
    value, model and step size of the sampled classes, and the soak. A native case is checked with
    the standard's outcome where the Python one departs from it because of the wrappers; the
    failing model is a Python model, so its cases are the Python family's only."""
    found = []
    for fmi in versions:
        found += (_non_finite(fmu_path, fmi, slow) + _out_of_range(fmu_path, fmi, slow)
                  + _step_sizes(fmu_path, fmi, slow) + _misuse(fmu_path, fmi) + _states(fmu_path, fmi)
                  + _instances(fmu_path, fmi, slow)
                  + _layouts(fmu_path, fmi) + _limits(fmu_path, fmi) + _persistent(fmu_path, fmi)
                  + _output_bounds(fmu_path, fmi)
                  + _start_time(fmu_path, fmi)
                  + (_model_failures(fmu_path, fmi) if family == "python" else []))
        if slow:
            found += _soak(fmu_path, fmi)
    found += _engines(fmu_path, versions)
    if family == "python":
        return found
    return [replace(case, family=family, departures=tuple(d for d in case.departures if d not in WRAPPER_DEPARTURES))
            for case in found]


class CaseServer:
    """A process that imported :mod:`.robustness_probe` once and runs each case in a child of its
    own forked from it (``robustness_probe --serve``; POSIX): a crash or hang stays the case's,
    and the case does not pay the imports, 0.2 s of CPU each."""

    def __init__(self) -> None:
        self._process = subprocess.Popen([sys.executable, "-m", "fmu_harness.checks.robustness_probe", "--serve"],
                                         cwd=ROOT, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                         errors="replace")

    def run(self, case: Case) -> dict:
        """The child's exit code, stdout, stderr, seconds, and whether it was killed at the limit."""
        request = {"case": json.dumps({"procedure": case.procedure, "arguments": list(case.arguments),
                                       "departures": list(case.departures)}), "time_limit": case.time_limit}
        self._process.stdin.write(json.dumps(request) + "\n")
        self._process.stdin.flush()
        answer = self._process.stdout.readline()
        if not answer:
            raise RuntimeError(f"the case server ended (exit code {self._process.wait()}) at {case.kind} / {case.name}")
        return json.loads(answer)

    def __enter__(self) -> CaseServer:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._process.stdin.close()
        self._process.wait()


def run(case: Case, server: CaseServer) -> Result:
    """Run ``case`` in a new process of ``server`` and classify what happened; a case whose FMUs
    were not built is skipped."""
    missing = [fmu.stem for fmu in case.fmus if not fmu.exists()]
    if missing:
        return Result(case, "skipped", f"no {case.family} FMU of {', '.join(missing)}", 0.0)
    done = server.run(case)
    if done["hung"]:
        return Result(case, "hang", f"no end within {case.time_limit:.0f} s", done["seconds"])
    lines = [line for line in done["stdout"].splitlines() if line.startswith(VERDICT)]
    if not lines:
        detail = f"exit code {done['returncode']}: {done['stderr'].strip()[-300:]}"
        return Result(case, "crash", detail, done["seconds"])
    verdict = json.loads(lines[-1][len(VERDICT):])
    return Result(case, verdict["result"], verdict.get("detail", ""), done["seconds"])


def run_all(suite: list[Case], workers: int = 2) -> list[Result]:
    """The cases on ``workers`` servers at once."""
    with ExitStack() as stack:
        servers: queue.SimpleQueue[CaseServer] = queue.SimpleQueue()
        for _ in range(workers):
            servers.put(stack.enter_context(CaseServer()))

        def on_a_server(case: Case) -> Result:
            server = servers.get()
            try:
                return run(case, server)
            finally:
                servers.put(server)

        with ThreadPoolExecutor(workers) as pool:
            return list(pool.map(on_a_server, suite))


COLUMNS = ("crash", "hang", "wrong status", "wrong output")


def table(results: list[Result]) -> str:
    """Markdown table per class (FMI versions and hosts together): the cases run, by outcome, those
    checked with a departure from the standard, and those skipped."""
    kinds = list(dict.fromkeys(result.case.kind for result in results))
    lines = ["| class | cases | crashes | hangs | wrong statuses | wrong outputs | limited | skipped |",
             "|---|---|---|---|---|---|---|---|"]
    for kind in kinds + ["all"]:
        rows = [r for r in results if kind in ("all", r.case.kind)]
        ran = [r for r in rows if r.verdict != "skipped"]
        counts = [sum(r.verdict == column for r in ran) for column in COLUMNS]
        limited = sum(bool(r.case.departures) for r in ran)
        lines.append(f"| {kind} | {len(ran)} | " + " | ".join(map(str, counts))
                     + f" | {limited} | {len(rows) - len(ran)} |")
    return "\n".join(lines)


def failures(results: list[Result]) -> list[Result]:
    return [result for result in results if result.verdict not in ("ok", "skipped")]


def skipped(results: list[Result]) -> str:
    """Why cases were skipped, e.g. "12 cases: no native FMU of TripodCoupling" ("" if none)."""
    reasons = [r.detail for r in results if r.verdict == "skipped"]
    return "; ".join(f"{reasons.count(reason)} cases: {reason}" for reason in dict.fromkeys(reasons))


def main(argv: list[str] | None = None) -> None:
    from ..packaging import fmu_path, native

    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--models", type=Path, default=Path("models"),
                        help="folder of the built FMUs (the native ones in its native/; default: models)")
    parser.add_argument("--family", action="append", choices=FAMILIES,
                        help="the FMUs to test (repeat for both; default: both)")
    parser.add_argument("--slow", action="store_true", help="every non-finite value and the soak")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    if not hasattr(os, "fork"):
        parser.error("the cases run in processes forked from a host of cases: this needs Linux or macOS")
    if not args.models.is_dir():
        parser.error(f"no folder {args.models}: build the FMUs first (python build_fmu.py)")
    args.models = args.models.resolve()  # the cases run in another folder
    families = args.family or list(FAMILIES)
    started, cpu = time.perf_counter(), _children_cpu()
    with tempfile.TemporaryDirectory() as failing:
        paths = {"python": with_failing_model(lambda model, fmi: fmu_path(args.models, model, fmi), Path(failing)),
                 "native": lambda model, fmi: native.fmu_path(args.models, model, fmi)}
        results = run_all([case for family in families for case in cases(paths[family], args.slow, family=family)],
                          args.workers)
    for family in families:
        of_family = [r for r in results if r.case.family == family]
        print(f"{family} FMUs\n{table(of_family)}")
        if skipped(of_family):
            print(f"skipped: {skipped(of_family)}")
    for result in failures(results):
        print(f"- {result.verdict}: {result.case.family} FMI {result.case.fmi} {result.case.kind} / "
              f"{result.case.name}: {result.detail}")
    print(f"{len(results)} runs in {time.perf_counter() - started:.0f} s wall clock, "
          f"{_children_cpu() - cpu:.0f} s CPU of the host processes")


def _children_cpu() -> float:
    """CPU seconds of the ended child processes (the wall clock of an idle machine is about this
    divided by the workers)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


if __name__ == "__main__":
    main()
