"""A work fuzzer for the CriticalSpeeds FMUs: random small layouts, each analysis within its budget.

Usage: ``python -m fmu_harness.checks.work_fuzzer [--cases N] [--seed S] [--python FMU] [--native FMU]``.
Each case is a random layout of one to four segments with extreme but accepted materials (Young's
modulus 1e8 to 5e12 Pa, density 0.01 to 20 000 kg/m3, walls down to 1e-4 of the diameter), masses,
anisotropic and damped bearings, hinges and unbalances, many and high orders and an ``omega_in_max`` near
the edge the work estimate accepts, then tunable changes mid-run (``omega_in_max``, ``orders``, the
bearing damping, the response position). Every case runs in a process of its own under a limit of
CPU time and address space (``resource.setrlimit``): the FMU is initialised, stepped, changed and
stepped again, and the CPU seconds of each analysis (initialisation or a changed step) are measured,
with the process's peak memory. Run on both families, every case's verdicts (accepted, or refused by the
estimate, the budget or otherwise, analysis by analysis) must be the same in both. ``benchmarks/work_fuzzer.py``
runs many cases, the robustness suite (tests/fmu/test_robustness.py) a few and the issue's layout.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from driveline.rotor.loader import loads_driveline
from driveline.rotor.model import (CAMPBELL_POINTS, FE_ELEMENTS, MAX_ORDER, MAX_ORDERS, MAX_SEARCHED_MODES,
                                   parse_orders, searched_modes)
from driveline.rotor.work import estimate
from fmu_harness.checks.analysis_work import (NATIVE_BUDGET, PYTHON_BUDGET, ROUND_OFF_LAYOUT, ROUND_OFF_PARAMETERS,
                                              peak_resident)
from ..console import summary

BUDGETS = {"python": PYTHON_BUDGET, "native": NATIVE_BUDGET}
#: Communication step of a run [s]; each analysis is followed by one step.
STEP = 1e-3
#: A start value or change of ``layout`` naming the case's own layout (its text written to a file).
CASE_LAYOUT = "<case layout>"


def _log_uniform(rng: np.random.Generator, low: float, high: float) -> float:
    return float(10.0 ** rng.uniform(math.log10(low), math.log10(high)))


def random_layout(rng: np.random.Generator) -> str:
    """A random layout text of one to four segments (extreme but accepted materials) with its point elements."""
    segments = int(rng.integers(1, 5))
    lengths = [_log_uniform(rng, 0.05, 1.5) for _ in range(segments)]
    total = sum(lengths)
    ends = ("free", "pinned", "clamped")
    lines = [f'left_end = "{ends[rng.integers(3)]}"', f'right_end = "{ends[rng.integers(3)]}"']
    for length in lengths:
        diameter = _log_uniform(rng, 0.005, 0.3)
        wall = diameter * _log_uniform(rng, 1e-4, 0.5)
        lines += ["[[segments]]", f"length = {length!r}", f"outer_diameter = {diameter!r}",
                  f"wall_thickness = {wall!r}", f"youngs_modulus = {_log_uniform(rng, 1e8, 5e12)!r}",
                  f"density = {_log_uniform(rng, 0.01, 2e4)!r}"]
        lines += [f"{flag} = false" for flag in ("shear", "gyroscopic") if rng.random() < 0.3]

    def position() -> str:
        return f"position = {float(rng.uniform(0.0, total))!r}"

    for _ in range(int(rng.integers(0, 4))):
        lines += ["[[masses]]", position(), f"mass = {_log_uniform(rng, 1e-3, 50.0)!r}",
                  f"polar_inertia = {_log_uniform(rng, 1e-6, 0.1)!r}",
                  f"diametral_inertia = {_log_uniform(rng, 1e-6, 0.1)!r}"]
    for _ in range(int(rng.integers(1, 4))):
        lines += ["[[bearings]]", position()]
        if rng.random() < 0.5:
            lines += [f"kxx = {_log_uniform(rng, 1e2, 1e9)!r}", f"kyy = {_log_uniform(rng, 1e2, 1e9)!r}"]
        else:
            lines += [f"stiffness = {_log_uniform(rng, 1e2, 1e9)!r}"]
        if rng.random() < 0.6:
            lines += [f"damping = {_log_uniform(rng, 1.0, 1e4)!r}"]
    for _ in range(int(rng.integers(0, 3)) if rng.random() < 0.4 else 0):
        lines += ["[[hinges]]", f"position = {float(rng.uniform(0.05, 0.95) * total)!r}"]
        if rng.random() < 0.5:
            lines += [f"bending_stiffness = {_log_uniform(rng, 1.0, 1e6)!r}"]
    lines += ["[[unbalances]]", position(), f"amount = {_log_uniform(rng, 1e-8, 1e-2)!r}"]
    return "\n".join(lines) + "\n"


def random_orders(rng: np.random.Generator) -> str:
    """One to MAX_ORDERS orders, high ones as likely as low ones."""
    count = int(rng.integers(1, MAX_ORDERS + 1))
    return ",".join(str(k) for k in sorted(rng.choice(np.arange(1, MAX_ORDER + 1), count, replace=False)))


def accepted_edge(text: str, orders: str) -> float | None:
    """The largest ``omega_in_max`` (a power of two times 1e-3 rad/s) that the work limits accept for
    ``text`` and ``orders``; None if the layout is refused (or accepts none)."""
    try:
        driveline = loads_driveline(text)
    except ValueError:
        return None
    best = None
    for k in range(40):
        omega_max = 1e-3 * 2.0 ** k
        parsed = parse_orders(orders)
        try:
            fine = (searched_modes(driveline, parsed, omega_max) <= MAX_SEARCHED_MODES
                    and estimate(driveline, parsed, omega_max, CAMPBELL_POINTS, FE_ELEMENTS).refusal() is None)
        except (ValueError, ArithmeticError):
            return best
        if not fine:
            return best
        best = omega_max
    return best


def random_case(rng: np.random.Generator) -> dict:
    """A case: a layout the loader accepts, start values with ``omega_in_max`` near the estimate's edge, and
    two tunable changes."""
    while True:
        text, orders = random_layout(rng), random_orders(rng)
        edge = accepted_edge(text, orders)
        if edge is not None:
            break
    omega_max = edge * float(rng.uniform(0.5, 1.0))
    start = {"omega_in_max": omega_max, "omega_in": omega_max * float(rng.uniform(0.0, 1.0)), "orders": orders,
             "band": 0.1}
    lower = omega_max * float(rng.uniform(0.3, 1.0))
    changes = [{"omega_in_max": lower, "omega_in": min(start["omega_in"], lower)},
               {"orders": random_orders(rng), "c_bearing": _log_uniform(rng, 1.0, 1e4),
                "response_position": float(rng.uniform(0.0, 1.0))}]
    return {"layout": text, "start": start, "changes": changes}


def issue_case() -> dict:
    """The layout that once took 12.9 s native and 25.4 s in the Python core (``ROUND_OFF_LAYOUT``), with a
    change of ``omega_in_max`` and of ``orders``."""
    return {"layout": ROUND_OFF_LAYOUT, "start": dict(ROUND_OFF_PARAMETERS),
            "changes": [{"omega_in_max": 1.5, "omega_in": 1.5}, {"orders": "1,2,3,89"}]}


def _cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def run_case(fmu: str, case: dict) -> dict:
    """The case on ``fmu`` in this process: CPU seconds, status and first message of each analysis (the
    initialisation and first step, then each change's step), and the peak resident memory. The case's
    ``layout`` text is written to a file, the layout unless its start values name another; a value
    ``CASE_LAYOUT`` names that file."""
    from fmu_harness.runs.runner import FmuInstance, StepRefused

    analyses = []
    with tempfile.TemporaryDirectory() as folder:
        layout = Path(folder) / "layout.toml"
        layout.write_text(case["layout"])

        def values(given: dict) -> dict:
            return {name: str(layout) if value == CASE_LAYOUT else value for name, value in given.items()}

        with FmuInstance(fmu) as instance:
            # the Python FMUs log a refusal at initialisation and refuse the next step (docs/robustness.md)
            calls = [lambda: (instance.initialize(values({"layout": CASE_LAYOUT, **case["start"]})),
                              instance.step(STEP))]
            calls += [lambda change=change: (instance.set(values(change)), instance.step(STEP))
                      for change in case["changes"]]
            for call in calls:
                started = _cpu()
                try:
                    call()
                    outcome = {"status": "OK", "message": ""}
                except StepRefused as refused:
                    outcome = {"status": refused.status, "message": (refused.messages or [""])[0]}
                analyses.append({"seconds": _cpu() - started, **outcome})
                if outcome["status"] != "OK":
                    break  # a refused analysis ends the run (the FMU is in its error state)
    return {"analyses": analyses, "peak": peak_resident()}


def run_limited(fmu: Path, case: dict, budget: tuple[float, int]) -> dict:
    """:func:`run_case` in a new process limited to twice the budget's CPU seconds (plus 5 s to start) and to
    the budget's address space plus 1 GB for the interpreter; {"failed": why} if it did not end.
    One BLAS thread: on a busy machine idle BLAS threads spin and bill CPU time the analysis does not use."""

    def limit() -> None:
        seconds, memory = budget
        resource.setrlimit(resource.RLIMIT_CPU, (int(2 * seconds) + 5, int(2 * seconds) + 6))
        resource.setrlimit(resource.RLIMIT_AS, (memory + 1024**3, memory + 1024**3))

    command = [sys.executable, "-c", "import json, sys; from fmu_harness.checks.work_fuzzer import run_case; "
               "print(json.dumps(run_case(sys.argv[1], json.loads(sys.argv[2]))))", str(fmu), json.dumps(case)]
    environment = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    try:
        done = subprocess.run(command, capture_output=True, text=True, preexec_fn=limit, env=environment,
                              timeout=10 * budget[0] + 60)
    except subprocess.TimeoutExpired:
        return {"failed": "no end in time"}
    if done.returncode:
        return {"failed": f"exit {done.returncode}: {' '.join(done.stderr.split()[-30:])}"}
    return json.loads(done.stdout.strip().splitlines()[-1])


def fuzz(fmus: dict[str, Path], count: int, seed: int, progress=None) -> list[dict]:
    """``count`` random cases (the issue's layout first) run on every family's FMU of ``fmus``."""
    rng = np.random.default_rng(seed)
    results = []
    for index in range(count):
        case = issue_case() if index == 0 else random_case(rng)
        outcome = {family: run_limited(path, case, BUDGETS[family]) for family, path in fmus.items()}
        results.append({"case": case, **outcome})
        if progress is not None:
            progress(index + 1, count)
    return results


def kind(analysis: dict) -> str:
    """What became of one analysis: accepted, refused by the estimate, by the budget, or otherwise."""
    if analysis["status"] == "OK":
        return "accepted"
    if "work budget" in analysis["message"]:
        return "budget"
    if "would take about" in analysis["message"] or "shaft modes" in analysis["message"]:
        return "estimate"
    return "other"


def over_budget(results: list[dict]) -> list[str]:
    """Every analysis beyond its family's budget (CPU seconds or memory), accepted or not, and every
    process that did not end."""
    found = []
    for number, result in enumerate(results):
        for family, (seconds, memory) in BUDGETS.items():
            run = result.get(family)
            if run is None:
                continue
            if "failed" in run:
                found.append(f"case {number}, {family}: {run['failed']}")
                continue
            for call, analysis in enumerate(run["analyses"]):
                if analysis["seconds"] > seconds:
                    found.append(f"case {number}, {family}, analysis {call}: {analysis['seconds']:.3g} s "
                                 f"({kind(analysis)})")
            if run["peak"] > memory:
                found.append(f"case {number}, {family}: peak {run['peak'] / 2**20:.0f} MB")
    return found


def verdicts(run: dict) -> list[str]:
    """The verdict of each analysis of a family's run (:func:`kind`), in order."""
    return [kind(analysis) for analysis in run["analyses"]]


def disagreements(results: list[dict]) -> list[str]:
    """Every case whose families' verdicts differ: an analysis that one family accepts and the other refuses, or
    refuses for another reason (the estimate, the budget, any other), with the first refusal of each; the cases
    only one family ran, or on which a family's process did not end (:func:`over_budget`), are not compared."""
    found = []
    for number, result in enumerate(results):
        runs = [result.get(family) for family in BUDGETS]
        if any(run is None or "failed" in run for run in runs):
            continue
        given = [verdicts(run) for run in runs]
        if given[0] != given[1]:
            said = [next((a["message"] for a in run["analyses"] if a["status"] != "OK"), "") for run in runs]
            found.append(f"case {number}: " + "; ".join(
                f"{family} {', '.join(kinds)}" + (f" ({message})" if message else "")
                for family, kinds, message in zip(BUDGETS, given, said)))
    return found


def exit_on_findings(results: list[dict]) -> None:
    """Name every analysis beyond its budget (:func:`over_budget`) and every case on which the families'
    verdicts differ (:func:`disagreements`), and exit, 1 if there is any."""
    over, differing = over_budget(results), disagreements(results)
    for line in over:
        print(f"over budget: {line}")
    for line in differing:
        print(f"verdicts differ: {line}")
    sys.exit(1 if over or differing else 0)


def summary(results: list[dict]) -> str:
    """Markdown: per family the cases, the analyses by outcome, the worst CPU seconds of an accepted
    analysis and of any, and the worst peak memory."""
    lines = ["| family | cases | analyses | accepted | refused: estimate | refused: budget | refused: other "
             "| worst accepted [s] | worst any [s] | worst peak [MB] |", "|---|---|---|---|---|---|---|---|---|---|"]
    for family in BUDGETS:
        runs = [result[family] for result in results if family in result]
        if not runs:
            continue
        analyses = [a for run in runs if "failed" not in run for a in run["analyses"]]
        kinds = [kind(a) for a in analyses]
        accepted = [a["seconds"] for a in analyses if a["status"] == "OK"]
        peaks = [run["peak"] for run in runs if "failed" not in run]
        lines.append(f"| {family} | {len(runs)} | {len(analyses)} | {kinds.count('accepted')} | "
                     f"{kinds.count('estimate')} | {kinds.count('budget')} | {kinds.count('other')} | "
                     f"{max(accepted, default=0.0):.3g} | {max((a['seconds'] for a in analyses), default=0.0):.3g} | "
                     f"{max(peaks, default=0) / 2**20:.0f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--cases", type=int, default=20,
                        help="cases per family (default 20; the first is the issue's layout)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random cases (default 0)")
    parser.add_argument("--python", type=Path, default=Path("models/CriticalSpeeds.fmu"), help="the Python FMU")
    parser.add_argument("--native", type=Path, default=Path("models/native/CriticalSpeeds.fmu"), help="the native FMU")
    args = parser.parse_args(argv)
    fmus = {family: path for family, path in (("python", args.python), ("native", args.native)) if path.exists()}
    if not fmus:
        parser.exit(2, f"no FMU at {args.python} or {args.native}: build them first "
                       "(python build_fmu.py CriticalSpeeds)\n")
    results = fuzz(fmus, args.cases, args.seed, lambda done, total: print(f"case {done}/{total}", file=sys.stderr))
    print(summary(results))
    exit_on_findings(results)


if __name__ == "__main__":
    main()
