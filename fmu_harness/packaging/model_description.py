"""Completes the model description that pythonfmu or pythonfmu3 writes, from the model's spec.

The one place where units, display units, ranges, descriptions and the initial
unknowns are added; the FMI 2.0 build calls :func:`complete_fmi2`, the FMI 3.0 build
:func:`complete_fmi3`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable

from driveline.variables import ModelSpec, Unit, Variable


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
    structure: Callable[[ET.Element, list[tuple[int, ET.Element]]], None],
) -> bytes:
    """Add units, descriptions and attributes to ``variables`` (pairs of the variable's element
    and the element that carries unit, min and max, in document order) and rebuild the model
    structure with ``structure`` from the outputs' 1-based indices and elements."""
    if spec.units:
        unit_definitions = ET.Element("UnitDefinitions")
        unit_definitions.extend(_unit_element("Unit", unit) for unit in spec.units)
        root.insert(list(root).index(root.find("CoSimulation")) + 1, unit_definitions)
    outputs = []
    references = {element.get("name"): element.get("valueReference") for element, _ in variables}
    fmi3 = root.get("fmiVersion", "").startswith("3")
    for index, (element, typed) in enumerate(variables, start=1):
        variable = spec[element.get("name")]
        element.set("description", variable.description)
        typed.attrib.update(_type_attributes(variable))
        if variable.causality != "output" and variable.type != "String":  # pythonfmu writes 16 digits
            typed.set("start", number_text(variable.start))
        if fmi3 and variable.derivative is not None:  # FMI 3.0: an input's derivative is an input too
            element.set("derivative", references[variable.derivative])
        if variable.causality == "output":
            outputs.append((index, element))
    model_structure = root.find("ModelStructure")
    for child in list(model_structure):
        model_structure.remove(child)
    structure(model_structure, outputs)
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def _fmi2_structure(model_structure: ET.Element, outputs: list[tuple[int, ET.Element]]) -> None:
    if outputs:
        for tag in ("Outputs", "InitialUnknowns"):
            unknowns = ET.SubElement(model_structure, tag)
            unknowns.extend(ET.Element("Unknown", index=str(index)) for index, _ in outputs)


def _fmi3_structure(model_structure: ET.Element, outputs: list[tuple[int, ET.Element]]) -> None:
    for tag in ("Output", "InitialUnknown"):
        model_structure.extend(ET.Element(tag, valueReference=output.get("valueReference")) for _, output in outputs)


def complete_fmi2(xml: bytes, spec: ModelSpec) -> bytes:
    """Return pythonfmu's FMI 2.0 model description with the spec's details added."""
    root = ET.fromstring(xml)
    scalars = root.find("ModelVariables").findall("ScalarVariable")
    variables = [(scalar, scalar.find(spec[scalar.get("name")].type)) for scalar in scalars]
    return _complete(root, spec, variables, _fmi2_structure)


def complete_fmi3(xml: bytes, spec: ModelSpec) -> bytes:
    """Return pythonfmu3's FMI 3.0 model description with the spec's details added (in FMI 3.0
    unit, min and max are attributes of the variable element itself; the adapter's independent
    variable ``time`` is not in the spec)."""
    root = ET.fromstring(xml)
    variables = [(element, element) for element in root.find("ModelVariables") if element.get("causality") != "independent"]
    return _complete(root, spec, variables, _fmi3_structure)
