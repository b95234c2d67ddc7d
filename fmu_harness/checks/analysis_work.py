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
from driveline.rotor.spec import OMEGA_IN_MAX_MIN
from driveline.rotor.work import MAX_ANALYSIS_SECONDS, STAGES, estimate
from ..console import summary

#: The budgets of one analysis on the project's two-core machine: (seconds, bytes of memory).
PYTHON_BUDGET = (30.0, 2 * 1024**3)
NATIVE_BUDGET = (5.0, 500 * 1024**2)
#: A layout of extreme materials found by a work fuzzer: its determinant ripples at about its rounding
#: level near a close pair at 11 384 rad/s, where the root search once re-scanned 1.7 million points at
#: a speed (12.9 s native, 25.4 s Python with ``ROUND_OFF_PARAMETERS``; estimated 0.105 s).
ROUND_OFF_LAYOUT = """left_end = "free"
right_end = "pinned"
[[segments]]
length = 0.8248646946212962
outer_diameter = 0.17068998163927307
wall_thickness = 0.0034137996327854615
youngs_modulus = 5045815318195.618
density = 3.907321004526678
gyroscopic = false
[[segments]]
length = 0.8248646946212962
outer_diameter = 0.2321754908004059
wall_thickness = 2.3217549080040592e-05
youngs_modulus = 210000000000.0
density = 1.0171558428091914
shear = false
[[segments]]
length = 0.8248646946212962
outer_diameter = 0.019952451022759693
wall_thickness = 0.00039904902045519386
youngs_modulus = 110072829.65974881
density = 0.020640445017250677
gyroscopic = true
[[bearings]]
position = 0.7733679342663501
kxx = 195.28871436131323
kyy = 2011.146833880055
damping = 16.8449620808454
[[bearings]]
position = 1.2189934173177135
stiffness = 148605257.06885213
[[unbalances]]
position = 1.440681430980566
amount = 8.265024109038702e-08
"""
ROUND_OFF_PARAMETERS = {"omega_in_max": 2.07419590242784, "omega_in": 2.07419590242784, "band": 0.1, "orders": "89"}


def _segments_repeated(layout: str, times: int) -> str:
    """``layout`` (its segments before its bearings) with its segments repeated ``times`` times, its point
    elements where they were."""
    head, rest = layout.split("[[segments]]", 1)
    segments, points = rest.split("[[bearings]]", 1)
    return head + times * ("[[segments]]" + segments) + "[[bearings]]" + points


#: ROUND_OFF_LAYOUT with its three segments repeated (six), the bearings where they were: with
#: ROUND_OFF_PARAMETERS refused natively ("more than 512 dips on one line") and accepted by the Python core (at
#: most 24 dips re-scanned on a line), the families' verdicts differing (issue 45, defect 6).
SIX_SEGMENT_LAYOUT = _segments_repeated(ROUND_OFF_LAYOUT, 2)
#: A layout the work estimate accepts (0.2 s) whose anisotropic Campbell table exceeds the analysis's budget
#: (driveline/rotor/budget.py) with ``BUDGET_PARAMETERS``: refused naming the Campbell table, natively
#: after 1.7 s of CPU time (found by a work fuzzer's layout with two masses and a bearing added).
BUDGET_LAYOUT = """left_end = "clamped"
right_end = "pinned"
[[segments]]
length = 1.4059768799749384
outer_diameter = 0.1251625266873248
wall_thickness = 0.027209713019476382
youngs_modulus = 3625575902.95697
density = 15071.722950688541
gyroscopic = false
[[segments]]
length = 1.086218955839054
outer_diameter = 0.04380485269892381
wall_thickness = 0.000687683508999283
youngs_modulus = 180139481380.35928
density = 168.9252328964127
shear = false
[[masses]]
position = 1.6700359239882223
mass = 38.23927134855459
polar_inertia = 0.00036102597923154037
diametral_inertia = 0.011247151157012181
[[masses]]
position = 0.34958642047857075
mass = 16.148109072445408
polar_inertia = 0.00015212135846689318
diametral_inertia = 0.024173897033860112
[[masses]]
position = 0.799567379381423
mass = 0.8583459474003896
polar_inertia = 0.017098879389715754
diametral_inertia = 0.0036039989582832637
[[bearings]]
position = 1.5449843227608087
stiffness = 413.02545157194186
damping = 160.81302708371194
[[bearings]]
position = 2.3792747480813317
stiffness = 14706.556304412345
damping = 62.10761727394972
[[bearings]]
position = 1.1969776055495367
kxx = 2164449.7769301157
kyy = 8121.219782890922
[[hinges]]
position = 0.9073154117425819
[[hinges]]
position = 0.48219320031474766
bending_stiffness = 362618.8792222968
[[unbalances]]
position = 0.8674876301034313
amount = 0.001144373592146762
[[masses]]
position = 0.1
mass = 1.0
polar_inertia = 0.001
diametral_inertia = 0.002
[[masses]]
position = 0.30000000000000004
mass = 2.0
polar_inertia = 0.001
diametral_inertia = 0.002
[[bearings]]
position = 0.2
kxx = 10000.0
kyy = 300000.0
"""
BUDGET_PARAMETERS = {"orders": "5,36", "omega_in_max": 65.536, "omega_in": 0.0}
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
    """Whether the work limits accept ``text`` with ``parameters`` (``orders``, ``omega_in_max``)."""
    with tempfile.NamedTemporaryFile("w", suffix=".toml") as file:
        file.write(text)
        file.flush()
        driveline = load_driveline(file.name)
    orders, omega_max = parse_orders(parameters.get("orders", "1,2,3")), parameters.get("omega_in_max", 1500.0)
    work = estimate(driveline, orders, omega_max, CAMPBELL_POINTS, FE_ELEMENTS)
    return searched_modes(driveline, orders, omega_max) <= MAX_SEARCHED_MODES and work.refusal() is None


def _most(make, top: int) -> int:
    """The largest ``n <= top`` with ``accepted(*make(n))`` (accepted grows as n falls)."""
    return next(n for n in range(top, 0, -1) if accepted(*make(n)))


def worst_cases() -> dict[str, tuple[str, dict]]:
    """Layout text and parameters of the worst inputs the limits allow, each kind at its edge, the
    propshaft engineer's shaft, and the issue's 566 s layout (refused)."""
    slow = {"omega_in_max": OMEGA_IN_MAX_MIN, "orders": "1", "omega_in": 0.0}

    def stations(n: int) -> tuple[str, dict]:
        return layout_text(n, 1.4, 2 * (n + 1), 2 * (n + 1), min(MAX_POINT_ELEMENTS, 2 * n)), slow

    def segments(n: int) -> tuple[str, dict]:
        return layout_text(n, 1.4, 2, 2, MAX_POINT_ELEMENTS), slow

    def shortest(n: int) -> tuple[str, dict]:
        return layout_text(n, 1e-3 * n, 2, 2, 2), slow

    propshaft = layout_text(20, 1.6, 10, 6, 4)
    orders = ",".join(str(k) for k in range(MAX_ORDER - MAX_ORDERS + 1, MAX_ORDER + 1))
    speeds = [1e-3 * 2.0 ** k for k in range(40)]
    fastest = max(w for w in speeds if accepted(propshaft, {"omega_in_max": w}))
    fastest_orders = max(w for w in speeds if accepted(propshaft, {"omega_in_max": w, "orders": orders}))
    return {
        "most stations": stations(_most(stations, MAX_SEGMENTS)),
        "most segments": segments(_most(segments, MAX_SEGMENTS)),
        "shortest segments (1 mm)": shortest(_most(shortest, MAX_SEGMENTS)),
        "stations between nodes": (layout_text(4, 1.4, 8, 8, 8, between=True), slow),
        "most orders": (propshaft, {"orders": orders, "omega_in_max": fastest_orders, "omega_in": 0.0}),
        "smallest omega_in_max": (propshaft, slow),
        "largest omega_in_max": (propshaft, {"omega_in_max": fastest, "omega_in": 0.0}),
        "propshaft, 20 segments": (propshaft, {"omega_in": 0.0}),
        "round-off ripple": (ROUND_OFF_LAYOUT, ROUND_OFF_PARAMETERS),
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
    work = estimate(driveline, orders, core.omega_in_max, CAMPBELL_POINTS, FE_ELEMENTS)
    result = {"estimate": dict(zip(STAGES, work.seconds)), "refusal": work.refusal(), "stages": {}}
    if result["refusal"] is not None:
        return result
    structure = {}
    steps = {
        "critical speeds": lambda: structure.setdefault("found", driveline.critical_speeds(3)),
        "order resonances": lambda: model.resonances(driveline, orders, core.omega_in_max),
        "FE check": lambda: structure.setdefault("natural", model.natural_frequencies(driveline)),
        "Campbell table": lambda: model.whirl_table(model.Structure(
            driveline, (0.0, 0.0, 0.0), 0, structure["natural"]), core.omega_in_max),
        "unbalance response": lambda: UnbalanceOutputs.build(driveline, driveline.unbalances,
                                                              core.response_position, core.omega_in_max),
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
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--native", type=Path, help="a native CriticalSpeeds FMU (FMI 2.0) to measure too")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        results = measure(Path(folder), args.native)
    print(table(results))
    print(f"limit of the estimate: {MAX_ANALYSIS_SECONDS} s; budgets: Python {PYTHON_BUDGET[0]:g} s, "
          f"{PYTHON_BUDGET[1] / 2**30:g} GB; native {NATIVE_BUDGET[0]:g} s, {NATIVE_BUDGET[1] / 2**20:g} MB")


if __name__ == "__main__":
    main()
