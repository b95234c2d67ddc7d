"""The worst CriticalSpeeds inputs the limits allow, and what each analysis stage costs on them.

Usage: ``python -m fmu_harness.checks.analysis_work [--native models/native/CriticalSpeeds.fmu]`` prints, per
layout, the work estimate (:mod:`driveline.rotor.work`) and the time and peak memory of every stage of
the Python analysis, each layout in a process of its own under a limit of time and address space; with
a native FMU, the time and peak memory of its whole analysis (``ExitInitializationMode``) too.
``benchmarks/analysis_work.py`` checks the bounds; ``tests/fmu/test_analysis_work.py`` runs the same cases.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from driveline.rotor.loader import MAX_POINT_ELEMENTS, MAX_SEGMENTS, load_driveline
from driveline.rotor.model import (CAMPBELL_POINTS, FE_ELEMENTS, MAX_ORDER, MAX_ORDERS, MAX_SEARCHED_MODES,
                                   CriticalSpeedsModel, parse_orders, searched_modes)
from driveline.rotor.spec import OMEGA_MAX_MIN
from driveline.rotor.work import MAX_ANALYSIS_SECONDS, STAGES, estimate

#: The budgets of one analysis on the project's two-core machine: (seconds, bytes of memory).
PYTHON_BUDGET = (30.0, 2 * 1024**3)
NATIVE_BUDGET = (5.0, 500 * 1024**2)
#: A tube of the shipped propshaft's size.
TUBE = 'outer_diameter = 0.0762\nwall_thickness = 0.00165\nmaterial = "steel"'


def layout_text(segments: int, length: float, masses: int, bearings: int, unbalances: int,
                between: bool = False) -> str:
    """``segments`` equal tubes over ``length`` m with point elements spread over the nodes (``between``:
    at positions between them, which cut the segments)."""
    lines = ['name = "generated"', "[materials.steel]", "youngs_modulus = 2.1e11", "density = 7850.0"]
    lines += [f"[[segments]]\nlength = {length / segments!r}\n{TUBE}"] * segments

    def where(i: int, count: int) -> str:
        return f"position = {length * (i + 0.5) / count!r}" if between else f"node = {i * (segments + 1) // count}"

    lines += [f"[[masses]]\n{where(i, masses)}\nmass = 0.1\npolar_inertia = 1e-4\ndiametral_inertia = 5e-5"
              for i in range(masses)]
    lines += [f"[[bearings]]\n{where(i, bearings)}\nstiffness = 1e6" for i in range(bearings)]
    lines += [f"[[unbalances]]\nposition = {length * (i + 0.5) / unbalances!r}\namount = 1e-5" for i in range(unbalances)]
    return "\n".join(lines) + "\n"


def accepted(text: str, parameters: dict) -> bool:
    """Whether the work limits accept ``text`` with ``parameters`` (``orders``, ``omega_max``)."""
    with tempfile.NamedTemporaryFile("w", suffix=".toml") as file:
        file.write(text)
        file.flush()
        driveline = load_driveline(file.name)
    orders, omega_max = parse_orders(parameters.get("orders", "1,2,3")), parameters.get("omega_max", 1500.0)
    work = estimate(driveline, orders, omega_max, CAMPBELL_POINTS, FE_ELEMENTS)
    return searched_modes(driveline, orders, omega_max) <= MAX_SEARCHED_MODES and work.refusal() is None


def _most(make, top: int) -> int:
    """The largest ``n <= top`` with ``accepted(*make(n))`` (accepted grows as n falls)."""
    return next(n for n in range(top, 0, -1) if accepted(*make(n)))


def worst_cases() -> dict[str, tuple[str, dict]]:
    """Layout text and parameters of the worst inputs the limits allow, each kind at its edge, the
    propshaft engineer's shaft, and the issue's 566 s layout (refused)."""
    slow = {"omega_max": OMEGA_MAX_MIN, "orders": "1", "omega": 0.0}

    def stations(n: int) -> tuple[str, dict]:
        return layout_text(n, 1.4, 2 * (n + 1), 2 * (n + 1), min(MAX_POINT_ELEMENTS, 2 * n)), slow

    def segments(n: int) -> tuple[str, dict]:
        return layout_text(n, 1.4, 2, 2, MAX_POINT_ELEMENTS), slow

    def shortest(n: int) -> tuple[str, dict]:
        return layout_text(n, 1e-3 * n, 2, 2, 2), slow

    propshaft = layout_text(20, 1.6, 10, 6, 4)
    orders = ",".join(str(k) for k in range(MAX_ORDER - MAX_ORDERS + 1, MAX_ORDER + 1))
    speeds = [1e-3 * 2.0 ** k for k in range(40)]
    fastest = max(w for w in speeds if accepted(propshaft, {"omega_max": w}))
    fastest_orders = max(w for w in speeds if accepted(propshaft, {"omega_max": w, "orders": orders}))
    return {
        "most stations": stations(_most(stations, MAX_SEGMENTS)),
        "most segments": segments(_most(segments, MAX_SEGMENTS)),
        "shortest segments (1 mm)": shortest(_most(shortest, MAX_SEGMENTS)),
        "stations between nodes": (layout_text(4, 1.4, 8, 8, 8, between=True), slow),
        "most orders": (propshaft, {"orders": orders, "omega_max": fastest_orders, "omega": 0.0}),
        "smallest omega_max": (propshaft, slow),
        "largest omega_max": (propshaft, {"omega_max": fastest, "omega": 0.0}),
        "propshaft, 20 segments": (propshaft, {"omega": 0.0}),
        "issue's 566 s layout": (layout_text(100, 1.4, 202, 202, 200), slow),
    }


def peak_resident() -> int:
    """Peak resident bytes of this process's program (``VmHWM``: ``ru_maxrss`` keeps the parent's peak
    across exec, docs/robustness.md)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) * 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def python_stages(path: str, parameters: dict) -> dict:
    """Every stage of the Python analysis of ``path`` with ``parameters``: seconds and the process's peak
    resident memory after it; the refusal instead if the model refuses."""
    from driveline.rotor import model
    from driveline.rotor.unbalance_outputs import UnbalanceOutputs

    core = CriticalSpeedsModel()
    core.layout = path
    for name, value in parameters.items():
        setattr(core, name, value)
    driveline = model.build_driveline(path, {})
    orders = parse_orders(core.orders)
    work = estimate(driveline, orders, core.omega_max, CAMPBELL_POINTS, FE_ELEMENTS)
    result = {"estimate": dict(zip(STAGES, work.seconds)), "refusal": work.refusal(), "stages": {}}
    if result["refusal"] is not None:
        return result
    structure = {}
    steps = {
        "critical speeds": lambda: structure.setdefault("found", driveline.critical_speeds(3)),
        "order resonances": lambda: model.resonances(driveline, orders, core.omega_max),
        "FE check": lambda: structure.setdefault("natural", model.natural_frequencies(driveline)),
        "Campbell table": lambda: model.whirl_table(model.Structure(
            driveline, (0.0, 0.0, 0.0), 0, structure["natural"]), core.omega_max),
        "unbalance response": lambda: UnbalanceOutputs.build(driveline, driveline.unbalances,
                                                              core.response_position, core.omega_max),
    }
    for name, step in steps.items():
        started = time.process_time()
        step()
        result["stages"][name] = (time.process_time() - started, peak_resident())
    return result


def native_analysis(fmu: str, path: str, parameters: dict) -> dict:
    """Seconds of the native FMU's ``ExitInitializationMode`` (its whole analysis), its status and
    first message, and the process's peak resident memory."""
    from fmpy import extract, read_model_description
    from fmpy.simulation import instantiate_fmu

    description = read_model_description(fmu)
    messages: list[str] = []
    instance = instantiate_fmu(extract(fmu), description, "CoSimulation", debug_logging=True,
                               logger=lambda *args: messages.append(args[-1].decode()))
    references = {v.name: v.valueReference for v in description.modelVariables}
    instance.setupExperiment(startTime=0.0)
    instance.enterInitializationMode()
    instance.setString([references["layout"]], [path])
    for name, value in parameters.items():
        setter = instance.setString if isinstance(value, str) else instance.setReal
        setter([references[name]], [value])
    started = time.process_time()
    try:
        instance.exitInitializationMode()
        status = "OK"
    except Exception as error:  # noqa: BLE001 - fmpy's exception for Error
        status = str(error)
    return {"seconds": time.process_time() - started, "status": status, "message": messages[:1],
            "peak": peak_resident()}


def run_limited(function: str, arguments: list, budget: tuple[float, int]) -> dict:
    """``function(*arguments)`` of this module in a new process limited to twice the budget's CPU
    seconds and its address space plus room for the interpreter; {"failed": why} if it did not end."""

    def limit() -> None:
        seconds, memory = budget
        resource.setrlimit(resource.RLIMIT_CPU, (int(2 * seconds) + 5, int(2 * seconds) + 6))
        resource.setrlimit(resource.RLIMIT_AS, (memory + 1024**3, memory + 1024**3))

    command = [sys.executable, "-c", f"import json, sys; from fmu_harness.checks.analysis_work import {function} as f; "
               f"print(json.dumps(f(*json.loads(sys.argv[1]))))", json.dumps(arguments)]
    try:
        done = subprocess.run(command, capture_output=True, text=True, preexec_fn=limit, timeout=10 * budget[0] + 60)
    except subprocess.TimeoutExpired:
        return {"failed": "no end in time"}
    if done.returncode:
        return {"failed": f"exit {done.returncode}: {' '.join(done.stderr.split()[-30:])}"}
    return json.loads(done.stdout.strip().splitlines()[-1])


def measure(folder: Path, native_fmu: Path | None = None) -> dict[str, dict]:
    """Every worst case written to ``folder`` and measured (Python stages; the native FMU's analysis)."""
    results = {}
    for name, (text, parameters) in worst_cases().items():
        path = folder / f"{name.split(',')[0].replace(' ', '_').replace(chr(39), '')}.toml"
        path.write_text(text)
        results[name] = {"python": run_limited("python_stages", [str(path), parameters], PYTHON_BUDGET)}
        if native_fmu is not None:
            results[name]["native"] = run_limited("native_analysis", [str(native_fmu), str(path), parameters],
                                                  NATIVE_BUDGET)
    return results


def table(results: dict[str, dict]) -> str:
    """Markdown: per case and stage the estimate, the Python time and peak, the native analysis."""
    lines = ["| case | stage | estimate [s] | Python [s] | Python peak [MB] | native analysis [s] | native peak [MB] |",
             "|---|---|---|---|---|---|---|"]
    for name, result in results.items():
        python, native = result["python"], result.get("native", {})
        if "failed" in python:
            lines.append(f"| {name} | - | - | {python['failed']} | | | |")
            continue
        shown_native = (f"{native['seconds']:.3g}" if native.get("status") == "OK" else "refused") if native else ""
        native_peak = f"{native['peak'] / 2**20:.0f}" if native.get("peak") else ""
        if python["refusal"] is not None:
            total = sum(python["estimate"].values())
            lines.append(f"| {name} | refused | {total:.3g} | refused | | {shown_native} | {native_peak} |")
            continue
        for i, stage in enumerate(STAGES):
            seconds, peak = python["stages"].get(stage, (None, None))
            if stage == "damped modes":  # built with the unbalance response (one UnbalanceOutputs)
                continue
            estimated = python["estimate"][stage] + (python["estimate"]["damped modes"] if stage == "unbalance response" else 0.0)
            lines.append(f"| {name if i == 0 else ''} | {stage} | {estimated:.3g} | {seconds:.3g} | "
                         f"{peak / 2**20:.0f} | {shown_native if i == 0 else ''} | {native_peak if i == 0 else ''} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--native", type=Path, help="a native CriticalSpeeds FMU (FMI 2.0) to measure too")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        results = measure(Path(folder), args.native)
    print(table(results))
    print(f"limit of the estimate: {MAX_ANALYSIS_SECONDS} s; budgets: Python {PYTHON_BUDGET[0]:g} s, "
          f"{PYTHON_BUDGET[1] / 2**30:g} GB; native {NATIVE_BUDGET[0]:g} s, {NATIVE_BUDGET[1] / 2**20:g} MB")


if __name__ == "__main__":
    main()
