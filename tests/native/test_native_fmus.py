"""The native (C) FMUs against their Python twins, through fmpy, both FMI versions: a clean and
identical description, a binary needing only libc and libm, the carried sources, equal outputs, the
same refusals word for word, and misuse answered with Error (never Fatal, never a crash). What both
families promise alike (refusals, state, reset, random runs against the core) is tested once for
both, in ``tests/fmu/`` with the ``family`` fixture."""

from __future__ import annotations

import math
import shutil
import struct
import subprocess
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu

from driveline.catalog import MODELS
from fmu_harness.checks import interop
from fmu_harness.packaging import native, toolchain
from fmu_harness.runs.runner import FmuInstance, StepRefused
from fmu_harness.runs.scenario import scenario
from support.alongside_the_core import expect_refused_parameters
from support.native_agreement import TOLERANCE, beyond_tolerance, deviation, refusals, up_to_the_toml_reason
from support.fmu_documentation import assert_documentation

NATIVE = native.native_models()
VERSIONS = ("2", "3")
def _native(native_dir: Path, name: str, fmi: str) -> Path:
    return native.fmu_path(native_dir, name, fmi)


def _standard_run(path: Path, name: str, **open_options) -> np.ndarray:
    case = scenario(MODELS[name].spec)
    with FmuInstance(path, **open_options) as fmu:
        fmu.initialize(case.input_values(0.0))
        return fmu.run(case.stop_time, case.step_size, case.signals())


def test_every_model_has_its_c_port_built(native_dir):
    """A model whose folder holds a library is native once every module its headers list is there:
    CriticalSpeeds' rotor library, PowertrainMounts'; today every catalog model is."""
    for name, modules in (("CriticalSpeeds", {"layout.c", "transfer.c", "roots.c", "spline.c", "campbell.c", "fem.c",
                                              "damped.c"}),
                          ("PowertrainMounts", {"layout.c", "characteristic.c", "rubber.c", "forces.c", "exact_step.c",
                                               "implicit_step.c", "dense.c"})):
        folder = native.model_folder(name)
        assert native.library_modules(name) == sorted(path.name for path in folder.glob("*.c")
                                                      if path != native.model_source(name))
        assert modules <= set(native.library_modules(name))
    assert NATIVE == list(MODELS)
    built = {path.relative_to(native_dir).as_posix() for path in native_dir.rglob("*.fmu")}
    packages = {f"{native.SUBDIR[fmi]}/{name}.fmu" for name in interop.CONTAINERS for fmi in VERSIONS}
    # the importer matrix writes the packages as one FMU beside the models when it runs first
    assert built - packages == {f"{native.SUBDIR[fmi]}/{name}.fmu" for name in NATIVE for fmi in VERSIONS}


@pytest.mark.parametrize("name", NATIVE)
def test_passes_fmpy_validate_and_fmutool_check(native_dir, name, fmi):
    path = _native(native_dir, name, fmi)
    assert validate_fmu(str(path)) == []
    assert interop._fmutool_check(path) == interop.Outcome("pass")


@pytest.mark.parametrize("name", NATIVE)
def test_binary_needs_only_libc_and_libm_and_exports_only_fmi(native_dir, tmp_path, name, fmi):
    with zipfile.ZipFile(_native(native_dir, name, fmi)) as archive:
        binaries = [member for member in archive.namelist() if member.startswith("binaries/")]
        assert len(binaries) == 1
        library = tmp_path / Path(binaries[0]).name
        library.write_bytes(archive.read(binaries[0]))
    dynamic = subprocess.run(["readelf", "-d", str(library)], capture_output=True, text=True, check=True).stdout
    needed = {line.split("[")[1].rstrip("]") for line in dynamic.splitlines() if "(NEEDED)" in line}
    assert "libc.so.6" in needed and needed <= {"libc.so.6", "libm.so.6"}  # libm only if the model calls it
    symbols = subprocess.run(["nm", "-D", "--defined-only", str(library)], capture_output=True, text=True,
                             check=True).stdout.split()[2::3]
    assert symbols and all(symbol.startswith(f"fmi{fmi}") for symbol in symbols)


def _fields(item: object) -> dict:
    return {slot: getattr(item, slot) for slot in type(item).__slots__ if slot != "__weakref__"} if item else {}


def _described(path: Path) -> dict:
    """Everything a host reads from a model description, except token, generator and Model Exchange
    (the native FMUs': the states' derivatives, and the states that are locals among the initial unknowns,
    tests/native/test_native_model_exchange.py)."""
    d = read_model_description(str(path))
    derivatives = {u.variable.name for u in d.derivatives}
    local_states = {u.variable.derivative.name for u in d.derivatives if u.variable.derivative.causality == "local"}
    d.modelVariables = [v for v in d.modelVariables if v.name not in derivatives]
    d.initialUnknowns = [u for u in d.initialUnknowns if u.variable.name not in derivatives | local_states]
    fields = ("name", "valueReference", "causality", "variability", "description", "type", "unit", "displayUnit",
              "min", "max", "start", "initial")
    return {
        "model": (d.modelName, d.description, d.fmiVersion, d.coSimulation.modelIdentifier),
        "variables": [tuple(getattr(v, f) for f in fields) for v in d.modelVariables],
        "units": [(u.name, _fields(u.baseUnit), [(x.name, x.factor, x.offset) for x in u.displayUnits])
                  for u in d.unitDefinitions],
        "experiment": _fields(d.defaultExperiment),
        "outputs": [v.variable.name for v in d.outputs],
        "initial_unknowns": [v.variable.name for v in d.initialUnknowns],
        "capabilities": {k: getattr(d.coSimulation, k) for k in (
            "canHandleVariableCommunicationStepSize", "canGetAndSetFMUstate", "canSerializeFMUstate")},
    }


@pytest.mark.parametrize("name", NATIVE)
def test_description_is_the_python_fmus(native_dir, fmu_path, name, fmi):
    python_description, native_description = (_described(path) for path in (fmu_path(name, fmi),
                                                                             _native(native_dir, name, fmi)))
    assert native_description == python_description
    with zipfile.ZipFile(_native(native_dir, name, fmi)) as archive:
        description = archive.read("modelDescription.xml").decode()
    for category in ("logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal", "logAll"):
        assert f'name="{category}"' in description


@pytest.mark.parametrize("name", NATIVE)
def test_every_start_value_is_the_specs_bit_for_bit_in_both_families(native_dir, fmu_path, name, fmi):
    """One number, one text: both families write a start as the spec's repr (pythonfmu alone wrote
    16 digits: omega_in 209.4395102393195 against the native 209.43951023931953)."""
    spec = MODELS[name].spec
    python, native = (read_model_description(str(path)) for path in (fmu_path(name, fmi), _native(native_dir, name, fmi)))
    written = [{v.name: v.start for v in d.modelVariables if v.causality != "independent"
                and not v.name.startswith("der(")} for d in (python, native)]  # the native Model Exchange's
    assert written[0] == written[1]
    for variable in spec.variables:
        text = written[1][variable.name]
        if variable.causality in ("output", "local"):
            assert text is None, variable.name
        elif variable.type == "Real":
            assert struct.pack("<d", float(text)) == struct.pack("<d", variable.start), (variable.name, text)
        elif variable.type == "Integer":
            assert int(text) == variable.start, variable.name


@pytest.mark.parametrize("name", NATIVE)
def test_standard_scenario_matches_the_python_fmu(native_dir, fmu_path, name, fmi):
    assert beyond_tolerance(_standard_run(fmu_path(name, fmi), name), _standard_run(_native(native_dir, name, fmi), name)) == {}


MODES = {  # parameters of the modes the standard scenario (spec start values) leaves out
    "TripodCoupling": [
        {"kinematics": 1},
        {"kinematics": 1, "mu": 0.05},
        {"kinematics": 1, "mu": 0.02, "v_slip": 1e-2, "seed_reactions": 1, "phi_in_start": 0.4},
        {"seed_reactions": 1},
        {"kinematics": 1, "beta_max": math.radians(60.0), "r": 0.07},
        {"kinematics": 1, "mu": 0.05, "T_load": -500.0},  # coast
        {"kinematics": 1, "beta_dot": 2.0, "beta_ddot": -40.0},
        {"beta_dot": 2.0, "beta_ddot": -40.0},
        {"kinematics": 1, "beta_rate": 1},  # rates from the scenario's beta samples
        # the moving housing: the bend plane turned and turning, the spider plunging, every tripod type
        {"psi": 0.7, "psi_dot": 4.0, "psi_ddot": -30.0, "seed_reactions": 1},
        {"kinematics": 1, "mu": 0.05, "psi": 0.7, "psi_dot": 4.0, "psi_ddot": -30.0, "plunge_dot": 0.02},
        {"kinematics": 1, "mu": 0.05, "tripod_type": 1, "psi": -2.0, "psi_dot": -3.0, "plunge_dot": -0.01},
        {"kinematics": 1, "mu": 0.05, "tripod_type": 2, "psi": 0.7, "psi_ddot": 30.0, "plunge_dot": 0.02},
    ],
}


def _mode_run(path: Path, name: str, parameters: dict) -> np.ndarray:
    """The standard scenario with ``parameters``, a load and a speed rate on top of the spec's start
    values (``parameters`` may hold inputs too, held over the run)."""
    case = scenario(MODELS[name].spec)
    held = {"T_load": 500.0, "alpha_in": 800.0, **{k: v for k, v in parameters.items() if k in case.signals()}}
    with FmuInstance(path) as fmu:
        fmu.initialize({**parameters, **case.input_values(0.0), **held})
        return fmu.run(case.stop_time, case.step_size, {k: v for k, v in case.signals().items() if k not in held})


@pytest.mark.parametrize("name, parameters", [(name, p) for name, modes in MODES.items() if name in NATIVE
                                              for p in modes])
def test_every_mode_matches_the_python_fmu(native_dir, fmu_path, name, parameters, fmi):
    """Exact kinematics, friction and the seed's reactions: the standard scenario in each mode."""
    reference = _mode_run(fmu_path(name, fmi), name, parameters)
    assert deviation(reference, _mode_run(_native(native_dir, name, fmi), name, parameters)) <= TOLERANCE


@pytest.mark.skipif("TripodCoupling" not in NATIVE, reason="the tripod has no C port")
def _half_way_state(path: Path, parameters: dict) -> tuple[float, bytes, np.ndarray]:
    """The standard scenario with ``parameters``: the time and serialized state half way, and the
    second half run on from there."""
    case = scenario(MODELS[read_model_description(str(path)).modelName].spec)
    with FmuInstance(path) as fmu:
        fmu.initialize({**parameters, **case.input_values(0.0)})
        fmu.run(case.stop_time / 2, case.step_size, case.signals())
        middle, state = fmu.time, fmu.get_state()
        serialized = fmu.serialize_state(state)
        fmu.free_state(state)
        return middle, serialized, fmu.run(case.stop_time, case.step_size, case.signals())


def test_the_exact_solvers_warm_start_is_part_of_the_state(native_dir, fmi):
    """A state stored half way through an exact run with friction, restored from its bytes into an
    instance whose solver was warm-started elsewhere, continues bit for bit."""
    path, parameters = _native(native_dir, "TripodCoupling", fmi), {"kinematics": 1, "mu": 0.05}
    case = scenario(MODELS["TripodCoupling"].spec)
    middle, serialized, reference = _half_way_state(path, parameters)
    with FmuInstance(path) as other:
        other.initialize({**parameters, "beta": 0.2, "phi_in_start": 1.0})
        other.run(case.stop_time / 3, case.step_size)
        restored = other.deserialize_state(serialized)
        other.set_state(restored)
        other.free_state(restored)
        other.time = middle
        assert other.run(case.stop_time, case.step_size, case.signals()).tobytes() == reference.tobytes()


#: A C program that loads a shared library (every symbol bound at once) and links no libm itself:
#: a library that needs libm and does not say so fails to load in it.
LOADER = """#include <dlfcn.h>
#include <stdio.h>
int main(int argc, char **argv)
{
    void *library = argc == 2 ? dlopen(argv[1], RTLD_NOW | RTLD_LOCAL) : NULL;
    if (library == NULL) {
        fprintf(stderr, "%s\\n", dlerror());
        return 1;
    }
    return dlclose(library);
}
"""


@pytest.fixture(scope="module")
def loader(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("loader")
    (folder / "loader.c").write_text(LOADER)
    subprocess.run([*toolchain.host_compiler(), "-std=c99", "-Wall", "-Werror", str(folder / "loader.c"), "-o",
                    str(folder / "loader"), "-ldl"], check=True, capture_output=True, text=True)
    return folder / "loader"


@pytest.mark.skipif(shutil.which("cmake") is None, reason="rebuilding from the carried sources needs cmake")
@pytest.mark.parametrize("name", NATIVE)
def test_carried_sources_rebuild_with_fmpy(native_dir, tmp_path, loader, name, fmi):
    """What a user of another platform does: fmpy's build_platform_binary (CMake) from the FMU's
    sources alone, with the documented options (libm, which the FMU's FMI 3.0 build description
    names); the rebuilt binary loads in a program that has not loaded libm, and gives the shipped
    one's results bit for bit."""
    from fmpy.build import build_platform_binary

    unzipdir = Path(extract(str(_native(native_dir, name, fmi)), unzipdir=str(tmp_path / "fmu")))
    shutil.rmtree(unzipdir / "binaries")
    (tmp_path / "build").mkdir()
    build_platform_binary(unzipdir, build_dir=tmp_path / "build", cmake_options=dict(native.REBUILD_CMAKE_OPTIONS))
    loaded = subprocess.run([str(loader), str(native.host_library(unzipdir, name, fmi))], capture_output=True, text=True)
    assert loaded.returncode == 0, loaded.stderr
    if fmi == "3":
        libraries = ET.parse(unzipdir / "sources" / "buildDescription.xml").getroot().iter("Library")
        assert [library.get("name") for library in libraries] == ["m"]
    rebuilt = _standard_run(_native(native_dir, name, fmi), name, unzipdir=str(unzipdir))
    assert rebuilt.tobytes() == _standard_run(_native(native_dir, name, fmi), name).tobytes()


@pytest.mark.parametrize("name", NATIVE)
def test_fmu_carries_its_documentation_and_licence(native_dir, name, fmi):
    assert_documentation(_native(native_dir, name, fmi), name)


DECLARED_RULES = [  # every kind of declared bound and relation the native models have, broken once
    ("CardanJoint", {"beta": math.radians(46.0)}),
    ("CardanJoint", {"beta_max": 0.5 * math.pi}),
    ("CardanJoint", {"beta_max": -0.1, "beta": 2.0}),
    ("UniversalReducer", {"z1": 29}),
    ("UniversalReducer", {"z2": 0}),
    ("UniversalReducer", {"module": 0.0}),
    ("UniversalReducer", {"e": -1e-3, "r_shaft": -0.0}),
    ("UniversalReducer", {"intersection_angle_min": 2.0, "intersection_angle_max": 1.9}),
    ("UniversalReducer", {"intersection_angle_max": math.pi}),
    ("UniversalReducer", {"intersection_angle": 1.5}),
    ("UniversalReducer", {"intersection_angle": 3.0}),
    ("SpeedSource", {"sine_amplitude": -1.0, "sine_frequency": math.inf}),
    ("TripodCoupling", {"r": 0.0}),
    ("TripodCoupling", {"l": 0.02}),
    ("TripodCoupling", {"beta_max": 1.1, "kinematics": 2}),
    ("TripodCoupling", {"beta": math.radians(50.0)}),
    ("TripodCoupling", {"mu": 0.05}),  # the model's own check: friction needs the exact kinematics
    ("TripodCoupling", {"mu": 2.0**-24}),  # repr 5.960464477539063e-08: not printf's nearest 16 digits
]


@pytest.mark.parametrize("name, values", [case for case in DECLARED_RULES if case[0] in NATIVE])
def test_declared_bounds_and_relations_refuse_word_for_word(native_dir, name, values, fmi):
    """The checks generated from the spec give the Python core's messages exactly: at
    initialisation, where parameters or start values are refused."""
    core = MODELS[name]()
    for variable, value in values.items():
        setattr(core, variable, value)
    errors = core.parameter_errors() or core.initialize(0.0)
    with FmuInstance(_native(native_dir, name, fmi)) as fmu:
        if errors:
            return expect_refused_parameters(fmu, values, errors)
        errors = core.step(0.0, 1e-3)
        assert errors
        fmu.initialize(values)
        with pytest.raises(StepRefused) as refused:
            fmu.step(1e-3)
    assert refused.value.messages == errors


ARITHMETIC_FAILURES = [  # where the Python core fails arithmetically, the C port refuses with its words
    ("TripodCoupling", {"phi_in_start": 1e308}),
    ("TripodCoupling", {"phi_in_start": 1e308, "kinematics": 1}),
    ("TripodCoupling", {"phi_in_start": 6e307, "kinematics": 1, "seed_reactions": 1}),
    ("TripodCoupling", {"kinematics": 1, "mu": 5.0, "T_load": 500.0}),
    ("TripodCoupling", {"kinematics": 1, "mu": 0.05, "v_slip": 1e-300, "omega_in": 1e150}),
    ("TripodCoupling", {"kinematics": 1, "r": 0.6999, "beta": 1.0, "beta_max": 1.04}),
    ("TripodCoupling", {"kinematics": 1, "omega_in": 1e200}),
    ("TripodCoupling", {"omega_in": 1e300}),
    ("TripodCoupling", {"T_load": 1e307}),
    ("TripodCoupling", {"T_load": 1e307, "kinematics": 1}),
    ("TripodCoupling", {"T_load": 1e306}),
    ("TripodCoupling", {"psi": 1e308}),  # the bend plane's angle: the pose at phi_in - psi
    ("TripodCoupling", {"psi": -1e308, "kinematics": 1}),
    ("TripodCoupling", {"psi_dot": 1e200, "kinematics": 1, "mu": 0.05}),  # the speed relative to the plane
]


@pytest.mark.parametrize("name, values", [case for case in ARITHMETIC_FAILURES if case[0] in NATIVE])
def test_arithmetic_failures_refuse_word_for_word(native_dir, name, values, fmi):
    test_declared_bounds_and_relations_refuse_word_for_word(native_dir, name, values, fmi)


# -- misuse: Error with a reason, never Fatal, never a crash --------------------------------------------


def _error(call, *args) -> int:
    with pytest.raises(FMICallException) as failed:
        call(*args)
    return failed.value.status


def test_misuse_returns_error_with_a_reason(native_dir, fmi):
    path = _native(native_dir, "CardanJoint", fmi)
    fmi3 = fmi == "3"
    cases = {
        "unknown value reference": lambda f: (f.getFloat64 if fmi3 else f.getReal)([999]),
        "wrong type": lambda f: (f.getInt32 if fmi3 else f.getInteger)([0]),
        "string on a Real": lambda f: f.setString([0], ["x"]),
        "set an output": lambda f: (f.setFloat64 if fmi3 else f.setReal)([6], [1.0]),
        "step before initialisation": lambda f: f.doStep(0.0, 1e-3),
    }
    for case, call in cases.items():
        with FmuInstance(path) as fmu:
            assert _error(call, fmu.fmu) == 3, case  # fmi2Error / fmi3Error
            assert fmu.log and fmu.log[-1].status == "Error" and fmu.log[-1].category == "logStatusError", case
            # after an Error the instance takes reset and, from there, a whole run again
            fmu.reset()
            fmu.initialize()
            fmu.step(1e-3)
    with FmuInstance(path) as fmu:
        fmu.initialize()
        fixed = fmu.variables["beta_max"].valueReference
        assert _error((fmu.fmu.setFloat64 if fmi3 else fmu.fmu.setReal), [fixed], [0.5]) == 3
        assert "fixed" in fmu.log[-1].message
    with FmuInstance(path) as fmu:
        fmu.initialize()
        fmu.step(1e-3)
        fmu.fmu.terminate()
        assert _error(fmu.fmu.doStep, 1e-3, 1e-3) == 3
    with FmuInstance(path) as fmu:
        fmu.initialize()
        assert _error(fmu.fmu.doStep, math.nan, 1e-3) == 3
        assert "not finite" in fmu.log[-1].message


@pytest.mark.parametrize("name", NATIVE)
def test_a_step_changes_the_outputs_and_locals_alone(native_dir, name, fmi):
    """A refused step is undone by restoring the outputs, locals and internal slots alone (StepUndo in
    fmu_instance.h): every parameter and input, Strings included, reads the same after steps as before."""
    step = MODELS[name].spec.default_experiment.step_size
    with FmuInstance(_native(native_dir, name, fmi)) as fmu:
        fmu.initialize()
        names = [v.name for v in fmu.description.modelVariables if v.causality in ("parameter", "input")]
        before = fmu.get(names)
        for _ in range(3):
            fmu.step(step)
        assert dict(zip(names, fmu.get(names))) == dict(zip(names, before))


def test_a_wrong_token_is_refused_at_instantiation(native_dir, tmp_path, fmi):
    path = _native(native_dir, "SpeedSource", fmi)
    unzipdir = extract(str(path), unzipdir=str(tmp_path))
    description = read_model_description(str(path))
    if fmi == "3":
        description.instantiationToken = "{wrong}"
    else:
        description.guid = "{wrong}"
    from fmu_harness.runs.runner import LoggedInstance

    logged: list[str] = []
    with pytest.raises(Exception, match="nstantiat"):  # fmpy's logger proxy is process-global: the router's
        LoggedInstance(unzipdir, description, "CoSimulation", "instance", logged.append)
    assert any("is not this FMU's" in message for message in logged)


def test_a_discarded_step_asks_to_stop_and_a_corrected_one_is_taken(native_dir, fmi):
    """A refused step would be refused again: fmi2Terminated is true after it (FMI 3.0's
    terminateSimulation: the robustness suite), so a retrying master stops; the refusal is logged
    once however often it is repeated; a corrected input steps on."""
    with FmuInstance(_native(native_dir, "CardanJoint", fmi)) as fmu:
        fmu.initialize()
        fmu.set({"beta": math.nan})
        for attempt in range(3):
            with pytest.raises(StepRefused) as refused:
                fmu.step(1e-3)
            assert refused.value.status == "Discard"
            assert len(refused.value.messages) == (1 if attempt == 0 else 0)
            if fmi == "2":
                assert fmu.fmu.getBooleanStatus(3) is True  # fmi2Terminated
                assert fmu.fmu.getRealStatus(2) == 0.0  # fmi2LastSuccessfulTime
        fmu.set({"beta": 0.3})
        fmu.step(1e-3)
        if fmi == "2":
            assert fmu.fmu.getBooleanStatus(3) is False
        assert fmu.get(["phi_in"])[0] == pytest.approx(MODELS["CardanJoint"].spec["omega_in"].start * 1e-3, rel=1e-15)


def test_fmi3_honours_the_start_time(native_dir):
    """Outputs at initialisation and the independent variable are those at the start time."""
    core = MODELS["SpeedSource"]()
    assert core.initialize(0.75) == []
    with FmuInstance(_native(native_dir, "SpeedSource", "3")) as fmu:
        fmu.initialize(start_time=0.75)
        assert fmu.get(["omega_out", "phi_out", "alpha_out", "time"]) == [core.omega_out, core.phi_out,
                                                                          core.alpha_out, 0.75]
        fmu.step(0.25)
        core.step(0.75, 0.25)
        assert fmu.get(["omega_out", "time"]) == [core.omega_out, 1.0]


def test_state_bytes_of_another_model_or_corrupt_are_refused(native_dir, fmi):
    with FmuInstance(_native(native_dir, "SpeedSource", fmi)) as other:
        other.initialize()
        foreign = other.serialize_state(other.get_state())
    # one instance at a time: fmpy's FMI 2.0 logger proxy serves the last instance created
    with FmuInstance(_native(native_dir, "CardanJoint", fmi)) as fmu:
        fmu.initialize()
        fmu.step(1e-3)
        serialized = fmu.serialize_state(fmu.get_state())
        corrupt = bytearray(serialized)
        corrupt[len(corrupt) // 2] ^= 0x10
        for data, reason in ((foreign, "another model"), (bytes(corrupt), "corrupt"), (serialized[:-1], "another model"),
                             (b"\x80\x04garbage", "not a serialized FMU state")):
            assert _error(fmu.deserialize_state, data) == 3
            assert reason in fmu.log[-1].message
            fmu.reset()


# -- CriticalSpeeds: String and Boolean parameters, shipped resources, the analysis ------------------------
# Parametrized by the model's name, so that they count as slow (tests/conftest.py) and are left
# out, with nothing to run, while the rotor library is incomplete.

CRITICAL = [name for name in NATIVE if name == "CriticalSpeeds"]
SHIPPED_LAYOUTS = ("two_piece_propshaft", "two_piece_propshaft_hinged")


def _ramp(t: float) -> float:
    return 1450.0 * t


def _critical_run(path: Path, parameters: dict, changes: dict | None = None, ramp: bool = False) -> np.ndarray:
    """The standard scenario (or a speed ramp to 1450 rad/s) with ``parameters``; ``changes`` set half way."""
    case = scenario(MODELS["CriticalSpeeds"].spec)
    signals = {"omega_in": _ramp} if ramp else case.signals()
    with FmuInstance(path) as fmu:
        fmu.initialize({**parameters, **({"omega_in": 0.0} if ramp else case.input_values(0.0))})
        first = fmu.run(case.stop_time / 2, case.step_size, signals)
        fmu.set(changes or {})
        second = fmu.run(case.stop_time, case.step_size, signals)
    return np.concatenate([first, second[1:]])


def _layout_file(folder: Path) -> Path:
    """A layout of the test's own: the shipped two-piece shaft with a longer rear tube, in a folder
    whose name needs escaping in a URI."""
    text = MODELS["CriticalSpeeds"].resource_files[0].read_text()
    target = folder / "own layouts" / "longer rear tube.toml"
    target.parent.mkdir()
    target.write_text(text.replace("length = 0.80", "length = 0.95", 1))
    return target


CRITICAL_MODES = [
    *({"layout": name} for name in SHIPPED_LAYOUTS),
    {"shear": False},
    {"orders": "2, 3", "band": 0.3, "c_bearing": 2000.0},
]


@pytest.mark.parametrize("name", CRITICAL)
@pytest.mark.parametrize("parameters", CRITICAL_MODES, ids=lambda p: ",".join(f"{k}={v}" for k, v in p.items()))
def test_critical_speeds_modes_match_the_python_fmu(native_dir, fmu_path, name, parameters, fmi):
    """Each shipped layout (found in the resources folder), the Rayleigh beam (shear false), other
    orders and damping: the standard scenario as the Python FMU's."""
    reference = _critical_run(fmu_path(name, fmi), parameters)
    assert beyond_tolerance(reference, _critical_run(_native(native_dir, name, fmi), parameters)) == {}


@pytest.mark.parametrize("name", CRITICAL)
def test_critical_speeds_layout_file_orders_change_and_ramp_match_the_python_fmu(native_dir, fmu_path, tmp_path, name,
                                                                                  fmi):
    """A layout file the test writes, orders changed mid-run (re-analysed at the next step), a speed
    ramp through the resonances."""
    layout = str(_layout_file(tmp_path))
    for parameters, changes, ramp in (({"layout": layout}, {"orders": "1,2,3,6"}, False),
                                      ({}, {"orders": "1,2,3,6", "shear": False}, True),
                                      ({"layout": "two_piece_propshaft"}, {"layout": layout}, True)):
        reference = _critical_run(fmu_path(name, fmi), parameters, changes, ramp)
        native_run = _critical_run(_native(native_dir, name, fmi), parameters, changes, ramp)
        assert beyond_tolerance(reference, native_run) == {}, (parameters, changes, ramp)


@pytest.mark.parametrize("name", CRITICAL)
def test_critical_speeds_refuses_like_the_python_fmu(native_dir, fmu_path, tmp_path, name, fmi):
    """Bad orders, bad layout values and files, the work limit, the plausibility check: refused with
    the Python FMU's words."""
    (tmp_path / "folder.toml").mkdir()
    (tmp_path / "garbage.toml").write_text("[[segments]\nlength = = 1\n")
    (tmp_path / "empty.toml").write_text("")
    cases = [
        {"orders": "1,x"}, {"orders": "0"}, {"orders": ""}, {"orders": "1, 2,,3"}, {"orders": ",".join(["1"] * 17)},
        {"orders": "99999999999999999999"}, {"orders": "\u00e9" * 30}, {"orders": "\u0661"}, {"orders": "\u00a02 , 101"},
        {"layout": "no_such_example"}, {"layout": "../../../etc/passwd"}, {"layout": "x" * 300 + ".toml"},
        {"layout": str(tmp_path / "missing.toml")}, {"layout": str(tmp_path / "folder.toml")},
        {"layout": str(tmp_path / "garbage.toml")}, {"layout": str(tmp_path / "empty.toml")},
        {"L_shaft": 100.0}, {"omega_in_max": 1e300}, {"density": 1e308}, {"E": 1e-300}, {"E": 1e180},
        {"D_outer": 1e200, "D_inner": 0.0}, {"orders": "1,2", "D_outer": 1e-100, "D_inner": 0.0},
    ]
    for parameters in cases:
        expected = [up_to_the_toml_reason(m) for m in refusals(fmu_path(name, fmi), parameters)]
        found = [up_to_the_toml_reason(m) for m in refusals(_native(native_dir, name, fmi), parameters)]
        assert found == expected, parameters


@pytest.mark.parametrize("name", CRITICAL)
def test_critical_speeds_strings_are_part_of_the_state(native_dir, name, fmi):
    """A state saved with other strings, serialized and restored into another instance, brings
    them back and continues bit for bit (the analysis is rebuilt for the restored parameters)."""
    path, case = _native(native_dir, name, fmi), scenario(MODELS[name].spec)
    middle, serialized, reference = _half_way_state(path, {"layout": "two_piece_propshaft", "orders": "1,2,6",
                                                           "band": 0.2})
    with FmuInstance(path) as other:
        other.initialize({"orders": "3"})
        other.run(case.stop_time / 4, case.step_size)
        restored = other.deserialize_state(serialized)
        other.set_state(restored)
        other.free_state(restored)
        assert other.get(["layout", "orders", "band"]) == ["two_piece_propshaft", "1,2,6", 0.2]
        other.time = middle
        assert other.run(case.stop_time, case.step_size, case.signals()).tobytes() == reference.tobytes()


@pytest.mark.parametrize("name", CRITICAL)
def test_critical_speeds_state_with_a_bad_string_length_is_refused(native_dir, name, fmi):
    """Serialized bytes whose string length runs beyond the bytes (checksum made right) are refused
    without reading beyond them."""
    with FmuInstance(_native(native_dir, name, fmi)) as fmu:
        fmu.initialize({"orders": "1,2"})
        state = fmu.get_state()
        serialized = bytearray(fmu.serialize_state(state))
        fmu.free_state(state)
        # the last string (orders, "1,2") sits just before the checksum: its length word before it
        at = len(serialized) - 8 - 3 - 4
        assert int.from_bytes(serialized[at:at + 4], "little") == 3
        for length in (4, 2**31, 2**32 - 1):
            corrupt = serialized.copy()
            corrupt[at:at + 4] = length.to_bytes(4, "little")
            checksum = 14695981039346656037
            for byte in corrupt[:-8]:
                checksum = ((checksum ^ byte) * 1099511628211) % 2**64
            corrupt[-8:] = checksum.to_bytes(8, "little")
            assert _error(fmu.deserialize_state, bytes(corrupt)) == 3
            assert "impossible values" in fmu.log[-1].message
            fmu.reset()


@pytest.mark.parametrize("name", CRITICAL)
def test_critical_speeds_string_limit_and_lifetime(native_dir, name, fmi):
    """A layout of 10^5 characters is refused by the set itself (Error, model_adapter's limit and
    wording); a string read stays valid and is the FMU's own copy."""
    path = _native(native_dir, name, fmi)
    with FmuInstance(path) as fmu:
        fmu.initialize()
        assert _error(fmu.fmu.setString, [fmu.variables["layout"].valueReference], ["1," * 50000]) == 3
        assert fmu.log[-1].message.endswith("layout is 100000 characters long (at most 4096)")
        fmu.reset()
        with pytest.raises(StepRefused, match="more than 16 orders"):  # 4096 characters: set, refused by the analysis
            fmu.initialize({"orders": "1," * 2047 + "2"})
        fmu.reset()
        fmu.initialize()
        fmu.set({"orders": "2,3"})
        first = fmu.get(["orders"])
        fmu.step(1e-3)
        assert first == fmu.get(["orders"]) == ["2,3"]


@pytest.mark.parametrize("name", CRITICAL)
def test_critical_speeds_without_resources_refuses_a_shipped_name(native_dir, tmp_path, name, fmi):
    """The resources folder is found where the FMU was extracted, in a folder whose URI needs
    percent-escapes; without it a shipped name is not found, with the loader's words, and the
    one-piece tube needs none."""
    path = _native(native_dir, name, fmi)
    unzipdir = Path(extract(str(path), unzipdir=str(tmp_path / "an FMU's folder %41 #1")))
    with FmuInstance(path, unzipdir=str(unzipdir)) as fmu:
        fmu.initialize({"layout": "two_piece_propshaft_hinged"})
        fmu.step(1e-3)
    shutil.rmtree(unzipdir / "resources")
    with FmuInstance(path, unzipdir=str(unzipdir)) as fmu:
        with pytest.raises(StepRefused) as refused:
            fmu.initialize({"layout": "two_piece_propshaft"})
        assert refused.value.messages == ["driveline: no shipped example named 'two_piece_propshaft'"]
        fmu.reset()
        fmu.initialize({"layout": ""})
        fmu.step(1e-3)


@pytest.mark.skipif("TripodCoupling" not in NATIVE, reason="the tripod has no C port")
def test_a_bend_extrapolated_beyond_its_range_is_refused_alike(native_dir, fmu_path, fmi):
    """beta + beta_dot h leaving [0, beta_max] refuses the step, with the same words in both families,
    and the model stays as before the step."""
    messages = []
    for path in (fmu_path("TripodCoupling", fmi), _native(native_dir, "TripodCoupling", fmi)):
        with FmuInstance(path) as fmu:
            fmu.initialize({"beta": 0.78, "beta_dot": 1.0})
            before = fmu.get(["phi_in", "Rx_in"])
            with pytest.raises(StepRefused) as refused:
                fmu.step(0.01)
            assert fmu.get(["phi_in", "Rx_in"]) == before
            messages.append(refused.value.messages)
            fmu.set({"beta_dot": -1.0})
            fmu.step(0.01)
    assert messages[0] == messages[1] and "beta extrapolated to the end of the step" in messages[0][0]
