"""Cost of one structural analysis of the CriticalSpeeds model (what a tunable change costs).

``python -m benchmarks.critical_speeds_analysis``: ``driveline.rotor.model.analyse`` (three
critical speeds and the finite-element check, Campbell table from 41 speeds, order resonances
1, 2, 3 up to twice ``omega_max = 1500 rad/s``) and its parts, for the one-piece tube of the
FMU's defaults, the shipped two-piece example, and the same tube cut into 20 equal segments with
a joint mass at every node (the issue's targets: 50 ms and 0.5 s). A change of ``orders`` costs
the resonances alone, one of ``omega_in_max`` the whirl table and the resonances. CPU time of the
process, best of five runs after a warm-up.

The second table is the whole initialisation of the FMUs (parameters set, the analysis with the
unbalance outputs, first outputs), native (C) and Python, FMI 2.0, for the same drivelines given
as the FMU's one-piece parameters or as a ``layout`` (the native target: 20 ms for the tube).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from fmpy import extract, read_model_description

from benchmarks import report
from benchmarks.timing import best_of
from driveline.rotor import (
    Bearing,
    ConcentratedMass,
    Driveline,
    ShaftSegment,
    example_path,
    load_driveline,
    one_piece_shaft,
)
from driveline.rotor.model import analyse, analyse_structure, resonances, whirl_table
from fmu_harness.packaging import build as build_fmu
from fmu_harness.packaging import native
from fmu_harness.runs.runner import FmuInstance
from fmu_harness.console import summary

ORDERS, OMEGA_MAX = (1, 2, 3), 1500.0
MODEL = "CriticalSpeeds"


def one_piece() -> Driveline:
    return one_piece_shaft(1.4, 0.0762, 0.0729, 2.1e11, 7850.0, 2.5, 0.004, 0.002, 1e7)


def twenty_segments() -> Driveline:
    segments = [ShaftSegment(1.4 / 20, 0.0762, 0.0729)] * 20
    masses = [ConcentratedMass(node, 0.1, 0.0002, 0.0001) for node in range(21)]
    return Driveline(segments, masses, [Bearing(0, 1e7), Bearing(20, 1e7)])


CASES = {
    "one-piece tube": (one_piece, 0.05),
    "two-piece example": (lambda: load_driveline(example_path("two_piece_propshaft")), None),
    "20 segments": (twenty_segments, 0.5),
}


def analysis_table(update_docs: bool) -> None:
    measurement = report.Measurement()
    lines = ["| driveline | structure [s] | whirl table [s] | resonances [s] | analysis [s] | target [s] |",
             "|---|---|---|---|---|---|"]
    for name, (build, target) in CASES.items():
        driveline = build()
        structure = analyse_structure(driveline)
        parts = (lambda: analyse_structure(driveline), lambda: whirl_table(structure, OMEGA_MAX),
                 lambda: resonances(driveline, ORDERS, OMEGA_MAX), lambda: analyse(driveline, ORDERS, OMEGA_MAX))
        seconds = []
        for part in parts:
            part()  # warm-up
            seconds.append(best_of(part, repeats=5, clock=time.process_time))
        lines.append(f"| {name} | " + " | ".join(f"{s:.3f}" for s in seconds) + f" | {target or ''} |")
    report.publish("benchmark-critical-speeds-analysis", measurement.stamp("CPU time, best of five after a warm-up"),
                   "\n".join(lines), update_docs)


#: The drivelines above as FMU parameters: the defaults, a shipped layout, a layout file (20 segments).
TWENTY_SEGMENTS_TOML = f"""[[segments]]
length = {1.4 / 20!r}
outer_diameter = 0.0762
inner_diameter = 0.0729
youngs_modulus = 2.1e11
density = 7850.0
shear = false
""" * 20 + "".join(f"""
[[masses]]
node = {node}
mass = 0.1
polar_inertia = 0.0002
diametral_inertia = 0.0001
""" for node in range(21)) + """
[[bearings]]
node = 0
stiffness = 1e7

[[bearings]]
node = 20
stiffness = 1e7
"""


def initialisation_seconds(path: Path, parameters: dict[str, object], work: Path) -> float:
    """CPU time of one initialisation of the FMU at ``path`` with ``parameters`` (best of five). Each
    call extracts the FMU into a folder of its own: writing over a library still mapped (a Python
    FMU's stays loaded after its instances are freed) would crash the process."""
    description = read_model_description(str(path))
    unzipdir = extract(str(path), unzipdir=tempfile.mkdtemp(dir=work))

    def initialise() -> None:
        instance = FmuInstance(path, unzipdir=unzipdir, description=description)
        instance.initialize(parameters)
        instance.close()

    initialise()  # warm-up
    return best_of(initialise, repeats=5, clock=time.process_time)


def fmu_table(update_docs: bool) -> None:
    measurement = report.Measurement()
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        layout = work / "twenty_segments.toml"
        layout.write_text(TWENTY_SEGMENTS_TOML)
        families = {"native": native.build(MODEL, work / "models", release=False),
                    "Python": build_fmu(MODEL, work / "models")}
        cases = {"one-piece tube (the defaults)": {},
                 "two-piece example (`layout = \"two_piece_propshaft\"`)": {"layout": "two_piece_propshaft"},
                 "20 segments with 21 joint masses (a layout file)": {"layout": str(layout)}}
        lines = ["| driveline | native FMU [ms] | Python FMU [ms] | Python / native |", "|---|---|---|---|"]
        for name, parameters in cases.items():
            native_s, python_s = (initialisation_seconds(path, parameters, work) for path in families.values())
            lines.append(f"| {name} | {native_s * 1e3:.1f} | {python_s * 1e3:.0f} | {python_s / native_s:.1f} |")
    report.publish("benchmark-critical-speeds-initialisation", measurement.stamp(
        "FMI 2.0, CPU time, best of five after a warm-up"), "\n".join(lines), update_docs)


if __name__ == "__main__":
    update_docs = report.parser(summary(__doc__)).parse_args().update_docs
    analysis_table(update_docs)
    print()
    fmu_table(update_docs)
