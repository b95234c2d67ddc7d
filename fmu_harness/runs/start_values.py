"""Start values checked before an engine starts: the model's own validation, in the FMU's words.

An FMU refuses a parameter that no input can make valid at ``ExitInitializationMode``: the native
FMUs return Error there, and libcosim turns that Error into an uncaught C++ exception that aborts
the host process (docs/hosting.md). Every place of the project that starts an engine (the
importers' sessions, the system master, sweeps) therefore first gives the start values to the
catalog model of each FMU, whose checks (the spec's bounds and relations, then the model's own,
``SteppedModel.parameter_errors`` and ``input_errors``, as ``SteppedModel.initialize``) are the code
the FMUs run, and stops with the first reason.

Usage: ``driveline-fmus check TARGET [NAME=VALUE ...]``, TARGET an SSP package (its parameter
bindings) or an FMU (the values given, ``beta=0.3``): prints what would be refused in one line,
``driveline-fmus check: refused: instance (Model): reason``, and exits with 1 (as ``driveline-fmus
system`` does for the same values), or prints that every start value is accepted and the platforms
whose binaries each FMU carries (the folders of its ``binaries/``).
"""

from __future__ import annotations

import zipfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from xml.etree import ElementTree as ET

from fmpy import read_model_description

from driveline.catalog import MODELS

from .ssp import bindings
from .ssp_package import read
from ..console import CommandParser, refused, summary
from ..packaging.toolchain import platforms_sentence

_KINDS = {"Real": float, "Integer": int, "Boolean": lambda text: str(text).lower() in ("true", "1"), "String": str}


class StartValuesRefused(ValueError):
    """Start values an FMU would refuse at initialisation; the message is one line, the
    instance's name and the FMU's first reason."""


@dataclass(frozen=True)
class Instance:
    """One FMU instance an engine is to start: its name, catalog model and start values."""

    name: str
    model: str
    values: Mapping[str, Any]


def refusals(model: str, values: Mapping[str, Any], declared_only: bool = False) -> list[str]:
    """Why the FMU of catalog model ``model`` would refuse the start values ``values`` (parameters
    and inputs by name) at initialisation, in its own words: the parameters' checks, then the
    inputs' (an input's start value beyond its bounds or relations, ``beta`` above ``beta_max``, is
    refused at ``ExitInitializationMode`` too; an input left out is at its declared start); [] when
    it takes them or when the model is not in the catalog (nothing to check it with).
    ``declared_only``: the spec's bounds and relations alone, of the parameters and then of the inputs,
    not the model's own checks (``CriticalSpeeds`` analyses the structure there, 0.04 to 0.5 s)."""
    model_class = MODELS.get(model)
    if model_class is None:
        return []
    core = model_class()
    for name, value in values.items():
        variable = next((v for v in core.spec.variables if v.name == name), None)
        if variable is None or variable.causality not in ("parameter", "input"):
            return [f"{name} is no parameter or input of {model}"]
        try:
            setattr(core, name, _KINDS[variable.type](value))
        except (TypeError, ValueError):
            return [f"{name} = {value!r} is not of type {variable.type}"]
    if declared_only:
        return core.declared_parameter_errors() or core.declared_input_errors()
    return core.parameter_errors() + core.input_errors()


def check_start_values(instances: list[Instance]) -> None:
    """Raise :class:`StartValuesRefused` for the first instance whose FMU would refuse its start
    values (one line: the instance, the FMU's first reason, how many more there are)."""
    for instance in instances:
        reasons = refusals(instance.model, instance.values)
        if reasons:
            more = f" (and {len(reasons) - 1} more)" if len(reasons) > 1 else ""
            raise StartValuesRefused(f"{instance.name} ({instance.model}): {reasons[0]}{more}")


def engine_instances(fmus: Mapping[str, Path] | None = None, ssp: Path | None = None,
                     start_values: Mapping[str, Any] | None = None) -> list[Instance]:
    """The instances an engine starts, as the importers' sessions take them: the FMUs ``{instance:
    path}`` or the components of an SSP package (with its parameter bindings), each with its
    share of ``start_values`` (``"instance.variable"``: value) on top."""
    given: dict[str, dict[str, Any]] = {}
    for key, value in (start_values or {}).items():
        instance, _, name = key.partition(".")
        given.setdefault(instance, {})[name] = value
    found = [Instance(*component) for component in bindings(ssp)] if ssp is not None else [
        Instance(name, read_model_description(str(path)).modelName, {}) for name, path in (fmus or {}).items()]
    fed = _connected_inputs(found, read(ssp).connections) if ssp is not None else {}
    return [Instance(i.name, i.model, {**fed.get(i.name, {}), **i.values, **given.get(i.name, {})}) for i in found]


def _connected_inputs(instances: list[Instance], connections: list[tuple[tuple[str, str], tuple[str, str]]]
                      ) -> dict[str, dict[str, Any]]:
    """The inputs a connection feeds, by instance, each at the declared start of the output feeding it:
    what an engine sets it to before ``ExitInitializationMode`` (not the input's own start); an output
    of a model outside the catalog is left out."""
    models = {i.name: MODELS.get(i.model) for i in instances}
    fed: dict[str, dict[str, Any]] = {}
    for (source, output), (target, name) in connections:
        model = models.get(source)
        variable = next((v for v in model.spec.variables if v.name == output), None) if model else None
        if variable is not None:
            fed.setdefault(target, {})[name] = variable.start
    return fed


def main(argv: list[str] | None = None) -> None:
    parser = CommandParser(description=summary(__doc__))
    parser.add_argument("target", type=Path, help="an SSP package or an FMU")
    parser.add_argument("values", nargs="*", metavar="NAME=VALUE", help="start values of an FMU")
    args = parser.parse_args(argv)
    if any("=" not in value for value in args.values) or (args.values and args.target.suffix.lower() == ".ssp"):
        parser.error("start values are NAME=VALUE, for an FMU (an SSP package brings its own)")
    if not args.target.is_file():
        parser.error(f"{args.target}: no such file")
    try:
        values = {f"{args.target.stem}.{value.partition('=')[0]}": value.partition("=")[2] for value in args.values}
        if args.target.suffix.lower() == ".ssp":
            instances = engine_instances(ssp=args.target)
        else:
            instances = engine_instances({args.target.stem: args.target}, start_values=values)
        check_start_values(instances)
    except StartValuesRefused as refusal:
        raise refused(parser.prog, str(refusal)) from None
    except (OSError, KeyError, ValueError, zipfile.BadZipFile, ET.ParseError) as error:
        parser.error(f"{args.target}: cannot be read ({type(error).__name__}: {error})")
    print(f"{args.target}: every start value accepted ({', '.join(i.name for i in instances)})")
    for fmu, members in fmu_members(args.target).items():
        print(f"{fmu}: {platforms_sentence(members)}")


def fmu_members(target: Path) -> dict[str, list[str]]:
    """The file names in each FMU of ``target``: an FMU's own, or those of every FMU an SSP package holds
    (by its path in the package)."""
    with zipfile.ZipFile(target) as archive:
        if target.suffix.lower() != ".ssp":
            return {target.name: archive.namelist()}
        found = {}
        for name in sorted(n for n in archive.namelist() if n.lower().endswith(".fmu")):
            with archive.open(name) as data, zipfile.ZipFile(data) as fmu:
                found[name] = fmu.namelist()
        return found


if __name__ == "__main__":
    main()
