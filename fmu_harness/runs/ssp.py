"""SSP 1.0 packages: the namespaces of their XML and what a package binds to its components."""

from __future__ import annotations

import zipfile
from pathlib import Path
from typing import Any
from xml.etree import ElementTree as ET

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"


def bindings(package: Path) -> list[tuple[str, str, dict[str, Any]]]:
    """``(component, model, {parameter: value text})`` of every component of the package: the
    model name of the FMU the package holds for it and the values of its parameter bindings."""
    with zipfile.ZipFile(package) as archive:
        structure = ET.fromstring(archive.read("SystemStructure.ssd"))
        found = []
        for component in structure.iter(f"{{{SSD}}}Component"):
            with zipfile.ZipFile(archive.open(component.get("source", ""))) as fmu:
                model = ET.fromstring(fmu.read("modelDescription.xml")).get("modelName", "")
            values = {parameter.get("name", ""): next(iter(parameter)).get("value")
                      for parameter in component.iter(f"{{{SSV}}}Parameter") if len(parameter)}
            found.append((component.get("name", ""), model, values))
    return found
