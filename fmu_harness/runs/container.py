"""An SSP package as one co-simulation FMU: its components, connections and parameter set inside FMU
Manipulation Toolbox's container (``fmu_manipulation_toolbox.container``, a maintained FMI importer in C
that a host loads as one FMU).

``build(package, target, step_size)`` embeds each component's FMU, links every connection, and exposes
each component's parameters and unconnected inputs as the container's parameters and inputs and every
output as an output, each named ``component.variable`` with its unit, bounds and description (with
``shown``, only those are outputs and every other output a local variable, read by name as before: a host
such as fmpy records every output at every communication point); the package's bindings are the
container's start values, applied by the container itself, so a host that sets nothing runs the package
as bound. The container steps its components at ``step_size`` by Jacobi
(every input one step late, as the project's master and libcosim) or, with ``sequential``, one after the
other in the package's order (the Gauss-Seidel master). A host's communication step may be any whole
number of container steps.

The toolbox's own SSP reader links the connections but drops the parameter set (the launch then ran with
the components' defaults: a 0.5 s ramp, both joints bent 30 deg with the closed-form kinematics and no
friction); the bindings go in here. The container initialises one component after the other, each leaving
initialisation before its outputs feed the next; the master reads every connection's output inside
initialisation in the package's order of connections, where each FMU computes it from what has been set so
far. The container's order is made the order in which the master first reads each component's outputs, so
every component leaves initialisation with the inputs the master gives it, and the runs are equal bit for
bit (on the rubber layout but for the first rows, whose rest values are rounding-level: docs/vehicle_launch.md).
The toolbox warns that a loop's first component (``VehicleDriveline`` in the launch) starts without the loop's
values: at rest they are the start values, up to that rounding.

What the container cannot carry is refused in one line before any work: a Python FMU (it needs Python in
the host: take the native package), an FMU without Co-Simulation, a binding of a variable the FMU has not
or of a String (the container passes no Strings), a connection whose ends are no output and input of one
type. The embedded FMUs travel without their ``documentation/`` and ``sources/`` (each component's own FMU carries
them; a host extracts the container at every run, and those files were 120 of its 144 and two thirds of the time
fmpy spent extracting it): the container's ``documentation/`` holds the package's page where the project has one
and the licence. The archive is reproducible byte for byte (:mod:`fmu_harness.packaging.archive`): the toolbox's
build time, user name and random token are replaced by the package's name and a token of the contents.
"""

from __future__ import annotations

import ctypes
import logging
import re
import tempfile
import zipfile
from collections.abc import Collection, Mapping, Sequence
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
from fmpy.fmi2 import fmi2True
from fmpy.model_description import ModelDescription

from ..packaging import archive, documentation
from .runner import FmuInstance, StepRefused, status_name
from .ssp_package import PackageError, SspSystem

TOOLBOX = "fmu_manipulation_toolbox"
AUTHOR = "driveline-fmus contributors"
CONFIGURATION = "resources/container.txt"
WARNING = 1  # FMI's status Warning: a step taken
#: What an embedded FMU (``resources/<index>/``) does not need inside the container: its documentation and sources.
EMBEDDED_EXTRAS = re.compile(r"resources/[^/]+/(documentation|sources)/")
#: Attributes of a variable's type the container's description takes from the embedded FMU's.
TYPE_ATTRIBUTES = ("quantity", "unit", "displayUnit", "min", "max", "nominal")


class ContainerRefused(PackageError):
    """What a container cannot carry, in one line."""


def _variables(description: ET.Element) -> dict[str, ET.Element]:
    """``{name: variable element}`` of an FMI 2.0 or 3.0 model description."""
    found = {}
    for element in description.find("ModelVariables"):
        found[element.get("name", "")] = element
    return found


def _type_element(variable: ET.Element) -> ET.Element:
    """The element holding a variable's type attributes: FMI 2.0's child (``Real``...), FMI 3.0's element."""
    return variable[0] if variable.tag == "ScalarVariable" and len(variable) else variable


def _type_name(variable: ET.Element) -> str:
    return _type_element(variable).tag


def model_descriptions(system: SspSystem, fmus: Mapping[str, Path]) -> dict[str, ET.Element]:
    """Each component's model description (the root element) by name, from its FMU ``fmus[name]``."""
    found = {}
    for component in system.components:
        with zipfile.ZipFile(fmus[component.name]) as fmu:
            found[component.name] = ET.fromstring(fmu.read("modelDescription.xml"))
    return found


def refusals(system: SspSystem, descriptions: Mapping[str, ET.Element]) -> list[str]:
    """Why the container cannot carry ``system`` (each component's model description by name); [] if it can."""
    found, python = [], []
    for component in system.components:
        description = descriptions[component.name]
        cosimulation = description.find("CoSimulation")
        named = f"{component.name} ({Path(component.source).name})"
        if cosimulation is None:
            found.append(f"component {named} has no Co-Simulation interface")
        elif cosimulation.get("needsExecutionTool") == "true" or description.get("generationTool", "").startswith(
                ("PythonFMU", "pythonfmu")):
            python.append(named)
        variables = _variables(description)
        for name in component.parameters:
            variable = variables.get(name)
            if variable is None:
                found.append(f"parameter {component.name}.{name}: {Path(component.source).name} has no such variable")
            elif _type_name(variable) == "String":
                found.append(f"parameter {component.name}.{name}: a String, which the container cannot pass")
    if python:
        found.insert(0, f"{'the Python FMUs of' if len(python) > 1 else 'the Python FMU of'} {', '.join(python)}, "
                        "which need Python in the host: take the native package")
    for (start, output), (end, input_) in system.connections:
        ends = []
        for element, name, causality in ((start, output, "output"), (end, input_, "input")):
            if element not in descriptions:
                found.append(f"connection {start}.{output} -> {end}.{input_}: no component {element}")
                break
            variable = _variables(descriptions[element]).get(name)
            if variable is None or variable.get("causality") != causality:
                found.append(f"connection {start}.{output} -> {end}.{input_}: {element}.{name} is no {causality}")
                break
            ends.append(_type_name(variable))
        else:
            if ends[0] != ends[1]:
                found.append(f"connection {start}.{output} -> {end}.{input_}: a {ends[0]} into a {ends[1]}")
    return found


def _value_text(value: float | int | bool | str) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(float(value)) if isinstance(value, float) else str(value)


def _exposed(system: SspSystem, descriptions: Mapping[str, ET.Element]) -> tuple[list, list]:
    """(container inputs, container outputs) as ``(component, variable)``: every parameter and input no
    connection feeds, every output, in the package's order."""
    connected = {end for _, end in system.connections}
    inputs, outputs = [], []
    for component in system.components:
        for name, variable in _variables(descriptions[component.name]).items():
            causality = variable.get("causality")
            if causality == "parameter" or (causality == "input" and (component.name, name) not in connected):
                inputs.append((component.name, name))
            elif causality == "output":
                outputs.append((component.name, name))
    return inputs, outputs


def _bindings_once(configuration: bytes) -> bytes:
    """The container's ``container.txt`` with every start value applied once, at instantiation: the toolbox
    marks an input's start value to be applied again on entering initialisation (``<RESET>`` 1), which
    undid a value a host had set before (fmpy and fmusim set start values there); a parameter's is applied
    once already. Every start value here is a package binding of a variable the container exposes."""
    lines = configuration.decode().split("\n")
    section = False
    for i, line in enumerate(lines):
        if line.startswith("#"):
            section = line.startswith("# Start values of ")
            count = None
        elif section and count is None:
            count = line
        elif section:
            vr, dim, _, value = line.split(" ", 3)
            lines[i] = f"{vr} {dim} 0 {value}"
    return "\n".join(lines).encode()


def _master_order(configuration: bytes, system: SspSystem) -> bytes:
    """The container's ``container.txt`` initialising its components in the order in which the project's master
    reads their outputs inside initialisation: the order of the package's connections (the first connection
    leaving each), the components no connection reads last. Each component's inputs then hold, as it leaves
    initialisation, the values the master gives it (the toolbox's order of links let the launch's joints start
    from the package's bound bend angle, a few units in the last place from the bend the mounts compute, and the
    runs parted by 5e-8 relative over 2 s)."""
    lines = configuration.decode().split("\n")
    heading = lines.index("# NB of embedded FMU's")
    count = int(lines[heading + 1].split()[0])
    names = [lines[heading + 2 + 3 * k].split()[0].removesuffix(".fmu") for k in range(count)]
    first_read = list(dict.fromkeys(start for (start, _), _ in system.connections))
    order = first_read + [name for name in names if name not in first_read]
    at = lines.index("# Initialization order of the embedded FMU's") + 1
    lines[at] = " ".join(str(names.index(name)) for name in order)
    return "\n".join(lines).encode()


def _describe(built: bytes, system: SspSystem, descriptions: Mapping[str, ET.Element],
              others: Mapping[str, bytes], shown: Collection[str] = ()) -> bytes:
    """The container's model description made a project FMU's: the links' local variables dropped (hosts
    see the components' outputs under their own names), the outputs not ``shown`` (if any are) made local
    variables, each exposed variable with the unit, bounds and
    description of its component's, the units defined, the package's name and stop time, no build time or
    user, a token from the contents."""
    root = ET.fromstring(built)
    variables = root.find("ModelVariables")
    for variable in [v for v in variables if v.get("causality") == "local"]:
        variables.remove(variable)
    hidden = [v for v in variables if shown and v.get("causality") == "output" and v.get("name") not in shown]
    for variable in hidden:
        variable.set("causality", "local")
    units: dict[str, ET.Element] = {}
    for component in system.components:
        definitions = descriptions[component.name].find("UnitDefinitions")
        for unit in definitions if definitions is not None else ():
            units.setdefault(unit.get("name", ""), unit)
    for variable in variables:
        component, dot, name = variable.get("name", "").partition(".")
        if not dot or component not in descriptions:
            continue
        embedded = _variables(descriptions[component]).get(name)
        target, source = _type_element(variable), _type_element(embedded)
        for attribute in TYPE_ATTRIBUTES:
            if source.get(attribute) is not None:
                target.set(attribute, source.get(attribute))
        if embedded.get("description"):
            variable.set("description", f"{component}: {embedded.get('description')}")
    used = {_type_element(v).get(a) for v in variables for a in ("unit", "displayUnit")} - {None}
    if used:
        definitions = ET.Element("UnitDefinitions")
        definitions.extend(units[name] for name in sorted(units) if name in used)
        root.insert(list(root).index(root.find("CoSimulation")) + 1, definitions)
    if root.get("fmiVersion") == "2.0":
        positions = {id(v): i for i, v in enumerate(variables, start=1)}
        structure = root.find("ModelStructure")
        outputs = [v for v in variables if v.get("causality") == "output"]
        for section in list(structure):
            structure.remove(section)
        if outputs:
            for section in ("Outputs", "InitialUnknowns"):
                ET.SubElement(structure, section).extend(
                    ET.Element("Unknown", index=str(positions[id(v)])) for v in outputs)
    else:
        structure, references = root.find("ModelStructure"), {v.get("valueReference") for v in hidden}
        for unknown in [u for u in structure if u.get("valueReference") in references]:
            structure.remove(unknown)
    names = ", ".join(f"{c.name} ({descriptions[c.name].get('modelName')})" for c in system.components)
    root.set("description", f"The SSP system {system.name} as one co-simulation FMU (FMU Manipulation Toolbox's "
                            f"container): {names}")
    root.set("author", AUTHOR)
    root.set("license", "MIT")
    root.set("copyright", "the embedded FMUs' own")
    root.attrib.pop("generationDateAndTime", None)
    token = "guid" if root.get("fmiVersion") == "2.0" else "instantiationToken"
    root.set(token, "")
    root.set(token, archive.content_token(ET.tostring(root), others))
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def build(system: SspSystem, fmus: Mapping[str, Path], target: Path, step_size: float, fmi_version: int = 2,
          sequential: bool = False, shown: Collection[str] = ()) -> Path:
    """The container FMU of ``system`` at ``target``, its components' FMUs ``{component: path}``, stepping at
    ``step_size`` (Jacobi, or ``sequential``: in the package's order), its outputs those ``shown``
    (``component.variable``; empty: every one) and the others local variables; :class:`ContainerRefused` for
    what it cannot carry."""
    from fmu_manipulation_toolbox.container import FMUContainer, FMUContainerError

    descriptions = model_descriptions(system, fmus)
    reasons = refusals(system, descriptions)
    if reasons:
        raise ContainerRefused(f"{system.name}: the container cannot carry {'; '.join(reasons)}")
    inputs, outputs = _exposed(system, descriptions)
    unknown = sorted(set(shown) - {f"{component}.{name}" for component, name in outputs})
    if unknown:
        raise ContainerRefused(f"{system.name}: no output {', '.join(unknown)} to show")
    log = logging.getLogger(TOOLBOX)
    handlers, propagate, level = log.handlers[:], log.propagate, log.level
    messages: list[logging.LogRecord] = []
    collector = logging.Handler(logging.WARNING)
    collector.emit = messages.append
    log.handlers, log.propagate = [collector], False
    log.setLevel(logging.WARNING)
    try:
        with tempfile.TemporaryDirectory(prefix="driveline-container-") as scratch:
            folder = Path(scratch)
            for component in system.components:
                (folder / f"{component.name}.fmu").write_bytes(Path(fmus[component.name]).read_bytes())
            container = FMUContainer(system.name, folder, fmi_version=fmi_version)
            container.stop_time = system.stop_time
            container.start_time = 0.0
            embedded = {c.name: container.get_fmu(f"{c.name}.fmu") for c in system.components}
            if any(fmu.is_me for fmu in embedded.values()):
                raise ContainerRefused(f"{system.name}: the toolbox embeds {', '.join(n for n, f in embedded.items() if f.is_me)} "
                                       "as Model Exchange")
            for component, name in inputs:
                container.add_input(f"{component}.{name}", f"{component}.fmu", name)
            for component, name in outputs:
                container.add_output(f"{component}.fmu", name, f"{component}.{name}")
            for (start, output), (end, input_) in system.connections:
                container.add_link(f"{start}.fmu", output, f"{end}.fmu", input_)
            for component in system.components:
                for name, value in component.parameters.items():
                    container.add_start_value(f"{component.name}.fmu", name, _value_text(value))
            container.make_fmu(f"{system.name}.fmu", step_size, sequential=sequential)
            with zipfile.ZipFile(folder / f"{system.name}.fmu") as built:
                members = {info.filename: built.read(info) for info in built.infolist()
                           if not info.is_dir() and not EMBEDDED_EXTRAS.match(info.filename)}
    except FMUContainerError as error:
        raise ContainerRefused(f"{system.name}: the container cannot carry it: {error.reason}") from None
    finally:
        log.handlers, log.propagate = handlers, propagate
        log.setLevel(level)
    errors = [record.getMessage() for record in messages if record.levelno >= logging.ERROR]
    if errors:
        raise ContainerRefused(f"{system.name}: the container refused {'; '.join(errors)}")
    members.update(documentation.members(system.name))
    members[CONFIGURATION] = _master_order(_bindings_once(members[CONFIGURATION]), system)
    others = {name: data for name, data in members.items() if name != "modelDescription.xml"}
    members["modelDescription.xml"] = _describe(members["modelDescription.xml"], system, descriptions, others, shown)
    archive.write_zip(target, members)
    return target


def run(fmu: Path, start_values: Mapping[str, float | int | bool], stop_time: float, step_size: float,
        outputs: Sequence[str], every: int = 1, unpacked: tuple[str, ModelDescription] | None = None) -> np.ndarray:
    """Run the container ``fmu`` whose step is ``step_size`` with ``start_values`` (``component.variable``), stepping
    it ``every`` container steps at once: rows of t_k and ``outputs`` at every such step up to ``stop_time``
    (one FMI call per step and per read: the container's components exchange their values in C). ``unpacked``:
    the FMU's extracted folder and parsed description, kept after the run. A refused step raises
    :class:`fmu_harness.runs.runner.StepRefused` with the component's own message."""
    instance = FmuInstance(fmu, "system", *(unpacked or (None, None)))
    try:
        instance.initialize(start_values)
        interval = step_size * every
        count = int(round(stop_time / interval))
        if instance.fmi_version == "2.0":
            rows = _fmi2_rows(instance, outputs, count, interval)
        else:
            read, rows = instance.reader(tuple(outputs)), []
            for k in range(count):
                instance.time = k * interval
                instance.step(interval)
                rows.append(read())
        times = (np.arange(count) + 1.0) * interval
        return np.column_stack([times, np.array(rows, dtype=float).reshape(count, len(outputs))])
    finally:
        instance.close()


def _fmi2_rows(instance: FmuInstance, outputs: Sequence[str], count: int, interval: float) -> np.ndarray:
    """The run's rows from FMI 2.0's doStep and getReal called directly, without fmpy's wrapper of each call (a
    sixth of a launch's cost in the map); a status beyond Warning raises :class:`StepRefused` as
    :meth:`FmuInstance.step` does."""
    references = (ctypes.c_uint * len(outputs))(*(instance.variables[name].valueReference for name in outputs))
    values = (ctypes.c_double * len(outputs))()
    do_step, get_real, component = instance.fmu.dll.fmi2DoStep, instance.fmu.dll.fmi2GetReal, instance.fmu.component
    rows = np.empty((count, len(outputs)))
    step = ctypes.c_double(interval)
    for k in range(count):
        instance.time = k * interval
        first = len(instance.log)
        status = do_step(component, ctypes.c_double(instance.time), step, fmi2True)
        call = "doStep"
        if status <= WARNING:
            status, call = get_real(component, references, len(outputs), values), "getReal"
        if status > WARNING:
            raise StepRefused(call, status_name(status), instance.time, instance.messages_since(first))
        rows[k] = values
    return rows
