"""The native FMUs' C under AddressSanitizer and UndefinedBehaviorSanitizer: a host linked with each fuzzed
model's carried sources (``support/sanitizer_fuzz.c``) calls every FMI function of both interfaces in every
state of the standard's state machines, and random sequences of them with hostile values, directional and
adjoint derivatives, and saved states corrupted with their checksum remade; each run in a process of its
own, with a time limit and a limit on resident memory. A sanitizer's report, a status outside OK, Warning,
Discard and Error, a value that is not finite got with OK, or a function the standard forbids in a state
that is not refused with Error fails the test.

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

pytestmark = pytest.mark.skipif(sanitizers.available() is not None, reason=str(sanitizers.available()))


@pytest.fixture(scope="module")
def fuzzer(native_dir, tmp_path_factory):
    built = {}

    def get(name: str, fmi: str):
        if (name, fmi) not in built:
            built[name, fmi] = sanitizers.build(native.fmu_path(native_dir, name, fmi), fmi,
                                                tmp_path_factory.mktemp(f"sanitized_{name}_{fmi}"))
        return built[name, fmi]

    return get


def _clean(result: tuple[int, str, dict[str, int]]) -> dict[str, int]:
    code, output, counts = result
    assert code == 0 and counts, output
    return counts


def test_instantiation_stores_the_start_values_without_undefined_behaviour(fuzzer):
    """Every start value is stored as its type (a Real of 2.1e11 was converted to int32 as well)."""
    assert _clean(sanitizers.run(*fuzzer("CriticalSpeeds", "2"), "instantiate", cases=3))["cases"] == 3


@pytest.mark.parametrize("name", FUZZED)
def test_every_function_in_every_state_of_both_interfaces(fuzzer, name, fmi):
    """30 functions in each of the 5 co-simulation and Model Exchange states (Instantiated, Initialization Mode,
    Event Mode, Continuous-Time Mode or Step Mode, Terminated, Error): 30 x 11 cases."""
    assert _clean(sanitizers.run(*fuzzer(name, fmi), "states"))["cases"] == 30 * 11


@pytest.mark.parametrize("name", FUZZED)
def test_random_call_sequences_with_hostile_arguments(fuzzer, name, fmi):
    counts = _clean(sanitizers.run(*fuzzer(name, fmi), "sequences", seed=45, cases=CASES))
    assert counts["cases"] == CASES and counts["calls"] >= 20 * CASES  # calls without a kept state are skipped
