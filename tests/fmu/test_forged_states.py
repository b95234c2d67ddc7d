"""Serialized FMU states whose checksum a host remade by hand: their values are checked as the model could
have left them (the time finite, every Real output finite and within its bounds), in both families; one
that fails is refused with the reason, nothing of it restored, and the instance steps no more until reset."""

from __future__ import annotations

import hashlib
import math
import struct

import pytest
from fmpy.fmi1 import FMICallException

from driveline.catalog import MODELS
from fmu_harness.runs.runner import FmuInstance, StepRefused
from fmu_src import saved_state

MODEL = "SpeedSource"  # cheap, with a Real output (omega_out) and a state (phi_out)
#: What a forged state changes, and the reason of its refusal.
FORGED = {
    "an output not finite": ("omega_out", math.nan, "output omega_out = nan is not finite"),
    "a state not finite": ("phi_out", -math.inf, "output phi_out = -inf is not finite"),
    "the time not finite": ("time", math.inf, "time = inf is not finite"),
}
#: The native state's layout before its Real values (fmu_state.c): magic, four header words, the token, the
#: slot count, mode and initialized flag, the start time, then the time.
NATIVE_TIME_AT = 8 + 4 * 4


def _native_forged(data: bytes, token: str, name: str, value: float) -> bytes:
    """The native bytes with ``name``'s value (a variable's by value reference, or the time) replaced, their
    FNV-1a checksum made right."""
    time_at = NATIVE_TIME_AT + len(token) + 3 * 4 + 8
    at = time_at if name == "time" else time_at + 8 + 8 * [v.name for v in MODELS[MODEL].spec.variables].index(name)
    forged = bytearray(data)
    forged[at:at + 8] = struct.pack("<d", value)
    checksum = 14695981039346656037
    for byte in forged[:-8]:
        checksum = ((checksum ^ byte) * 1099511628211) % 2**64
    forged[-8:] = checksum.to_bytes(8, "little")
    return bytes(forged)


def _python_forged(data: bytes, name: str, value: float) -> bytes:
    """The Python state's bytes with ``name``'s value replaced, its SHA-256 made right."""
    body = data[:-hashlib.sha256().digest_size]
    key = f'["{name}",["f","'.encode()
    start = body.index(key) + len(key)
    end = body.index(b'"', start)
    body = body[:start] + value.hex().encode() + body[end:]
    return body + hashlib.sha256(body).digest()


def _restore(fmu: FmuInstance, data: bytes) -> None:
    """Deserialize and set ``data``; a refusal by either call (native: Error) is what the test reads."""
    try:
        fmu.set_state(fmu.deserialize_state(data))
    except FMICallException as refused:
        assert refused.status == 3


@pytest.mark.parametrize("case", FORGED)
def test_a_forged_state_is_refused_with_the_reason(family, fmi, case):
    name, value, reason = FORGED[case]
    with family.open(MODEL, fmi) as fmu:
        fmu.initialize()
        fmu.step(1e-3)
        state = fmu.get_state()
        data = fmu.serialize_state(state)
        fmu.free_state(state)
        fmu.step(1e-3)
        token = fmu.description.guid if fmi == "2" else fmu.description.instantiationToken
        forged = (_python_forged(data, name, value) if data.startswith(saved_state.MAGIC)
                  else _native_forged(data, token, name, value))
        _restore(fmu, data)  # the state as saved is accepted
        outputs = fmu.get(fmu.outputs())
        _restore(fmu, forged)
        assert any(f"the state holds an impossible value ({reason})" in record.message for record in fmu.log)
        assert fmu.get(fmu.outputs()) == outputs
        with pytest.raises(StepRefused):
            fmu.step(1e-3)
