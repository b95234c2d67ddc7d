"""The native FMUs' C under AddressSanitizer and UndefinedBehaviorSanitizer: a host linked with each fuzzed
model's carried sources (``support/sanitizer_fuzz.c``) calls every FMI function of both interfaces in every
state of the standard's state machines, and random sequences of them with hostile values, directional and
adjoint derivatives, and saved states corrupted with their checksum remade; each run in a process of its
own, with a time limit and a limit on resident memory. A sanitizer's report, a status outside OK, Warning,
Discard and Error, a value that is not finite got with OK, or a function the standard forbids in a state
that is not refused with Error fails the test.

Each entry point the layer added or hardened (the Model Exchange functions, the directional and adjoint
derivatives, DoStep, the saved states) is also a fuzz target of its own, with a fixed seed and a few cases: cheap
enough for the fast set, as are the random sequences; the sanitized builds, which a module's tests share, are
charged to none of them. The campaigns behind docs/robustness.md's counts run the same host with more cases.

The models fuzzed cover the layer's new entry points: CardanJoint (one state, directional derivatives),
PowertrainMounts (twelve states, input derivatives, a layout file), VehicleDriveline (ten states);
CriticalSpeeds is instantiated only (its start values hold a Real beyond int32: E = 2.1e11 Pa)."""

from __future__ import annotations

import pytest

from fmu_harness.packaging import native
from support import sanitizers

FUZZED = ("CardanJoint", "PowertrainMounts", "VehicleDriveline")
#: Cases of the random sequences per model and FMI version (40 calls each): about a second under the sanitizers.
CASES = 150
#: Cases of each entry point's fuzz target per model and FMI version (8 calls each, fixed seed): the fast set's
#: share, 16 targets x 12 cases, a fraction of a second under the sanitizers; the campaigns run many more.
TARGET_CASES = 12
#: The fuzz targets of MODE "targets" (TARGETS in support/sanitizer_fuzz.c): the entry points the layer added or
#: hardened. The Model Exchange ones and the adjoint derivative are not targets of a co-simulation-only model.
TARGETS = ("SetTime", "SetContinuousStates", "GetContinuousStates", "GetDerivatives", "GetNominalsOfContinuousStates",
           "GetEventIndicators", "EnterEventMode", "EnterContinuousTimeMode", "NewDiscreteStates",
           "CompletedIntegratorStep", "GetDirectionalDerivative", "GetAdjointDerivative", "DoStep", "GetFMUState",
           "SetFMUState", "SerializeFMUState")

pytestmark = pytest.mark.skipif(sanitizers.available() is not None, reason=str(sanitizers.available()))


@pytest.fixture(scope="session")
def sanitizer_builds() -> dict:
    return {}


@pytest.fixture
def sanitized(sanitizer_builds, native_dir, tmp_path_factory, name, fmi):
    """The fuzzing host built with the test's model (``name``) and FMI version under the sanitizers, and the
    FMU's resources: a build the module's tests share, charged to none of them (conftest.SHARED_BUILDS)."""
    if (name, fmi) not in sanitizer_builds:
        sanitizer_builds[name, fmi] = sanitizers.build(native.fmu_path(native_dir, name, fmi), fmi,
                                                       tmp_path_factory.mktemp(f"sanitized_{name}_{fmi}"))
    return sanitizer_builds[name, fmi]


def _clean(result: tuple[int, str, dict[str, int]]) -> dict[str, int]:
    code, output, counts = result
    assert code == 0 and counts, output
    return counts


@pytest.mark.parametrize("name", ["CriticalSpeeds"])
def test_instantiation_stores_the_start_values_without_undefined_behaviour(sanitized, fmi):
    """Every start value is stored as its type (a Real of 2.1e11 was converted to int32 as well)."""
    assert _clean(sanitizers.run(*sanitized, "instantiate", cases=3))["cases"] == 3


@pytest.mark.parametrize("name", FUZZED)
def test_every_function_in_every_state_of_both_interfaces(sanitized, name):
    """30 functions in each of the 5 co-simulation and Model Exchange states (Instantiated, Initialization Mode,
    Event Mode, Continuous-Time Mode or Step Mode, Terminated, Error): 30 x 11 cases."""
    assert _clean(sanitizers.run(*sanitized, "states"))["cases"] == 30 * 11


@pytest.mark.parametrize("name", FUZZED)
def test_random_call_sequences_with_hostile_arguments(sanitized, name):
    counts = _clean(sanitizers.run(*sanitized, "sequences", seed=45, cases=CASES))
    assert counts["cases"] == CASES and counts["calls"] >= 20 * CASES  # calls without a kept state are skipped


@pytest.mark.parametrize("name", FUZZED)
def test_a_fuzz_target_for_each_new_entry_point(sanitized, name):
    """Each entry point the layer added or hardened, fuzzed on its own: TARGET_CASES fresh instances per target,
    each driven into a random state of its interface, then eight calls, every other one the target's with
    hostile arguments; a target forbidden in the state its calls left the instance in is refused with Error."""
    counts = _clean(sanitizers.run(*sanitized, "targets", seed=45, cases=TARGET_CASES))
    assert {key: n for key, n in counts.items() if key.startswith("target ")} == {
        f"target {target}": TARGET_CASES for target in TARGETS}
    assert counts["cases"] == len(TARGETS) * TARGET_CASES
