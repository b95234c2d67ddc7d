"""The native FMUs in a host with no Python in the process: ``tests/native_host.c``, compiled here,
loads each FMU's shared library (dlopen), runs the model's standard scenario against the Python
FMU's results (two instances side by side, a state stored, serialized and restored half way, a
refused step at the end), and does so again under valgrind: no invalid read or write, no leak."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest
from fmpy import extract, read_model_description

from driveline.catalog import MODELS
from fmu_harness.packaging import native, toolchain
from fmu_harness.runs.runner import FmuInstance
from fmu_harness.runs.scenario import scenario

HOST_SOURCE = Path(__file__).with_name("native_host.c")
VALGRIND = ("valgrind", "--error-exitcode=99", "--leak-check=full", "--show-leak-kinds=definite,indirect,possible",
            "--errors-for-leak-kinds=definite,indirect,possible")


@pytest.fixture(scope="module")
def host(tmp_path_factory: pytest.TempPathFactory) -> Path:
    executable = tmp_path_factory.mktemp("host") / "native_host"
    subprocess.run([*toolchain.host_compiler(), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2",
                    "-isystem", str(native.fmi_headers()), str(HOST_SOURCE), "-o", str(executable), "-ldl", "-lm"],
                   check=True, capture_output=True, text=True)
    return executable


# The standard scenario of every native model, and the modes it leaves out (its parameters
# are the spec's start values); CriticalSpeeds' String and Boolean parameters, a shipped layout
# found in the resources folder the host hands over.
MODES = {"TripodCoupling": [{"kinematics": 1, "mu": 0.05}, {"kinematics": 1, "seed_reactions": 1}],
         "CriticalSpeeds": [{"layout": "two_piece_propshaft"}, {"orders": "1,2,3,6", "shear": False}]}
#: Largest deviation from the Python FMU, relative to each output's largest magnitude: the damping
#: ratio's eigenvalue real part and the response near a resonance, 1e-9 (why: SIGNAL_TOLERANCE of
#: tests/test_native_fmus.py).
TOLERANCES = {"CriticalSpeeds": 1e-9}
RUNS = [(name, parameters) for name in native.native_models() for parameters in ({}, *MODES.get(name, ()))]


def _host_command(native_dir: Path, fmu_path, name: str, fmi: str, work: Path, parameters: dict) -> list[str]:
    """Extract the native FMU and write its scenario with ``parameters`` and the Python FMU's outputs
    as reference."""
    path = native.fmu_path(native_dir, name, fmi)
    unzipdir = Path(extract(str(path), unzipdir=str(work / "fmu")))
    description = read_model_description(str(path))
    token = description.instantiationToken if fmi == "3" else description.guid
    library = native.host_library(unzipdir, name, fmi)
    spec = MODELS[name].spec
    case = scenario(spec)
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
             f"tolerance {TOLERANCES.get(name, 1e-12)!r}", f"steps {case.steps} {case.step_size!r}"]
    for row in expected:
        time = float(row["time"])
        values = [time, *case.input_values(time).values(), *(float(row[n]) for n in outputs)]
        lines.append(" ".join(repr(v) for v in values))
    scenario_file = work / "scenario.txt"
    scenario_file.write_text("\n".join(lines) + "\n")
    return [str(library), fmi, token, str(scenario_file), str(unzipdir / "resources")]


@pytest.mark.parametrize("name, parameters", RUNS)
def test_host_runs_the_standard_scenario_like_the_python_fmu(host, native_dir, fmu_path, tmp_path, name, parameters,
                                                              fmi):
    done = subprocess.run([str(host), *_host_command(native_dir, fmu_path, name, fmi, tmp_path, parameters)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "checks passed" in done.stdout
    assert float(re.search(r"deviation (\S+),", done.stdout).group(1)) <= TOLERANCES.get(name, 1e-12)
    reason = "is not finite" if MODELS[name].spec.of("input") else "step size must be positive"
    assert reason in done.stderr  # the refused step's reason reached the host's logger


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed (Debian: apt-get install valgrind)")
@pytest.mark.parametrize("name, parameters", RUNS)
def test_host_under_valgrind_has_no_memory_errors_or_leaks(host, native_dir, fmu_path, tmp_path, name, parameters,
                                                           fmi):
    done = subprocess.run([*VALGRIND, str(host), *_host_command(native_dir, fmu_path, name, fmi, tmp_path,
                                                                parameters)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr[-3000:]
    assert "ERROR SUMMARY: 0 errors from 0 contexts" in done.stderr
    assert "definitely lost" not in done.stderr or re.search(r"definitely lost: 0 bytes", done.stderr)
