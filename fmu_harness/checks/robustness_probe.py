"""One robustness case, run in a process of its own: ``python -m fmu_harness.checks.robustness_probe CASE_JSON``,
or forked from a host of cases (``--serve``, :func:`serve`) that imported this module once.

The case names a procedure of this module, its arguments and the departures from the standard
its outcome is checked with (none for the native FMUs; the wrappers' for the Python FMUs,
docs/robustness.md); the procedure drives the FMU through raw FMI calls (fmpy, or the
libcosim/Ecos engines) and raises :class:`Wrong` when a status or an output is not the defined
one. The last line printed is the verdict as JSON; a process that dies before printing it
crashed, one that does not end in time hung.
"""

from __future__ import annotations

import importlib
import json
import math
import os
import pickle
import signal
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.simulation import instantiate_fmu

VERDICT = "robustness verdict: "
#: Departures from the standard that the Python wrappers force (docs/robustness.md): a case of the
#: Python FMUs names those its outcome is checked with, a case of the native FMUs none of them.
STATUS_OK_LOGGED = "pythonfmu/pythonfmu3 return OK (the error is logged, later steps refused)"
NO_GUID_CHECK = "pythonfmu/pythonfmu3 do not pass the GUID / instantiation token to Python"
FMI2_DISCARD = "pythonfmu has no fmi2Error without fmi2Fatal: misuse returns fmi2Discard"
DISTINCT_TEXTS_LEAK = "pythonfmu/pythonfmu3 leak every distinct log text: the soak repeats one refusal"
WRAPPER_DEPARTURES = frozenset({STATUS_OK_LOGGED, NO_GUID_CHECK, FMI2_DISCARD, DISTINCT_TEXTS_LEAK})
#: A departure of a host, whatever the FMU.
ECOS_IGNORES_DISCARD = "Ecos ignores fmi2Discard/fmi3Discard"
WRONG_TOKEN = "{00000000-0000-0000-0000-000000000000}"
STATUS_NAMES = ("OK", "Warning", "Discard", "Error", "Fatal", "Pending")
_FMI3_NAMES = {"getReal": "getFloat64", "setReal": "setFloat64", "getInteger": "getInt32", "setInteger": "setInt32",
               "getFMUstate": "getFMUState", "setFMUstate": "setFMUState", "freeFMUstate": "freeFMUState",
               "serializeFMUstate": "serializeFMUState", "deSerializeFMUstate": "deserializeFMUState"}


class Wrong(Exception):
    """A status or output other than the defined one; ``kind`` is "status" or "output"."""

    def __init__(self, kind: str, detail: str):
        super().__init__(detail)
        self.kind = kind


class Probe:
    """One instance of the FMU at ``path`` with logging on; calls return their FMI status name.

    ``departures`` (set once per process from the case) are the documented departures from the
    standard the outcomes are checked with."""

    departures: frozenset[str] = frozenset()

    def __init__(self, path: str, name: str = "probe", guid: str | None = None, unzipdir: str | None = None):
        self.description = read_model_description(path)
        if guid is not None:
            self.description.guid = self.description.instantiationToken = guid
        self.unzipdir = unzipdir or extract(path)
        self.fmi3 = self.description.fmiVersion.startswith("3")
        self.log: list[tuple[str, str]] = []
        self.variables = {v.name: v for v in self.description.modelVariables}
        self.fmu = instantiate_fmu(self.unzipdir, self.description, "CoSimulation", debug_logging=True, logger=self._on_log)
        self.time = 0.0

    def _on_log(self, *args: Any) -> None:
        status, _, message = args[-3:]
        text = message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)
        self.log.append((STATUS_NAMES[status] if 0 <= status < len(STATUS_NAMES) else str(status), text))

    # -- raw calls ---------------------------------------------------------------
    def call(self, name: str, *args: Any) -> tuple[str, Any]:
        """``(status name, result)`` of FMI call ``name`` (FMI 2.0 spelling, mapped for 3.0)."""
        function = getattr(self.fmu, _FMI3_NAMES.get(name, name) if self.fmi3 else name)
        try:
            return "OK", function(*args)
        except FMICallException as error:
            return STATUS_NAMES[error.status], None

    def status(self, name: str, *args: Any) -> str:
        return self.call(name, *args)[0]

    def reference(self, name: str) -> int:
        return self.variables[name].valueReference

    def set(self, name: str, value: Any) -> str:
        kind = self.variables[name].type
        setter = {"Real": "setReal", "Float64": "setReal", "Integer": "setInteger", "Int32": "setInteger",
                  "Boolean": "setBoolean", "String": "setString"}[kind]
        return self.status(setter, [self.reference(name)], [value])

    def get(self, names: list[str]) -> list[float]:
        return [self.call("getReal", [self.reference(name)])[1][0] for name in names]

    def outputs(self) -> list[str]:
        return [v.name for v in self.description.modelVariables
                if v.causality == "output" and v.type in ("Real", "Float64")]

    def enter(self, start_time: float = 0.0) -> str:
        if self.fmi3:
            return self.status("enterInitializationMode", None, start_time)
        self.status("setupExperiment", None, start_time)
        return self.status("enterInitializationMode")

    def initialize(self, values: dict[str, Any] | None = None, start_time: float = 0.0) -> str:
        self.time = start_time
        self.enter(start_time)
        for name, value in (values or {}).items():
            self.set(name, value)
        return self.status("exitInitializationMode")

    def step(self, step_size: float, time: float | None = None) -> str:
        status = self.status("doStep", self.time if time is None else time, step_size)
        if status == "OK":
            self.time += step_size
        return status

    def step_stopping(self, step_size: float) -> tuple[str, bool]:
        """``(status, stop)`` of a doStep from the current time: ``stop`` is FMI 3.0's
        terminateSimulation, or FMI 2.0's fmi2Terminated asked for after a Discard, as fmusim and
        fmpy's ``simulate_fmu`` ask."""
        if not self.fmi3:
            status = self.step(step_size)
            return status, status == "Discard" and bool(self.call("getBooleanStatus", 3)[1])  # fmi2Terminated
        from ctypes import byref

        from fmpy.fmi3 import fmi3Boolean, fmi3Float64

        event, stop, early, last = fmi3Boolean(False), fmi3Boolean(False), fmi3Boolean(False), fmi3Float64(0.0)
        try:
            self.fmu.fmi3DoStep(self.fmu.component, self.time, step_size, fmi3Boolean(True), byref(event), byref(stop),
                                byref(early), byref(last))
            status = "OK"
            self.time += step_size
        except FMICallException as error:
            status = STATUS_NAMES[error.status]
        return status, bool(stop.value)

    def errors_logged(self) -> list[str]:
        return [text for status, text in self.log if status == "Error"]

    def departs(self, departure: str) -> bool:
        return departure in self.departures

    def refusal(self) -> str:
        """Status of a call after misuse, or of a misused call: Error; fmi2Discard where pythonfmu
        has no fmi2Error without Fatal."""
        return "Discard" if self.departs(FMI2_DISCARD) else "Error"

    def misuse_status(self) -> str:
        """Status of a misused call other than doStep: Error; OK (the error logged) for the wrappers."""
        return "OK" if self.departs(STATUS_OK_LOGGED) else "Error"

    def close(self) -> None:
        self.fmu.freeInstance()


def expect(observed: str, *allowed: str, what: str = "") -> None:
    if observed not in allowed:
        raise Wrong("status", f"{what or 'call'} returned {observed}, expected {' or '.join(allowed)}")


def _finite_outputs(probe: Probe) -> None:
    values = probe.get(probe.outputs())
    if not all(math.isfinite(v) for v in values):
        raise Wrong("output", f"non-finite outputs with status OK: {values}")


# -- procedures: (path, *arguments) -> None, raising Wrong ----------------------------
def bad_input(path: str, name: str, value: float) -> None:
    """A bad input refuses the step (Discard), keeps the outputs; the corrected input steps on."""
    probe = Probe(path)
    expect(probe.initialize(), "OK", what="exitInitializationMode")
    expect(probe.step(1e-3), "OK", what="first doStep")
    good, before = probe.get([name])[0], probe.get(probe.outputs())
    probe.set(name, value)
    expect(probe.step(1e-3), "Discard", what=f"doStep with {name} = {value!r}")
    if not any(name in text for text in probe.errors_logged()):
        raise Wrong("status", f"the refusal does not name {name}: {probe.errors_logged()}")
    after = probe.get(probe.outputs())
    if [repr(v) for v in after] != [repr(v) for v in before]:
        raise Wrong("output", f"a refused step changed the outputs: {before} -> {after}")
    probe.set(name, good)
    expect(probe.step(1e-3), "OK", what="doStep after correcting the input")
    _finite_outputs(probe)
    probe.close()


def _refused_parameters(probe: Probe, values: dict[str, Any], fragment: str) -> None:
    """Parameters no input can make valid: exitInitializationMode returns Error (the wrappers: OK)
    with a message holding ``fragment`` logged, and every step is refused."""
    shown = ", ".join(f"{name} = {str(value)[:40]!r}" for name, value in values.items())
    expect(probe.initialize(values), probe.misuse_status(), what=f"exitInitializationMode with {shown}")
    if not any(fragment in text for text in probe.errors_logged()):
        raise Wrong("status", f"no message with {fragment!r}: {[t[:120] for t in probe.errors_logged()]}")
    expect(probe.step(1e-3), probe.refusal(), what=f"doStep with {shown}")
    probe.close()


def bad_parameter(path: str, name: str, value: Any) -> None:
    """A bad start value of a parameter is refused at initialisation, naming it."""
    _refused_parameters(Probe(path), {name: value}, name)


def persistent_refusal(path: str, name: str, value: Any, fragment: str) -> None:
    """A master that retries a discarded step at the same time until the FMU asks it to stop
    (fmusim's FMI 2.0 loop; fmpy's ``simulate_fmu`` asks fmi2Terminated the same way) stops after
    the first refusal, which is logged once however often the step is repeated."""
    probe = Probe(path)
    expect(probe.initialize(), "OK", what="exitInitializationMode")
    expect(probe.step(1e-3), "OK", what="first doStep")
    probe.set(name, value)
    for tries in range(1, 1001):
        status, stop = probe.step_stopping(1e-3)
        if status != "Discard" or stop:
            break
    expect(status, "Discard", what=f"doStep with {name} = {value!r}")
    if not stop:
        raise Wrong("status", f"the FMU did not ask the master to stop after {tries} refused steps")
    expect(probe.step_stopping(1e-3)[0], "Discard", what="the same step repeated")
    naming = [text for text in probe.errors_logged() if fragment in text]
    if len(naming) != 1:
        raise Wrong("status", f"the refusal was logged {len(naming)} times: {naming[:3]}")
    probe.close()


def step_size(path: str, size: float) -> None:
    """Non-positive or non-finite sizes are refused; a tiny or huge one is taken or refused, never
    with non-finite outputs."""
    probe = Probe(path)
    probe.initialize()
    status = probe.step(size)
    if math.isfinite(size) and size > 0.0:
        expect(status, "OK", "Discard", what=f"doStep({size!r})")
        if status == "OK":
            _finite_outputs(probe)
    else:
        expect(status, "Discard", what=f"doStep({size!r})")
    expect(probe.step(1e-3), "OK", what="a good step after it")
    probe.close()


def _refused_instantiation(path: str) -> None:
    """Instantiation with a wrong token returns NULL (fmpy raises) with the reason logged."""
    probe = Probe.__new__(Probe)  # constructed in two steps to keep its log when instantiation fails
    try:
        probe.__init__(path, guid=WRONG_TOKEN)
    except Exception as error:  # noqa: BLE001 - fmpy's exception for a NULL instance
        if "instantiate" not in str(error) or not probe.errors_logged():
            raise Wrong("status", f"instantiation failed otherwise: {error}; logged {probe.errors_logged()}") from error
        return
    probe.close()
    raise Wrong("status", "instantiation with a wrong token did not return NULL")


def misuse(path: str, kind: str) -> None:
    """Calls out of the life-cycle order or with wrong references: the defined outcome is the
    status of the call (Error, or the wrappers' departure), an Error logged, and (error state)
    every later step refused; a wrong token makes instantiation return NULL."""
    if kind == "wrong guid" and NO_GUID_CHECK not in Probe.departures:
        return _refused_instantiation(path)
    probe = Probe(path, guid=WRONG_TOKEN if kind == "wrong guid" else None)
    first_input = next((v.name for v in probe.description.modelVariables if v.causality == "input"), None)
    fixed = next((v.name for v in probe.description.modelVariables if v.causality == "parameter"
                  and v.variability == "fixed" and v.type in ("Real", "Float64")), None)
    output = probe.outputs()[0]
    if kind == "step before initialisation":
        expect(probe.step(1e-3), probe.refusal(), what="doStep before initialisation")
        return probe.close()
    if kind == "step in initialisation mode":
        probe.enter()
        expect(probe.step(1e-3), probe.refusal(), what="doStep in initialisation mode")
        return probe.close()
    if kind == "nan start time":
        expect(probe.enter(math.nan), probe.misuse_status(), what="initialisation at t = nan")
        if not probe.errors_logged():
            raise Wrong("status", "a start time of nan logged no error")
        probe.status("exitInitializationMode")
        expect(probe.step(1e-3), probe.refusal(), what="doStep after a start time of nan")
        return probe.close()
    if kind == "wrong guid":
        expect(probe.initialize(), "OK")
        expect(probe.step(1e-3), "OK", what="doStep (pythonfmu does not check the GUID)")
        return probe.close()
    probe.initialize()
    expect(probe.step(1e-3), "OK", what="first doStep")
    if kind in ("step after terminate", "set after terminate"):
        expect(probe.status("terminate"), "OK", what="terminate")
        if kind == "set after terminate" and first_input:
            expect(probe.set(first_input, 1.0), probe.misuse_status(), what="set after terminate")
            if not probe.errors_logged():
                raise Wrong("status", "setting after terminate logged no error")
    elif kind in ("nan time", "-inf time", "time going backwards"):
        time = {"nan time": math.nan, "-inf time": -math.inf}.get(kind, probe.time - 1e-3)
        expect(probe.step(1e-3, time), probe.refusal(), what=f"doStep at t = {time}")
        if not probe.errors_logged():
            raise Wrong("status", f"doStep at t = {time}: no error logged")
    else:
        call = {
            "unknown value reference": lambda: probe.call("getReal", [987654])[0],
            "string on a real": lambda: probe.status("setString", [probe.reference(output if not first_input else first_input)], ["x"]),
            "set an output": lambda: probe.status("setReal", [probe.reference(output)], [1.0]),
            "fixed parameter after initialisation": lambda: probe.set(fixed, 0.5) if fixed else probe.misuse_status(),
            "enter initialisation twice": lambda: probe.enter(),
        }[kind]
        expect(call(), probe.misuse_status(), what=kind)
        if kind == "fixed parameter after initialisation" and not fixed:
            return probe.close()
        if not probe.errors_logged():
            raise Wrong("status", f"{kind}: no error logged")
    expect(probe.step(1e-3), probe.refusal(), what=f"doStep after {kind}")
    probe.close()


def _state_bytes(probe: Probe) -> bytes:
    state = probe.call("getFMUstate")[1]
    data = bytes(probe.call("serializeFMUstate", state)[1])
    probe.call("freeFMUstate", state)
    return data


class _RunsCommand:
    def __init__(self, marker: str):
        self.marker = marker

    def __reduce__(self):
        return (os.system, (f"touch {self.marker}",))


def state(path: str, kind: str, other_path: str = "") -> None:
    """A serialised state restores exactly; anything else is refused with Error by
    deserialising or setting it (the wrappers: OK at setFMUstate), the reason logged, later steps
    refused, and never run."""
    other_state = b""
    if kind == "another model's state":  # first: fmpy's FMI 2.0 logger serves the last instance created
        other = Probe(other_path, "other")
        other.initialize()
        other_state = _state_bytes(other)
        other.close()
    probe = Probe(path)
    probe.initialize()
    for _ in range(3):
        expect(probe.step(1e-3), "OK")
    good = _state_bytes(probe)
    marker = Path(probe.unzipdir) / "state_code_ran"
    data = {
        "round trip": good,
        "pickle running a command": pickle.dumps(_RunsCommand(str(marker))),
        "truncated": good[: len(good) // 2],
        "one bit flipped": good[:50] + bytes([good[50] ^ 4]) + good[51:],
        "empty": b"",
        "another model's state": other_state,
    }[kind]
    time, reference = probe.time, None
    if kind == "round trip":
        reference = [probe.step(1e-3) and probe.get(probe.outputs()) for _ in range(3)]
        probe.time = time
    status, restored = probe.call("deSerializeFMUstate", data)
    if status == "OK":
        status = probe.status("setFMUstate", restored)
    expect(status, "OK" if kind == "round trip" else probe.misuse_status(),
           what="deserialising and setting the state")
    if marker.exists():
        raise Wrong("output", "deserialising ran a command")
    if kind == "round trip":
        again = [probe.step(1e-3) and probe.get(probe.outputs()) for _ in range(3)]
        if again != reference:
            raise Wrong("output", "the restored state continued differently")
        return probe.close()
    if not any("refused" in text for text in probe.errors_logged()):
        raise Wrong("status", f"{kind}: no refusal logged")
    expect(probe.step(1e-3), probe.refusal(), what="doStep after a refused state")
    probe.close()


MOUNTS_HEADER = "mass = 200.0\ncentre_of_gravity = [0.0, 0.0, 0.0]\ninertia = [10.0, 8.0, 9.0, 0.0, 0.0, 0.0]\n"
SEGMENT_TABLE = "[[segments]]\nlength = 0.1\nouter_diameter = 0.05\nyoungs_modulus = 2.1e11\ndensity = 7850.0\n"


def hostile_file(target: Path, kind: str) -> None:
    """Create a hostile layout file of ``kind`` at ``target``."""
    if kind == "fifo":
        os.mkfifo(target)
    elif kind == "dev zero":
        target.symlink_to("/dev/zero")
    elif kind == "directory":
        target.mkdir()
    elif kind == "many stations":  # inside every loader limit; its analysis once took 566 s (native)
        from .analysis_work import layout_text

        target.write_text(layout_text(100, 1.4, 202, 202, 200))
    elif kind in ("many mounts", "mounts on a line"):
        count = 9 if kind == "many mounts" else 3
        target.write_text(MOUNTS_HEADER + "".join(f"[[mounts]]\nposition = [{0.1 * i}, 0.0, 0.0]\n"
                                                  "stiffness = [1e5, 1e5, 1e5]\n" for i in range(count)))
    elif kind == "deep nesting":
        target.write_text("x = " + "[" * 1000 + "]" * 1000)
    else:
        target.write_text(SEGMENT_TABLE * {"many segments": 101, "large file": 10000}[kind])


def layout(path: str, value: str, fragment: str, prepare: str = "") -> None:
    """A hostile ``layout`` is refused at initialisation with a message holding ``fragment``,
    quickly; the message reaches the logger verbatim (no printf conversion of host text)."""
    folder = Path(extract(path))
    target = folder / value if prepare else Path(value)
    if prepare:
        hostile_file(target, prepare)
    _refused_parameters(Probe(path, unzipdir=str(folder)), {"layout": str(target) if prepare else value}, fragment)


def parameter_limit(path: str, name: str, value: Any, fragment: str) -> None:
    """A parameter beyond what the analysis can do in bounded time or resolve is refused quickly,
    at initialisation."""
    _refused_parameters(Probe(path), {name: value}, fragment)


def bounded_output(path: str, values: dict[str, Any], fragment: str) -> None:
    """Start values whose outputs lie beyond a declared physical bound are refused at initialisation
    as bad parameters are; the inputs among them set after initialisation refuse every step with the
    bound named and the master asked to stop."""
    _refused_parameters(Probe(path), values, fragment)
    probe = Probe(path)
    inputs = {name: value for name, value in values.items() if probe.variables[name].causality == "input"}
    expect(probe.initialize({name: value for name, value in values.items() if name not in inputs}), "OK",
           what="exitInitializationMode")
    for name, value in inputs.items():
        probe.set(name, value)
    status, stop = probe.step_stopping(1e-3)
    expect(status, "Discard", what=f"doStep with {values}")
    if not stop or not any(fragment in text for text in probe.errors_logged()):
        raise Wrong("status", f"stop {stop}, no message with {fragment!r}: {[t[:120] for t in probe.errors_logged()]}")
    probe.close()


def long_string(path: str, name: str, length: int) -> None:
    """A string longer than the adapter accepts is refused at the set (error state)."""
    probe = Probe(path)
    probe.initialize()
    expect(probe.set(name, "1," * (length // 2)), probe.misuse_status(), what="setString")
    expect(probe.step(1e-3), probe.refusal(), what="doStep after the refused string")
    probe.close()


def start_time(path: str, start: float) -> None:
    """Outputs of a time-dependent model read right after initialisation at ``start``: those at
    ``start``, and the first step from there is a run's through it (docs/robustness.md)."""
    def initial_outputs(name: str, at: float) -> tuple[list[float], list[float]]:
        probe = Probe(path, name)
        probe.initialize(start_time=at)
        initial = probe.get(probe.outputs())
        expect(probe.step(0.0 + 1e-3), "OK")
        stepped = probe.get(probe.outputs())
        probe.close()
        return initial, stepped

    (initial, stepped), (at_zero, _) = initial_outputs("probe", start), initial_outputs("fresh", 0.0)
    if initial == at_zero:
        raise Wrong("output", f"outputs after initialisation at t = {start}: {initial} (at t = 0: {at_zero})")
    reference = Probe(path, "reference")
    reference.initialize(start_time=start - 1e-3)
    expect(reference.step(1e-3), "OK")
    expect(reference.step(1e-3), "OK")
    if max(abs(a - b) for a, b in zip(reference.get(reference.outputs()), stepped)) > 1e-9 * max(map(abs, stepped)):
        raise Wrong("output", "the first step from a start time other than 0 differs from a run through it")
    reference.close()


def instances(path: str, threads: bool) -> None:
    """Two instances stepped interleaved (or in two threads) give what each gives alone."""
    def run(probe: Probe, results: list, omega: float | None) -> None:
        probe.initialize()
        rows = []
        for _ in range(20):
            if omega is not None and probe.outputs():
                first_input = next((v.name for v in probe.description.modelVariables if v.causality == "input"), None)
                if first_input:
                    probe.set(first_input, omega)
            expect(probe.step(1e-3), "OK")
            rows.append(probe.get(probe.outputs()))
        results.append(rows)

    alone: list = []
    for omega in (None, 1.0):
        probe = Probe(path, f"alone{omega}")
        run(probe, alone, omega)
        probe.close()
    together: list[list] = [[], []]
    pair = [Probe(path, "a"), Probe(path, "b")]
    if threads:
        workers = [threading.Thread(target=run, args=(p, r, o)) for p, r, o in zip(pair, together, (None, 1.0))]
        for worker in workers:
            worker.start()
        for worker in workers:
            worker.join()
        together = [r[0] for r in together]
    else:
        for probe in pair:
            probe.initialize()
        first_input = next((v.name for v in pair[1].description.modelVariables if v.causality == "input"), None)
        rows: list[list] = [[], []]
        for _ in range(20):
            for index, probe in enumerate(pair):
                if index == 1 and first_input:
                    probe.set(first_input, 1.0)
                expect(probe.step(1e-3), "OK")
                rows[index].append(probe.get(probe.outputs()))
        together = rows
    for probe in pair:
        probe.close()
    if together != alone:
        raise Wrong("output", "interleaved instances differ from instances alone")


def engine_refusal(path: str, engine: str, name: str, value: float) -> None:
    """In libcosim or Ecos, a step the FMU refuses leaves its outputs as they were and the host
    running; libcosim reports the step as not taken (Ecos advances its time regardless)."""
    from . import importers

    session = (importers.cosim_session if engine == "libcosim" else importers.ecos_session)(1e-3, {"m": Path(path)})
    outputs = [f"m.{v.name}" for v in read_model_description(path).modelVariables
               if v.causality == "output" and v.type in ("Real", "Float64")]
    session.step()
    before = session.get(outputs)
    session.set({f"m.{name}": value})
    taken = session.step()
    after = session.get(outputs)
    session.close()
    if engine == "libcosim" and taken is not False:
        raise Wrong("status", f"libcosim reported the refused step as taken ({taken!r})")
    if [repr(v) for v in after] != [repr(v) for v in before]:
        raise Wrong("output", f"the refused step changed the outputs: {before} -> {after}")


def model_failure(path: str, failure: int, name: str) -> None:
    """A model step raising ``name`` outside the model's own checks: the error state (logged with
    the exception's name, later steps refused) for anything but an ArithmeticError, which the
    model refuses as a step (Discard); after Reset the instance steps again."""
    probe = Probe(path)
    expect(probe.initialize({"failure": failure}), "OK")
    arithmetic = name == "OverflowError"
    expect(probe.step(1e-3), "Discard" if arithmetic else probe.refusal(), what=f"doStep raising {name}")
    if not any(name in text for text in probe.errors_logged()):
        raise Wrong("status", f"{name} not named in the log: {probe.errors_logged()[:2]}")
    expect(probe.step(1e-3), "Discard" if arithmetic else probe.refusal(), what=f"the next doStep after {name}")
    expect(probe.status("reset"), "OK", what="reset")
    expect(probe.initialize(), "OK", what="initialisation after reset")
    expect(probe.step(1e-3), "OK", what="doStep after reset")
    probe.close()


def _peak_resident_kb() -> int:
    """Peak resident set of this process image in kB (Linux). Unlike ``getrusage``'s ``ru_maxrss``,
    which a child keeps from its parent across ``exec`` and so hides any growth below the
    parent's size, it starts afresh in the new program."""
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))


def soak(path: str, name: str, alternations: int) -> None:
    """Bad and good values of input ``name`` alternated many times: every bad step refused, every
    good one taken, and resident memory bounded. Each bad value lies above the input's maximum
    and differs from the others, so every refusal logs a text of its own; where the wrappers leak
    each distinct text, the bad value is NaN every time, whose repeated refusal reuses its text
    and category (docs/robustness.md)."""
    probe = Probe(path)
    probe.initialize()
    good = probe.get([name])[0]
    distinct = not probe.departs(DISTINCT_TEXTS_LEAK)
    top = float(probe.variables[name].max) if distinct else math.nan  # NaN times anything is NaN
    baseline = None
    for index in range(alternations):
        probe.set(name, top * (1.0 + 1e-12 * (index + 1)))
        expect(probe.step(1e-3), "Discard", what=f"bad step {index}")
        probe.set(name, good)
        expect(probe.step(1e-3), "OK", what=f"good step {index}")
        probe.log.clear()
        if index == alternations // 10:
            baseline = _peak_resident_kb()
    growth = _peak_resident_kb() - (baseline or 0)
    if growth > 2 * 1024:  # kB over 90 % of the run; measured 0 (the wrappers: 11 MB for distinct texts)
        raise Wrong("output", f"resident memory grew by {growth} kB")
    probe.close()


def serve() -> None:
    """``python -m fmu_harness.checks.robustness_probe --serve``: a host of cases. Each line on
    stdin, ``{"case": CASE_JSON, "time_limit": seconds}``, is run in a child forked from this
    process, which imported fmpy and the procedures once (0.2 s of CPU that a process of its own
    pays for each case): the case still has a process of its own, which may crash or hang alone.
    Each case is answered with one line on stdout: the child's exit code (minus the signal that
    ended it), its stdout and stderr, and whether it was killed at the time limit (``hung``)."""
    for module in PRELOADED:
        importlib.import_module(module)
    answers = os.fdopen(os.dup(sys.stdout.fileno()), "w")
    for line in sys.stdin:
        request = json.loads(line)
        answers.write(json.dumps(_forked(request["case"], request["time_limit"])) + "\n")
        answers.flush()


#: Modules of the environment the Python FMUs' cores import (CriticalSpeeds, PowertrainMounts), loaded
#: by the server once: 0.5 s of CPU for each case otherwise. The FMU's own code (its resources) is still
#: imported by each case.
PRELOADED = ("scipy.linalg", "scipy.interpolate")


def _forked(case: str, time_limit: float) -> dict[str, Any]:
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        sys.stdout.flush()
        sys.stderr.flush()
        started = time.monotonic()
        child = os.fork()
        if child == 0:
            try:
                os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
                os.dup2(out.fileno(), 1)
                os.dup2(err.fileno(), 2)
                main([case])
            finally:
                os._exit(1)  # main leaves with os._exit(0) once the verdict is printed
        hung, delay = False, 0.001
        while not (ended := os.waitpid(child, os.WNOHANG))[0]:
            if time.monotonic() - started > time_limit:
                os.kill(child, signal.SIGKILL)
                ended, hung = os.waitpid(child, 0), True
                break
            time.sleep(delay)
            delay = min(2 * delay, 0.02)
        seconds = time.monotonic() - started
        out.seek(0)
        err.seek(0)
        return {"returncode": os.waitstatus_to_exitcode(ended[1]), "hung": hung, "seconds": seconds,
                "stdout": out.read().decode("utf-8", "replace"), "stderr": err.read().decode("utf-8", "replace")}


def main(argv: list[str] | None = None) -> None:
    arguments = argv or sys.argv[1:]
    if arguments == ["--serve"]:
        serve()
        return
    case = json.loads(arguments[0])
    Probe.departures = frozenset(case["departures"])
    try:
        globals()[case["procedure"]](*case["arguments"])
        verdict = {"result": "ok"}
    except Wrong as wrong:
        verdict = {"result": f"wrong {wrong.kind}", "detail": str(wrong)}
    except Exception as error:  # noqa: BLE001 - the host saw an exception from an FMI call
        verdict = {"result": "wrong status", "detail": f"{type(error).__name__}: {error}"}
    print(VERDICT + json.dumps(verdict), flush=True)
    os._exit(0)  # skip interpreter teardown: an FMU's embedded objects are not ours to finalise


if __name__ == "__main__":
    main()
