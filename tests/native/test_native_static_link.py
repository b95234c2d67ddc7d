"""Two native FMUs linked statically into one program, told apart by the FMI function prefix
(``FMI2_FUNCTION_PREFIX``/``FMI3_FUNCTION_PREFIX``, one per model): each model's carried sources
are compiled with its prefix and prelinked into one object whose only global symbols are its
prefixed FMI functions (``cc -r``, then ``objcopy``: the shared layer's internal functions have
the same names in every model), and a C program calls both models' functions: instantiate,
initialise, one step, get an output, free. The outputs equal those of the FMUs' shared libraries."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from fmpy import extract, read_model_description, simulate_fmu

from fmu_harness.packaging import native, toolchain

MODELS = ("CardanJoint", "SpeedSource")

HOST = {
    "2": """
#define CALLS(P) \\
    extern fmi2InstantiateTYPE P##fmi2Instantiate; extern fmi2SetupExperimentTYPE P##fmi2SetupExperiment; \\
    extern fmi2EnterInitializationModeTYPE P##fmi2EnterInitializationMode; \\
    extern fmi2ExitInitializationModeTYPE P##fmi2ExitInitializationMode; extern fmi2DoStepTYPE P##fmi2DoStep; \\
    extern fmi2GetRealTYPE P##fmi2GetReal; extern fmi2FreeInstanceTYPE P##fmi2FreeInstance; \\
    static int run_##P(const char *token, unsigned int vr, double h, double *value) \\
    { \\
        fmi2Component c = P##fmi2Instantiate(#P, fmi2CoSimulation, token, "", &callbacks, fmi2False, fmi2False); \\
        int ok = c != NULL && P##fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK && \\
                 P##fmi2EnterInitializationMode(c) == fmi2OK && P##fmi2ExitInitializationMode(c) == fmi2OK && \\
                 P##fmi2DoStep(c, 0.0, h, fmi2True) == fmi2OK && P##fmi2GetReal(c, &vr, 1, value) == fmi2OK; \\
        if (c != NULL) P##fmi2FreeInstance(c); \\
        return ok; \\
    }
#include "fmi2FunctionTypes.h"
static void logger(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...)
{
    (void)e; (void)s; (void)c;
    fprintf(stderr, "%s: %s\\n", n, m);
}
static const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
""",
    "3": """
#define CALLS(P) \\
    extern fmi3InstantiateCoSimulationTYPE P##fmi3InstantiateCoSimulation; \\
    extern fmi3EnterInitializationModeTYPE P##fmi3EnterInitializationMode; \\
    extern fmi3ExitInitializationModeTYPE P##fmi3ExitInitializationMode; extern fmi3DoStepTYPE P##fmi3DoStep; \\
    extern fmi3GetFloat64TYPE P##fmi3GetFloat64; extern fmi3FreeInstanceTYPE P##fmi3FreeInstance; \\
    static int run_##P(const char *token, unsigned int vr, double h, double *value) \\
    { \\
        fmi3Boolean event, terminate, early; fmi3Float64 last; \\
        fmi3Instance c = P##fmi3InstantiateCoSimulation(#P, token, NULL, fmi3False, fmi3False, fmi3False, fmi3False, \\
                                                        NULL, 0, NULL, NULL, NULL); \\
        int ok = c != NULL && P##fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) == fmi3OK && \\
                 P##fmi3ExitInitializationMode(c) == fmi3OK && \\
                 P##fmi3DoStep(c, 0.0, h, fmi3True, &event, &terminate, &early, &last) == fmi3OK && \\
                 P##fmi3GetFloat64(c, &vr, 1, value, 1) == fmi3OK; \\
        if (c != NULL) P##fmi3FreeInstance(c); \\
        return ok; \\
    }
#include "fmi3FunctionTypes.h"
""",
}


def _program(fmi: str, cases: dict[str, tuple[str, int, float]]) -> str:
    """The C program: each model's calls under its prefix, then one run of each, printing its output."""
    lines = ["#include <stdio.h>", "#include <stdlib.h>", HOST[fmi]]
    lines += [f"CALLS({name}_)" for name in cases]
    lines += ["int main(void)", "{", "    double value;", "    int failed = 0;"]
    for name, (token, vr, h) in cases.items():
        lines += [f'    if (run_{name}_("{token}", {vr}u, {h!r}, &value)) printf("{name} %.17g\\n", value);',
                  "    else failed = 1;"]
    lines += ["    return failed;", "}", ""]
    return "\n".join(lines)


@pytest.mark.skipif(shutil.which("objcopy") is None, reason="prelinking needs objcopy (Debian: apt-get install binutils)")
def test_two_fmus_with_prefixes_link_into_one_program(native_dir, tmp_path, fmi):
    compiler = toolchain.host_compiler()
    cases, objects, expected = {}, [], {}
    for name in MODELS:
        fmu = native.fmu_path(native_dir, name, fmi)
        unzipdir = Path(extract(str(fmu), unzipdir=str(tmp_path / name)))
        description = read_model_description(str(fmu))
        output = next(v for v in description.modelVariables if v.causality == "output" and v.type in ("Real", "Float64"))
        step = float(description.defaultExperiment.stepSize)
        cases[name] = (description.guid if fmi == "2" else description.instantiationToken, output.valueReference, step)
        sources = sorted((unzipdir / "sources").rglob("*.c"))
        compiled = []
        for source in sources:
            compiled.append(tmp_path / name / f"{source.stem}.o")
            subprocess.run([*compiler, *toolchain.CFLAGS, f"-DFMI{fmi}_FUNCTION_PREFIX={name}_",
                            "-I", str(unzipdir / "sources"), "-isystem", str(native.fmi_headers()), "-c", str(source),
                            "-o", str(compiled[-1])], check=True, capture_output=True, text=True)
        objects.append(tmp_path / f"{name}.o")
        subprocess.run([*compiler, "-r", "-nostdlib", *map(str, compiled), "-o", str(objects[-1])], check=True,
                       capture_output=True, text=True)
        subprocess.run(["objcopy", "--wildcard", f"--keep-global-symbol={name}_fmi{fmi}*", str(objects[-1])],
                       check=True, capture_output=True, text=True)
        result = simulate_fmu(str(fmu), stop_time=step, step_size=step, output_interval=step, output=[output.name])
        expected[name] = float(result[output.name][-1])
    program = tmp_path / "two_fmus.c"
    program.write_text(_program(fmi, cases))
    executable = tmp_path / "two_fmus"
    subprocess.run([*compiler, "-std=c99", "-Wall", "-Wextra", "-Werror", "-isystem", str(native.fmi_headers()),
                    str(program), *map(str, objects), "-o", str(executable), "-lm"], check=True, capture_output=True,
                   text=True)
    done = subprocess.run([str(executable)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    got = {line.split()[0]: float(line.split()[1]) for line in done.stdout.splitlines()}
    assert got == pytest.approx(expected, rel=1e-12, abs=0.0)
