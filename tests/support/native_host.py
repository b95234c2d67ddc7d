"""The C test host's side in Python (``native_host.c`` beside this file, a host with no Python in
its process): the runs it makes of each native model and the scenario file it reads, the Python
FMU's outputs as the reference."""

from __future__ import annotations

from pathlib import Path

from fmpy import extract, read_model_description

from driveline.catalog import MODELS
from fmu_harness.packaging import native
from fmu_harness.runs.runner import FmuInstance
from fmu_harness.runs.scenario import scenario
from support.native_agreement import SCALE_FLOOR, SIGNAL_TOLERANCE, TOLERANCE

HOST_SOURCE = Path(__file__).with_name("native_host.c")

# The standard scenario of every native model, and the modes it leaves out (its parameters
# are the spec's start values); CriticalSpeeds' String and Boolean parameters, a shipped layout
# found in the resources folder the host hands over.
MODES = {"TripodCoupling": [{"kinematics": 1, "mu": 0.05}, {"kinematics": 1, "seed_reactions": 1}],
         "CriticalSpeeds": [{"layout": "two_piece_propshaft"}, {"orders": "1,2,3,6", "shear": False}]}
#: Largest deviation from the Python FMU, relative to each output's largest magnitude: the damping
#: ratio's eigenvalue real part and the response near a resonance, 1e-9 (why: SIGNAL_TOLERANCE of
#: support.native_agreement). The host takes each output's scale floor (SCALE_FLOOR: PowertrainMounts' rest on
#: progressive mounts is rounding) and its own tolerance where that allows more (SIGNAL_TOLERANCE) from there.
TOLERANCES = {"CriticalSpeeds": 1e-9}
RUNS = [(name, parameters) for name in native.native_models() for parameters in ({}, *MODES.get(name, ()))]


def host_tolerance(name: str) -> float:
    """Model ``name``'s largest deviation from the Python FMU in the host (:data:`TOLERANCES`, else the
    native agreement's)."""
    return TOLERANCES.get(name, TOLERANCE)


def _weight(output: str, tolerance: float) -> float:
    """An output's tolerance as a multiple of its model's: what support.native_agreement allows it beyond."""
    return max(1.0, SIGNAL_TOLERANCE.get(output, TOLERANCE) / tolerance)


def host_command(native_dir: Path, fmu_path, name: str, fmi: str, work: Path, parameters: dict) -> list[str]:
    """Extract the native FMU and write its scenario with ``parameters`` and the Python FMU's outputs
    as reference."""
    path = native.fmu_path(native_dir, name, fmi)
    unzipdir = Path(extract(str(path), unzipdir=str(work / "fmu")))
    description = read_model_description(str(path))
    token = description.instantiationToken if fmi == "3" else description.guid
    library = native.host_library(unzipdir, name, fmi)
    spec = MODELS[name].spec
    case = scenario(spec)
    tolerance = host_tolerance(name)
    references = {v.name: v.valueReference for v in description.modelVariables}
    outputs = [v.name for v in spec.of("output") if v.type == "Real"]
    with FmuInstance(fmu_path(name, fmi)) as fmu:
        fmu.initialize({**parameters, **case.input_values(0.0)})
        expected = fmu.run(case.stop_time, case.step_size, case.signals(), outputs)
    inputs = list(case.inputs)
    lines = [f"inputs {len(inputs)} " + " ".join(str(references[n]) for n in inputs),
             f"outputs {len(outputs)} " + " ".join(str(references[n]) for n in outputs),
             *(f"{kind} {len(chosen)} " + " ".join(f"{references[n]} {chosen[n]}" for n in chosen)
               for kind, chosen in (("parameters", {n: repr(v) for n, v in parameters.items() if spec[n].type == "Real"}),
                                    ("integers", {n: v for n, v in parameters.items() if spec[n].type == "Integer"}),
                                    ("booleans", {n: int(v) for n, v in parameters.items() if spec[n].type == "Boolean"}),
                                    ("strings", {n: v for n, v in parameters.items() if spec[n].type == "String"}))),
             f"tolerance {tolerance!r}",
             f"limits {len(outputs)} " + " ".join(f"{SCALE_FLOOR.get(n, 0.0)!r} {_weight(n, tolerance)!r}" for n in outputs),
             f"steps {case.steps} {case.step_size!r}"]
    for row in expected:
        time = float(row["time"])
        values = [time, *case.input_values(time).values(), *(float(row[n]) for n in outputs)]
        lines.append(" ".join(repr(v) for v in values))
    scenario_file = work / "scenario.txt"
    scenario_file.write_text("\n".join(lines) + "\n")
    return [str(library), fmi, token, str(scenario_file), str(unzipdir / "resources")]
