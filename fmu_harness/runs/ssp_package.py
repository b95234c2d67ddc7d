"""Any SSP 1.0 package of FMUs, read for a master: its components (each FMU's path in the package, its
parameter bindings), its connections and its default stop time; and a copy with parameters changed.

Read are what the project's packages hold and what a simple package by another tool holds: inline
``ParameterBindings`` (``ssv:ParameterSet``) and components whose ``source`` is an FMU inside the
package. A package beyond that (nested systems, referenced parameter files) is refused by name.
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree as ET

from .ssp import SSD, SSV

STRUCTURE = "SystemStructure.ssd"
TYPES = ("Real", "Integer", "Boolean", "String")


class PackageError(ValueError):
    """What is wrong with a package or a change asked of it, in one line."""


@dataclass
class SspComponent:
    name: str
    source: str  # the FMU's path inside the package
    parameters: dict[str, float | int | bool | str] = field(default_factory=dict)


@dataclass
class SspSystem:
    name: str
    components: list[SspComponent]
    connections: list[tuple[tuple[str, str], tuple[str, str]]]
    stop_time: float | None
    parameter_set: str | None  # the name of the first inline parameter set (Ecos applies one by name)

    def component(self, name: str) -> SspComponent:
        for component in self.components:
            if component.name == name:
                return component
        raise PackageError(f"the system has no component {name!r} (it has {', '.join(self.names())})")

    def names(self) -> list[str]:
        return [c.name for c in self.components]


def _value(element: ET.Element) -> float | int | bool | str:
    kind = element.tag.rpartition("}")[2]
    text = element.get("value", "")
    try:
        read = {"Real": float, "Integer": int, "Boolean": lambda s: s.strip() in ("true", "1"), "String": str}
        return read[kind](text)
    except (KeyError, ValueError):
        raise PackageError(f"parameter value {text!r} of type {kind} cannot be read") from None


def _bindings(element: ET.Element, component: str) -> dict[str, float | int | bool | str]:
    values: dict[str, float | int | bool | str] = {}
    for binding in element.iter(f"{{{SSD}}}ParameterBinding"):
        if binding.get("source"):
            raise PackageError(f"component {component}: parameter bindings from a file ({binding.get('source')}) "
                               "are not supported; bind them inline")
        for parameter in binding.iter(f"{{{SSV}}}Parameter"):
            typed = [child for child in parameter if child.tag.rpartition("}")[2] in TYPES]
            if typed:
                values[parameter.get("name", "")] = _value(typed[0])
    return values


def read(path: Path) -> SspSystem:
    """The system of the package at ``path``; :class:`PackageError` naming what cannot be read."""
    try:
        with zipfile.ZipFile(path) as archive:
            root = ET.fromstring(archive.read(STRUCTURE))
            members = set(archive.namelist())
    except FileNotFoundError:
        raise PackageError(f"{path}: no such file") from None
    except (zipfile.BadZipFile, IsADirectoryError, PermissionError) as error:
        raise PackageError(f"{path}: not an SSP package ({error})") from None
    except KeyError:
        raise PackageError(f"{path}: the package holds no {STRUCTURE}") from None
    except ET.ParseError as error:
        raise PackageError(f"{path}: {STRUCTURE} is no XML ({error})") from None
    system = root.find(f"{{{SSD}}}System")
    if system is None:
        raise PackageError(f"{path}: {STRUCTURE} describes no system")
    components = []
    for element in system.iterfind(f"{{{SSD}}}Elements/*"):
        name = element.get("name", "")
        if element.tag != f"{{{SSD}}}Component":
            raise PackageError(f"{path}: element {name!r} is a nested system, which is not supported")
        source = element.get("source", "")
        if source not in members:
            raise PackageError(f"{path}: component {name!r} names {source!r}, which the package does not hold")
        components.append(SspComponent(name, source, _bindings(element, name)))
    connections = [((c.get("startElement", ""), c.get("startConnector", "")),
                    (c.get("endElement", ""), c.get("endConnector", "")))
                   for c in system.iterfind(f"{{{SSD}}}Connections/{{{SSD}}}Connection")]
    experiment = root.find(f"{{{SSD}}}DefaultExperiment")
    stop = experiment.get("stopTime") if experiment is not None else None
    parameter_set = root.find(f".//{{{SSV}}}ParameterSet")
    return SspSystem(system.get("name") or root.get("name") or path.stem, components, connections,
                     float(stop) if stop else None, parameter_set.get("name") if parameter_set is not None else None)


def _typed_element(kind: str, value: float | int | bool | str) -> ET.Element:
    text = repr(float(value)) if kind == "Real" else ("true" if value else "false") if kind == "Boolean" else str(value)
    return ET.Element(f"{{{SSV}}}{kind}", value=text)


def with_parameters(path: Path, changes: dict[tuple[str, str], tuple[str, float | int | bool | str]],
                    target: Path) -> Path:
    """A copy of the package at ``target`` whose bindings set ``{(component, variable): (type, value)}``,
    added to the component's inline parameter set (one is made where it has none)."""
    with zipfile.ZipFile(path) as archive:
        root = ET.fromstring(archive.read(STRUCTURE))
        members = [(info, archive.read(info)) for info in archive.infolist() if info.filename != STRUCTURE]
    system = root.find(f"{{{SSD}}}System")
    name = system.get("name", "parameters")
    for (component_name, variable), (kind, value) in changes.items():
        component = next(e for e in system.iterfind(f"{{{SSD}}}Elements/{{{SSD}}}Component")
                         if e.get("name") == component_name)
        parameters = component.find(f".//{{{SSV}}}Parameters")
        if parameters is None:
            bindings = component.find(f"{{{SSD}}}ParameterBindings")
            if bindings is None:
                bindings = ET.SubElement(component, f"{{{SSD}}}ParameterBindings")
            values = ET.SubElement(ET.SubElement(bindings, f"{{{SSD}}}ParameterBinding"), f"{{{SSD}}}ParameterValues")
            parameters = ET.SubElement(ET.SubElement(values, f"{{{SSV}}}ParameterSet", version="1.0", name=name),
                                       f"{{{SSV}}}Parameters")
        parameter = next((p for p in parameters if p.get("name") == variable), None)
        if parameter is None:
            parameter = ET.SubElement(parameters, f"{{{SSV}}}Parameter", name=variable)
        for child in list(parameter):
            parameter.remove(child)
        parameter.append(_typed_element(kind, value))
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr(STRUCTURE, ET.tostring(root, encoding="UTF-8", xml_declaration=True))
        for info, data in members:
            archive.writestr(info, data)
    return target

