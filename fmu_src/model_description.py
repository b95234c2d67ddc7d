"""Completes the model description that pythonfmu writes, from the model's spec.

The one place where units, display units, ranges, descriptions and the initial
unknowns are added; the FMI 2.0 build calls :func:`complete_fmi2`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from xml.dom.minidom import parseString

from driveline.variables import ModelSpec, Unit, Variable


def _number(value: float | int) -> str:
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
        attributes["min"] = _number(variable.min)
    if variable.max is not None:
        attributes["max"] = _number(variable.max)
    return attributes


def complete_fmi2(xml: bytes, spec: ModelSpec) -> bytes:
    """Return pythonfmu's FMI 2.0 model description with the spec's details added."""
    root = ET.fromstring(xml)
    if spec.units:
        unit_definitions = ET.Element("UnitDefinitions")
        unit_definitions.extend(_unit_element("Unit", unit) for unit in spec.units)
        root.insert(list(root).index(root.find("CoSimulation")) + 1, unit_definitions)

    scalars = root.find("ModelVariables").findall("ScalarVariable")
    outputs = []
    for index, scalar in enumerate(scalars, start=1):
        variable = spec[scalar.get("name")]
        scalar.set("description", variable.description)
        scalar.find(variable.type).attrib.update(_type_attributes(variable))
        if variable.causality == "output":
            outputs.append(str(index))

    structure = root.find("ModelStructure")
    for child in list(structure):
        structure.remove(child)
    if outputs:
        for tag in ("Outputs", "InitialUnknowns"):
            ET.SubElement(structure, tag).extend(ET.Element("Unknown", index=i) for i in outputs)
    return parseString(ET.tostring(root, encoding="UTF-8")).toprettyxml(indent="  ", encoding="UTF-8")
