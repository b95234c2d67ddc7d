"""Completes the model description that pythonfmu or pythonfmu3 writes, from the model's spec.

The one place where units, display units, ranges, descriptions and the model structure
(outputs and initial unknowns with the ``dependencies`` the spec declares) are added; the FMI 2.0
build calls :func:`complete_fmi2`, the FMI 3.0 build :func:`complete_fmi3`, for the Python and
the native FMUs alike.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass

from driveline.variables import COMPUTED, ModelSpec, Unit, Variable


def number_text(value: float | int | bool) -> str:
    """A number as both families' model descriptions write it: a float's repr (the shortest text
    that reads back bit for bit), an integer as it is, a Boolean as XML's ``true``/``false``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(float(value)) if isinstance(value, float) else str(value)


def _unit_element(tag: str, unit: Unit) -> ET.Element:
    element = ET.Element(tag, name=unit.name)
    if unit.exponents:
        ET.SubElement(element, "BaseUnit", {k: str(v) for k, v in unit.exponents.items()})
    for display in unit.display_units:
        attributes = {"name": display.name, "factor": repr(display.factor)}
        if display.offset:
            attributes["offset"] = repr(display.offset)
        ET.SubElement(element, "DisplayUnit", attributes)
    return element


def _type_attributes(variable: Variable) -> dict[str, str]:
    attributes = {}
    if variable.unit is not None:
        attributes["unit"] = variable.unit
    if variable.display_unit is not None:
        attributes["displayUnit"] = variable.display_unit
    if variable.min is not None:
        attributes["min"] = number_text(variable.min)
    if variable.max is not None:
        attributes["max"] = number_text(variable.max)
    return attributes


def _complete(
    root: ET.Element,
    spec: ModelSpec,
    variables: list[tuple[ET.Element, ET.Element]],
    structure: Callable[[ET.Element, list[Unknown], list[Unknown], list[Unknown]], None],
) -> bytes:
    """Add units, descriptions and attributes to ``variables`` (pairs of the variable's element
    and the element that carries unit, min and max, in document order) and rebuild the model
    structure with ``structure`` from the 1-based indices, elements and dependencies of the outputs,
    the state derivatives and the initial unknowns. A description with a ``<ModelExchange>`` element has the states'
    derivatives ``der(<state>)`` among its variables (written complete), its states their
    ``nominal``, and its outputs depend on the states too; a state that is a local is an initial unknown
    there (FMI 2.0 and 3.0: every continuous state whose initial value is calculated), and a local
    appears nowhere else in the structure."""
    if spec.units:
        unit_definitions = ET.Element("UnitDefinitions")
        unit_definitions.extend(_unit_element("Unit", unit) for unit in spec.units)
        root.insert(list(root).index(root.find("CoSimulation")) + 1, unit_definitions)
    outputs, local_states = [], []
    references = {element.get("name"): element.get("valueReference") for element, _ in variables}
    indices = {element.get("name"): index for index, (element, _) in enumerate(variables, start=1)}
    fmi3 = root.get("fmiVersion", "").startswith("3")
    states = root.find("ModelExchange") is not None

    def known(names: tuple[str, ...]) -> list[tuple[int, str]]:
        return [(indices[name], references[name]) for name in names]

    nominals = {state.name: state.nominal for state in spec.states if states}
    derivatives = [Unknown(indices[state.derivative_name], variables[indices[state.derivative_name] - 1][0],
                           known(spec.derivative_dependencies(state)),
                           known(spec.derivative_dependencies(state, initial=True)))
                   for state in spec.states if states]
    for index, (element, typed) in enumerate(variables, start=1):
        if element.get("name") not in {v.name for v in spec.variables}:
            continue
        variable = spec[element.get("name")]
        element.set("description", variable.description)
        typed.attrib.update(_type_attributes(variable))
        if variable.name in nominals:  # a continuous state: its typical magnitude, the solver's scale
            typed.set("nominal", number_text(nominals[variable.name]))
        if variable.causality not in COMPUTED and variable.type != "String":  # pythonfmu writes 16 digits
            typed.set("start", number_text(variable.start))
        if fmi3 and variable.derivative is not None:  # FMI 3.0: an input's derivative is an input too
            element.set("derivative", references[variable.derivative])
        if variable.causality == "output":
            outputs.append(Unknown(index, element, known(spec.output_dependencies(variable.name, states)),
                                   known(spec.initial_dependencies(variable.name))))
        elif variable.causality == "local" and variable.name in nominals:
            local_states.append(Unknown(index, element, [], known(spec.initial_dependencies(variable.name))))
    model_structure = root.find("ModelStructure")
    for child in list(model_structure):
        model_structure.remove(child)
    initial_unknowns = sorted(outputs + local_states, key=lambda unknown: unknown.index) + derivatives
    structure(model_structure, outputs, derivatives, initial_unknowns)
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


@dataclass(frozen=True)
class Unknown:
    """An output or a state derivative: its 1-based index, its element, and the (index, value
    reference) of each variable it depends on in step or continuous-time mode (inputs, states) and
    at initialisation (parameters and inputs)."""

    index: int
    element: ET.Element
    step: list[tuple[int, str]]
    initial: list[tuple[int, str]]


def _dependencies(known: list[str]) -> dict[str, str]:
    """``dependencies`` and ``dependenciesKind``: nonlinear ("dependent") on every known listed."""
    return {"dependencies": " ".join(known), "dependenciesKind": " ".join(["dependent"] * len(known))}


def _fmi2_structure(model_structure: ET.Element, outputs: list[Unknown], derivatives: list[Unknown],
                    initial_unknowns: list[Unknown]) -> None:
    for tag, unknowns, initial in (("Outputs", outputs, False), ("Derivatives", derivatives, False),
                                   ("InitialUnknowns", initial_unknowns, True)):
        if unknowns:
            ET.SubElement(model_structure, tag).extend(
                ET.Element("Unknown", index=str(unknown.index),
                           **_dependencies([str(index) for index, _ in (unknown.initial if initial else unknown.step)]))
                for unknown in unknowns)


def _fmi3_structure(model_structure: ET.Element, outputs: list[Unknown], derivatives: list[Unknown],
                    initial_unknowns: list[Unknown]) -> None:
    for tag, unknowns, initial in (("Output", outputs, False), ("ContinuousStateDerivative", derivatives, False),
                                   ("InitialUnknown", initial_unknowns, True)):
        model_structure.extend(
            ET.Element(tag, valueReference=unknown.element.get("valueReference"),
                       **_dependencies([reference for _, reference in (unknown.initial if initial else unknown.step)]))
            for unknown in unknowns)


def complete_fmi2(xml: bytes, spec: ModelSpec) -> bytes:
    """Return pythonfmu's FMI 2.0 model description with the spec's details added."""
    root = ET.fromstring(xml)
    scalars = root.find("ModelVariables").findall("ScalarVariable")
    variables = [(scalar, scalar.find("Real") if scalar.get("name").startswith("der(") else
                  scalar.find(spec[scalar.get("name")].type)) for scalar in scalars]
    return _complete(root, spec, variables, _fmi2_structure)


def complete_fmi3(xml: bytes, spec: ModelSpec) -> bytes:
    """Return pythonfmu3's FMI 3.0 model description with the spec's details added (in FMI 3.0
    unit, min and max are attributes of the variable element itself; the adapter's independent
    variable ``time`` is not in the spec)."""
    root = ET.fromstring(xml)
    variables = [(element, element) for element in root.find("ModelVariables") if element.get("causality") != "independent"]
    return _complete(root, spec, variables, _fmi3_structure)
