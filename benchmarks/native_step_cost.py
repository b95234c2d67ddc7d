"""Per-step cost of the native FMUs, through fmpy and from a C host, against their Python twins
and a no-physics native twin built the same way.

``python -m benchmarks.native_step_cost``: for each model with a C port and each FMI version,
builds the native FMU, its no-physics twin (``benchmarks/native_minimal.c`` with the model's
generated variable table: same variables, range checks and FMI traffic) and the Python FMU. Through
fmpy's low-level API each is stepped as in :mod:`benchmarks.step_cost` (one batched set of the Real
inputs, doStep, one batched get of the Real outputs; CPU time, best of alternating rounds). From C,
``benchmarks/native_step_timer.c`` (compiled here) loads the shared library with dlopen and times
the same three calls per step (CPU time, best of its rounds). The tripod runs in both kinematics
modes (:data:`benchmarks.step_cost.VARIANTS`) against the same twin.
"""

from __future__ import annotations

import subprocess
import tempfile
from pathlib import Path

from fmpy import extract, read_model_description

from benchmarks import report
from benchmarks.step_cost import ROUNDS, STEPS, VARIANTS, Stepper, best_alternating
from driveline.catalog import MODELS
from fmu_harness.packaging import build, native, toolchain
from fmu_harness.console import summary

HERE = Path(__file__).resolve().parent
C_STEPS, C_ROUNDS = 200_000, 7
ANALYSIS = "CriticalSpeeds"  # its step solves the damped model's response: apart in the summary


def compile_timer(folder: Path) -> Path:
    executable = folder / "native_step_timer"
    subprocess.run([*toolchain.host_compiler(), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2",
                    "-isystem", str(native.fmi_headers()), str(HERE / "native_step_timer.c"), "-o", str(executable),
                    "-ldl"], check=True)
    return executable


def c_host_cost(timer: Path, fmu: Path, fmi: str, work: Path, integers: dict[str, int],
                inputs_set: list[str] | None = None, outputs_read: list[str] | None = None) -> float:
    """Nanoseconds per step of ``fmu`` from the C timer, with the Integer parameters ``integers``,
    setting the inputs ``inputs_set`` and reading the outputs ``outputs_read`` (None: all Real ones)."""
    unzipdir = Path(extract(str(fmu), unzipdir=str(work)))
    description = read_model_description(str(fmu))
    token = description.instantiationToken if fmi == "3" else description.guid
    real = ("Real", "Float64")
    references = {v.name: v.valueReference for v in description.modelVariables}
    inputs = [v.valueReference for v in description.modelVariables if v.causality == "input" and v.type in real] \
        if inputs_set is None else [references[name] for name in inputs_set]
    outputs = [v.valueReference for v in description.modelVariables if v.causality == "output" and v.type in real] \
        if outputs_read is None else [references[name] for name in outputs_read]
    library = native.host_library(unzipdir, description.coSimulation.modelIdentifier, fmi)
    done = subprocess.run([str(timer), str(library), fmi, token, description.defaultExperiment.stepSize,
                           str(C_STEPS), str(C_ROUNDS), " ".join(map(str, inputs)), " ".join(map(str, outputs)),
                           str((unzipdir / "resources").absolute()),
                           " ".join(f"{references[name]}={value}" for name, value in integers.items())],
                          check=True, capture_output=True, text=True)
    return float(done.stdout)


def main() -> None:
    args = report.parser(summary(__doc__)).parse_args()
    measurement = report.Measurement()
    lines = ["| FMU | FMI | variant | native via fmpy µs | no-physics twin via fmpy µs | ratio | Python FMU via fmpy µs "
             "| Python / native | native from C ns | no-physics twin from C ns |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    ratios: dict[str, list[float]] = {"twin": [], "analysis twin": [], "Python": [], "C": []}
    with tempfile.TemporaryDirectory() as folder:
        dest = Path(folder)
        timer = compile_timer(dest)
        for fmi in ("2", "3"):
            for name in native.native_models():
                inputs = [v.name for v in MODELS[name].spec.of("input")]
                fmu = native.build(name, dest, fmi, release=False)
                twin = native.build(name, dest / "twin", fmi, HERE / "native_minimal.c", release=False)
                python_fmu = build(name, dest / "python", fmi)
                for variant, values in VARIANTS.get(name, {"": {}}).items():
                    ours, floor, python = best_alternating([Stepper(path, values, inputs)
                                                            for path in (fmu, twin, python_fmu)])
                    c_ours = c_host_cost(timer, fmu, fmi, dest / f"c_{name}_{fmi}_{variant}", values)
                    c_floor = c_host_cost(timer, twin, fmi, dest / f"c_twin_{name}_{fmi}_{variant}", values)
                    ratios["analysis twin" if name == ANALYSIS else "twin"].append(ours / floor)
                    ratios["Python"].append(python / ours)
                    ratios["C"].append(c_ours)
                    lines.append(f"| {name} | {fmi}.0 | {variant} | {ours:.2f} | {floor:.2f} | {ours / floor:.2f} "
                                 f"| {python:.1f} | {python / ours:.1f} | {c_ours:.0f} | {c_floor:.0f} |")
    span = lambda values, digits: f"{min(values):.{digits}f} to {max(values):.{digits}f}"  # noqa: E731
    lines.append(f"\nThrough fmpy a native step costs {span(ratios['twin'], 2)} times its no-physics twin's, "
                 f"{ANALYSIS} {span(ratios['analysis twin'], 2)} times, and the Python FMU's "
                 f"{span(ratios['Python'], 1)} times the native one's; from C a step costs "
                 f"{span([ns / 1e3 for ns in ratios['C']], 2)} µs.")
    report.publish("benchmark-native-step-cost", measurement.stamp(
        f"CPU time, via fmpy best of {ROUNDS} alternating rounds of {STEPS} steps, from C best of {C_ROUNDS} rounds "
        f"of {C_STEPS} steps"), "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
