"""Native (C) co-simulation FMUs, FMI 2.0 and 3.0, generated from the same specs as the Python FMUs.

The C sources lie by role under ``fmu_src/native/``: ``fmi/`` the shared FMI 2.0/3.0 layer, ``lib/`` the
libraries more than one model uses, ``models/<model_in_snake_case>/`` one folder per model. A model is
native when its folder holds ``<model_in_snake_case>.c``, the port of its physics, and every module
the folder's headers list (:func:`library_modules`); the others are skipped. For each native model
and FMI version this module

* generates ``model_variables.h``/``.c`` from the spec: the variable table (value reference =
  position in the spec, as in the Python FMUs) and the range checks' messages, cut from
  :meth:`driveline.model.SteppedModel._range_error` itself so the wording exists once, and the
  messages of the model's own checks, cut from them run on the model's ``extra_parameter_probes``;
* generates the model description with the Python FMUs' own completion
  (:mod:`model_description`: units, display units, min/max, descriptions, model structure), so a
  host can swap one FMU for the other, plus the sources the FMU carries (FMI 2.0 ``SourceFiles``,
  FMI 3.0 ``sources/buildDescription.xml``);
* compiles the shared library for each platform (:mod:`.toolchain`: zig, five platforms) with
  the FMI headers fmpy installs (``fmpy/c-code``), warnings as errors, and packs the FMU with its
  sources: the layer, the model's folder and the files of ``lib/`` they include (:func:`used_library`),
  by their paths below ``fmu_src/native/``, the generated files at the top (the one include folder a
  host needs, as fmpy's ``build_platform_binary`` gives it); then the resource files its model class
  declares (``SteppedModel.resource_files``, into ``resources/``), its doc page and the licence.

FMI 2.0 FMUs land in ``<dest>/native/``, FMI 3.0 ones in ``<dest>/native/fmi3/``.
"""

from __future__ import annotations

import hashlib
import math
import re
import sys
import tempfile
import textwrap
import uuid
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import fmpy

import fmu_src
from driveline import __version__
from driveline.catalog import MODELS
from driveline.model import TIME_TOLERANCE, SteppedModel
from driveline.variables import COMPUTED, UNITS, ModelSpec, Relation, Variable

from ..console import Progress
from . import documentation, toolchain
from .archive import TOKEN_NAMESPACE, write_zip
from .documentation import snake_case
from .model_description import complete_fmi2, complete_fmi3, number_text
from .native_constants import HEADER as CONSTANTS_HEADER
from .native_constants import constants_header

#: The model description's generationTool of a native FMU
GENERATION_TOOL = "driveline-fmus native build"

NATIVE_SRC = Path(fmu_src.__file__).resolve().parent / "native"
#: The shared FMI layer, the libraries more than one model uses, the models' folders
LAYER_SOURCES, LIBRARY_SOURCES, MODEL_SOURCES = NATIVE_SRC / "fmi", NATIVE_SRC / "lib", NATIVE_SRC / "models"
#: Each FMI version's functions (the rest of the layer serves both)
LAYER = {"2": "fmi/fmi2_functions.c", "3": "fmi/fmi3_functions.c"}
SUBDIR = {"2": "native", "3": "native/fmi3"}
LOG_CATEGORIES = ("Warning", "Discard", "Error", "Fatal")


def model_folder(name: str) -> Path:
    """The folder of a model's C port: its model file and its own library (modules and headers)."""
    return MODEL_SOURCES / snake_case(name)


def model_source(name: str) -> Path:
    return model_folder(name) / f"{snake_case(name)}.c"


_JACOBIAN_HOOK = re.compile(r"\.jacobian\s*=")


def provides_derivatives(name: str) -> bool:
    """The model's C port gives the ``jacobian`` hook (``.jacobian = ...`` in its ``model_hooks``): its FMU
    offers directional (and FMI 3.0 adjoint) derivatives and says so in its model description."""
    return bool(_JACOBIAN_HOOK.search(model_source(name).read_text()))


def jacobian_layout(spec: ModelSpec) -> tuple[list[str], list[str]]:
    """The rows of a model's Jacobian (its Real outputs and locals; the states' derivatives follow them) and its
    columns (its Real inputs and states), in spec order."""
    states = {state.name for state in spec.states}
    rows = [v.name for v in spec.of(*COMPUTED) if v.type == "Real"]
    columns = [v.name for v in spec.variables
               if v.type == "Real" and (v.causality == "input" or v.name in states)]
    return rows, columns


_MODULE_LINE = re.compile(r"^\s*\*\s+(\w+\.c)\s", re.MULTILINE)


def library_modules(name: str) -> list[str]:
    """The modules of a model's own library, as the headers of its folder list them: a comment line
    `` *   transfer.c   what it holds`` per module (rotor.h). None for a model whose folder has no header."""
    folder = model_folder(name)
    return sorted({module for header in folder.glob("*.h") for module in _MODULE_LINE.findall(header.read_text())})


def has_c_port(name: str) -> bool:
    """The model file exists and every module its folder's headers list."""
    if not model_source(name).exists():
        return False
    return all((model_folder(name) / module).is_file() for module in library_modules(name))


_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)


def included(source: Path, root: Path = NATIVE_SRC) -> list[Path]:
    """The files below ``root`` (``fmu_src/native/``, or an FMU's ``sources/``) that ``source`` includes: a
    name is looked up next to the file, then from ``root`` (the one include folder; in ``fmu_src/native/``
    the generated headers are not there, the FMI headers nowhere)."""
    found = []
    for name in _INCLUDE.findall(source.read_text()):
        for folder in (source.parent, root):
            if (folder / name).is_file():
                found.append((folder / name).resolve())
                break
    return found


def header_modules(header: Path) -> list[Path]:
    """The modules that define what ``header`` declares: those its comment lists (toml.h), else the
    module of its own name, if there is one."""
    names = _MODULE_LINE.findall(header.read_text()) or [header.with_suffix(".c").name]
    return [header.parent / module for module in names if (header.parent / module).is_file()]


def used_sources(starts: list[Path], root: Path = NATIVE_SRC) -> list[Path]:
    """``starts`` and every file below ``root`` they use: what they include, and the modules of each
    header included, followed to the end."""
    seen, pending = set(), [start.resolve() for start in starts]
    while pending:
        source = pending.pop()
        if source in seen:
            continue
        seen.add(source)
        pending += included(source, root)
        if source.suffix == ".h":
            pending += header_modules(source)
    return sorted(seen)


def used_library(name: str) -> list[Path]:
    """The files of ``lib/`` that the layer and the model's folder use."""
    roots = [*LAYER_SOURCES.glob("*.[ch]"), *model_folder(name).glob("*.[ch]")]
    return [path for path in used_sources(roots) if path.is_relative_to(LIBRARY_SOURCES.resolve())]


def native_models() -> list[str]:
    """The catalog models with a (complete) C port, in catalog order."""
    return [name for name in MODELS if has_c_port(name)]


def fmu_path(dest: Path, name: str, fmi: str = "2") -> Path:
    """Where :func:`build` puts the native FMU of ``name`` for FMI version ``fmi``."""
    return dest / SUBDIR[fmi] / f"{name}.fmu"


def library_path(unzipdir: Path, name: str, fmi: str, platform: toolchain.Platform) -> Path:
    """Where an extracted FMU holds its binary for ``platform``."""
    return unzipdir / "binaries" / platform.folder(fmi) / f"{name}{platform.suffix}"


def host_library(unzipdir: Path, name: str, fmi: str) -> Path:
    """The binary of an extracted FMU for this machine."""
    host = toolchain.host_platform()
    if host is None:
        raise RuntimeError("this machine is none of the native FMUs' platforms")
    return library_path(unzipdir, name, fmi, host)


def fmi_headers() -> Path:
    """The FMI 2.0 and 3.0 headers shipped with fmpy."""
    return Path(fmpy.__file__).parent / "c-code"


# -- the variable table in C --------------------------------------------------------------------

# A checked value enters a message through Python's repr() or, in a display unit, through
# format(factor * value + offset, ".6g"); these marks stand for either, so the wording can be cut
# from the Python checks themselves and the C side fills the values in the same way.
_SLOTS = {("value", "repr"): "SLOT_VALUE_REPR", ("value", "g6"): "SLOT_VALUE_DISPLAY",
          ("bound", "repr"): "SLOT_BOUND_REPR", ("bound", "g6"): "SLOT_BOUND_DISPLAY"}
_MARK = re.compile("\x00(value|bound):(repr|g6)\x00")


class _Marked(float):
    """A float that keeps its mark through the arithmetic of a display unit and prints as it."""

    role = "value"

    def __repr__(self) -> str:
        return f"\x00{self.role}:repr\x00"

    def __format__(self, spec: str) -> str:
        return f"\x00{self.role}:g6\x00"

    def _same(self, other: object) -> _Marked:
        return self

    __add__ = __radd__ = __mul__ = __rmul__ = __sub__ = __rsub__ = _same


class _MarkedInt(int):
    role = "value"

    def __repr__(self) -> str:
        return f"\x00{self.role}:repr\x00"


def _marked(variable: Variable, value: float, role: str = "value") -> float:
    marked = _MarkedInt(int(value)) if variable.type == "Integer" else _Marked(value)
    marked.role = role
    return marked


def _template(message: str | None) -> str:
    """A C message template (``{text, slot}`` pieces) from a message with marked values."""
    if message is None:
        raise ValueError("the probed check gave no message")
    pieces, rest = [], message
    while (found := _MARK.search(rest)) is not None:
        pieces.append(f"{{{_c_string(rest[:found.start()])}, {_SLOTS[found.group(1), found.group(2)]}}}")
        rest = rest[found.end():]
    pieces.append(f"{{{_c_string(rest)}, SLOT_END}}")
    return "{{" + ", ".join(pieces) + "}}"


_NO_MESSAGE = '{{{"", SLOT_END}}}'


def _range_message(variable: Variable, value: float) -> str:
    return _template(SteppedModel._range_error(SimpleNamespace(**{variable.name: _marked(variable, value)}), variable))


def _c_string(text: str) -> str:
    escaped = text.replace("\\", "\\\\").replace('"', '\\"')
    if any(ord(c) < 32 or ord(c) > 126 for c in escaped):
        raise ValueError(f"not plain ASCII: {text!r}")
    return f'"{escaped}"'


def _c_double(value: float) -> str:
    return repr(float(value)) if math.isfinite(value) else ("HUGE_VAL" if value > 0 else "-HUGE_VAL")


def _display(variable: Variable) -> tuple[float, float]:
    """Factor and offset of the variable's display unit (1, 0 without one)."""
    if variable.display_unit is None:
        return 1.0, 0.0
    display = next(d for d in UNITS[variable.unit].display_units if d.name == variable.display_unit)
    return display.factor, display.offset


def _table_entry(variable: Variable) -> str:
    if variable.type in ("Boolean", "String"):  # no bounds: only a start value
        start = "NULL" if variable.type == "Boolean" else _c_string(variable.start)
        number = float(bool(variable.start)) if variable.type == "Boolean" else 0.0
        return (
            f"    {{{_c_string(variable.name)}, VAR_{variable.type.upper()}, CAUSALITY_{variable.causality.upper()}, "
            f"{int(variable.effective_variability == 'tunable')}, {_c_double(number)},\n"
            f"     0, 0, 0, 0, 0.0, 0.0, 1.0, 0.0,\n     {_NO_MESSAGE},\n     {_NO_MESSAGE},\n     {_NO_MESSAGE},\n"
            f"     {start}}},"
        )
    if variable.type not in ("Real", "Integer"):
        raise ValueError(f"{variable.name}: the native FMUs hold Real, Integer, Boolean and String variables only")
    below = (lambda x: x - 1) if variable.type == "Integer" else (lambda x: math.nextafter(x, -math.inf))
    above = (lambda x: x + 1) if variable.type == "Integer" else (lambda x: math.nextafter(x, math.inf))
    has_min, has_max = variable.min is not None, variable.max is not None
    minimum = maximum = _NO_MESSAGE
    if has_min:
        minimum = _range_message(variable, variable.min if variable.min_exclusive else below(variable.min))
    if has_max:
        maximum = _range_message(variable, variable.max if variable.max_exclusive else above(variable.max))
    messages = [_range_message(variable, math.nan) if variable.type == "Real" else _NO_MESSAGE, minimum, maximum]
    factor, offset = _display(variable)
    return (
        f"    {{{_c_string(variable.name)}, VAR_{variable.type.upper()}, CAUSALITY_{variable.causality.upper()}, "
        f"{int(variable.effective_variability == 'tunable')}, {_c_double(float(variable.start))},\n"
        f"     {int(has_min)}, {int(has_max)}, {int(variable.min_exclusive)}, {int(variable.max_exclusive)}, "
        f"{_c_double(variable.min if has_min else 0.0)}, {_c_double(variable.max if has_max else 0.0)}, "
        f"{_c_double(factor)}, {_c_double(offset)},\n     " + ",\n     ".join(messages) + ",\n     NULL},"
    )


_OPERATORS = {"<": "OP_LT", "<=": "OP_LE", ">": "OP_GT", ">=": "OP_GE"}


def _relation_entry(spec: ModelSpec, relation: Relation) -> str:
    """One declared relation, its message cut from SteppedModel._relation_error on a violation."""
    left = spec[relation.lhs]
    right_variable = spec[relation.rhs] if isinstance(relation.rhs, str) else None
    violating = 1.0 if relation.op in ("<", "<=") else -1.0  # against a (marked) bound of 0
    values = {left.name: _marked(left, violating)}
    if right_variable is not None:
        values[right_variable.name] = _marked(right_variable, 0.0, "bound")
    probe = SimpleNamespace(spec=spec, **values)
    message = SteppedModel._relation_error(probe, relation)
    if right_variable is None:  # a constant bound is part of the text
        message = SteppedModel._relation_error(SimpleNamespace(spec=spec, **{left.name: values[left.name]}), relation)
    integer_bound = right_variable is not None and right_variable.type == "Integer" and relation.bound(1) == 1
    rhs_index = spec.variables.index(right_variable) if right_variable is not None else -1
    constant = relation.rhs if right_variable is None else 0.0
    return (
        f"    {{V_{left.name}, {_OPERATORS[relation.op]}, {rhs_index}, {_c_double(constant)}, "
        f"{_c_double(relation.scale)}, {_c_double(relation.offset)}, {int(integer_bound)}, "
        f"{int(spec.involves_input(relation))},\n     {_template(message)}}},"
    )


def _extra_message(model: type[SteppedModel], probe: dict[str, float]) -> str:
    """The message of one of ``model``'s own parameter checks, cut from the check run on its probe
    (the other parameters at their start values), with the first probed value marked."""
    spec = model.spec
    shown = next(iter(probe))
    values = {v.name: v.start for v in spec.variables} | probe
    values[shown] = _marked(spec[shown], probe[shown])
    errors = model.extra_parameter_errors(SimpleNamespace(**values))
    if len(errors) != 1:
        raise ValueError(f"{spec.name}: the probe {probe} gives {len(errors)} messages, not one")
    return f"    {{V_{shown}, {_template(errors[0])}}},"


def _checked_range(variable: Variable) -> str:
    """The closed interval of doubles in which ``variable`` needs no message of the range checks (a Real finite,
    an exclusive bound the next double inward), as a C initialiser of a CheckedRange."""
    real = variable.type == "Real"
    low, high = (-sys.float_info.max, sys.float_info.max) if real else (-math.inf, math.inf)
    if variable.min is not None:
        low = max(low, math.nextafter(variable.min, math.inf) if variable.min_exclusive else float(variable.min))
    if variable.max is not None:
        high = min(high, math.nextafter(variable.max, -math.inf) if variable.max_exclusive else float(variable.max))
    return f"{{V_{variable.name}, {int(real)}, {_c_double(low)}, {_c_double(high)}}}"


def _ranges(variables: list[Variable]) -> str:
    """The variables' CheckedRange entries, an empty one after them, as the lines of a C initialiser."""
    return "\n    " + ",\n    ".join([*(_checked_range(v) for v in variables), "{-1, 0, 0.0, 0.0}"]) + "\n"


def _references(variables: list[Variable]) -> str:
    """The variables' value references, -1 after them, as the lines of a C initialiser."""
    references = ", ".join([*(f"V_{v.name}" for v in variables), "-1"])
    return "\n    " + "\n    ".join(textwrap.wrap(references, 100)) + "\n"


def _positions(names: list[str], spec: ModelSpec) -> str:
    """Each variable's position in ``names`` (-1: not there), as the lines of a C initialiser."""
    positions = ", ".join(str(names.index(v.name)) if v.name in names else "-1" for v in spec.variables)
    return "\n    " + "\n    ".join(textwrap.wrap(positions, 100)) + "\n"


def variable_table(model: type[SteppedModel], token: str) -> dict[str, str]:
    """``model_variables.h`` and ``model_variables.c`` of ``model``'s spec and own checks."""
    spec = model.spec
    probes = model.extra_parameter_probes
    names = "\n".join(f"    V_{v.name} = {index}," for index, v in enumerate(spec.variables))
    derivatives = input_derivatives(spec)
    rows, columns = jacobian_layout(spec)
    jacobian_enums = "".join(f"enum {{\n{entries}}};\n" for entries in (
        "".join(f"    ROW_{name} = {k},\n" for k, name in enumerate(rows)),
        "".join(f"    COLUMN_{name} = {k},\n" for k, name in enumerate(columns))) if entries)
    constants = "".join(f"#define {name} {_c_string(value) if isinstance(value, str) else value}\n"
                        for name, value in model.native_constants.items())
    parts = model.derived_parts
    most = max((len(names) for names in parts.values()), default=0)
    part_enum = "" if not parts else (
        "\n/* the parts of the derived data (derived_parts): model_part_values lists the parameters each is\n"
        " * built for, -1 ending a list */\nenum {\n" + "".join(f"    PART_{name.upper()},\n" for name in parts)
        + f"    PARTS\n}};\n#define PART_MOST_VALUES {most}\nextern const int model_part_values[PARTS][PART_MOST_VALUES + 1];\n")
    extra_enum = part_enum + "" if not probes else part_enum + "\n/* messages of the model's own checks */\nenum {\n" + "".join(
        f"    MESSAGE_{name} = {index},\n" for index, name in enumerate(probes)) + "};\n"
    groups = (("parameter",), ("input",), COMPUTED)
    by_group = [[v for v in spec.of(*causalities)
                 if v.type == "Real" and causalities != COMPUTED or v.min is not None or v.max is not None]
                for causalities in groups]
    checked = [v for variables in by_group for v in variables]
    starts = [sum(len(variables) for variables in by_group[:k]) for k in range(len(groups) + 1)]
    real_computed = [v for v in spec.of(*COMPUTED) if v.type == "Real"]
    int_computed = [v for v in spec.of(*COMPUTED) if v.type in ("Integer", "Boolean")]
    header = f"""/* Variables of {spec.name}, generated from its spec by the native build: do not edit. */
#ifndef MODEL_VARIABLES_H
#define MODEL_VARIABLES_H

#define MODEL_NAME {_c_string(spec.name)}
#define MODEL_TOKEN model_token
#define MODEL_VARIABLE_COUNT {len(spec.variables)}
#define MODEL_STRING_COUNT {sum(v.type == "String" for v in spec.variables)}
#define MODEL_RELATION_COUNT {len(spec.relations)}
#define MODEL_EXTRA_MESSAGE_COUNT {len(probes)}
/* driveline.model.TIME_TOLERANCE: how far, relative to the time reached, a step may start before it */
#define MODEL_TIME_TOLERANCE {_c_double(TIME_TOLERANCE)}
#define MODEL_INPUT_DERIVATIVE_COUNT {len(derivatives)}
/* Model Exchange: continuous states (ModelSpec.states) */
#define MODEL_STATE_COUNT {len(spec.states)}
/* the variables the range checks read, by group (model_checked_from: the parameters, the inputs, the outputs and
 * locals, CheckedGroup), in the table's order: the bounded ones and the Real parameters and inputs (finite; the
 * sum of the Real outputs and locals shows that they are before their bounds are checked: model_real_computed) */
#define MODEL_CHECKED_COUNT {len(checked)}
#define MODEL_REAL_COMPUTED_COUNT {len(real_computed)}
extern const int model_checked_from[{len(groups) + 1}];
extern const int model_real_computed[MODEL_REAL_COMPUTED_COUNT + 1];
/* the Integer and Boolean outputs and locals: with the Real ones, the values a step may change (StepUndo) */
#define MODEL_INT_COMPUTED_COUNT {len(int_computed)}
extern const int model_int_computed[MODEL_INT_COMPUTED_COUNT + 1];
/* Directional derivatives: the Jacobian's rows are the Real outputs and locals (ROW_<name>), then der(<state>), its
 * columns the Real inputs and the states (COLUMN_<name>) */
#define MODEL_OUTPUT_ROWS {len(rows)}
#define MODEL_ROW_COUNT {len(rows) + len(spec.states)}
#define MODEL_COLUMN_COUNT {len(columns)}
{constants}
/* the FMU's token (FMI 2.0 GUID, FMI 3.0 instantiation token): the FMI version's, in model_variables.c */
extern const char model_token[];

/* value references */
enum {{
{names}
}};
{jacobian_enums}{extra_enum}
#endif
"""
    entries = "\n".join(_table_entry(v) for v in spec.variables)
    relations = "\n".join(_relation_entry(spec, r) for r in spec.relations)
    source = f"""/* Variable table, declared bounds and relations, own checks' messages of {spec.name}, generated
 * from its spec: do not edit. */
#include <math.h>

#include "fmi/fmu_instance.h"

const char model_token[] = {_c_string(token)};

const VariableInfo model_variables[MODEL_VARIABLE_COUNT] = {{
{entries}
}};

/* -1 ends each list */
/* the variables the range checks read and where each needs no message, an empty entry after them */
const CheckedRange model_checked_ranges[MODEL_CHECKED_COUNT + 1] = {{{_ranges(checked)}}};
const int model_checked_from[{len(groups) + 1}] = {{{", ".join(map(str, starts))}}};
const int model_real_computed[MODEL_REAL_COMPUTED_COUNT + 1] = {{{_references(real_computed)}}};
const int model_int_computed[MODEL_INT_COMPUTED_COUNT + 1] = {{{_references(int_computed)}}};
"""
    source += f"""
/* each variable's row and column of the Jacobian (directional derivatives), -1 for none */
const int model_jacobian_rows[MODEL_VARIABLE_COUNT] = {{{_positions(rows, spec)}}};
const int model_jacobian_columns[MODEL_VARIABLE_COUNT] = {{{_positions(columns, spec)}}};
"""
    if spec.relations:
        source += f"""
const RelationInfo model_relations[MODEL_RELATION_COUNT] = {{
{relations}
}};
"""
    if probes:
        extra = "\n".join(_extra_message(model, probe) for probe in probes.values())
        source += f"""
const ExtraMessage model_extra_messages[MODEL_EXTRA_MESSAGE_COUNT] = {{
{extra}
}};
"""
    if parts:
        lists = "\n".join("    {" + ", ".join([*(f"V_{name}" for name in names), "-1"]) + "}," for names in parts.values())
        source += f"""
const int model_part_values[PARTS][PART_MOST_VALUES + 1] = {{
{lists}
}};
"""
    if spec.states:
        states = ", ".join(f"V_{state.name}" for state in spec.states)
        sources = ", ".join(f"V_{state.derivative}" for state in spec.states)
        nominals = ", ".join(_c_double(state.nominal) for state in spec.states)
        source += f"""
/* the continuous states, the variables that are their time derivatives and their nominal values */
const int model_states[MODEL_STATE_COUNT] = {{{states}}};
const int model_state_derivatives[MODEL_STATE_COUNT] = {{{sources}}};
const double model_state_nominals[MODEL_STATE_COUNT] = {{{nominals}}};
"""
    if derivatives:
        table = "\n".join(f"    {{V_{of}, {order}, V_{target}}}," for of, order, target in derivatives)
        source += f"""
const InputDerivative model_input_derivatives[MODEL_INPUT_DERIVATIVE_COUNT] = {{
{table}
}};
"""
    return {"model_variables.h": header, "model_variables.c": source}


def input_derivatives(spec: ModelSpec) -> list[tuple[str, int, str]]:
    """``(input, order, variable)``: the inputs that hold an input's time derivatives, by order."""
    found = []
    for variable in spec.of("input"):
        base, order = variable.name, 0
        while spec[base].derivative is not None:
            base, order = spec[base].derivative, order + 1
        if order:
            found.append((base, order, variable.name))
    return found


# -- model description ----------------------------------------------------------------------------


_FMI3_TYPES = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "String": "String"}


def _skeleton(spec: ModelSpec, fmi: str, token: str, sources: list[str]) -> ET.Element:
    """The description before :mod:`model_description` completes it (as pythonfmu's is)."""
    fmi3 = fmi == "3"
    experiment = spec.default_experiment
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "3.0" if fmi3 else "2.0", "modelName": spec.name,
        ("instantiationToken" if fmi3 else "guid"): token, "description": spec.description,
        "author": "driveline-fmus contributors", "license": "MIT", "version": __version__,
        "generationTool": GENERATION_TOOL, "variableNamingConvention": "structured",
    })
    state = "State" if fmi3 else "state"
    derivatives = {} if not provides_derivatives(spec.name) else (
        {"providesDirectionalDerivatives": "true", "providesAdjointDerivatives": "true"} if fmi3
        else {"providesDirectionalDerivative": "true"})
    if not MODELS[spec.name].co_simulation_only:
        ET.SubElement(root, "ModelExchange", {  # the same binary: one model identifier for both interfaces
            "modelIdentifier": spec.name, "needsExecutionTool": "false", **derivatives,
            "canBeInstantiatedOnlyOncePerProcess": "false", f"canGetAndSetFMU{state}": "true",
            f"canSerializeFMU{state}": "true",
            **({"needsCompletedIntegratorStep": "false"} if fmi3 else
               {"completedIntegratorStepNotNeeded": "true", "canNotUseMemoryManagementFunctions": "true"}),
        })
    cosimulation = ET.SubElement(root, "CoSimulation", {
        "modelIdentifier": spec.name, "needsExecutionTool": "false", **derivatives,
        "canHandleVariableCommunicationStepSize": "true",
        "canBeInstantiatedOnlyOncePerProcess": "false", f"canGetAndSetFMU{state}": "true",
        f"canSerializeFMU{state}": "true",
        **({} if fmi3 else {"canInterpolateInputs": "true" if input_derivatives(spec) else "false",
                             "canNotUseMemoryManagementFunctions": "true"}),
    })
    if not fmi3:
        for interface in root.iter():
            if interface.tag in ("ModelExchange", "CoSimulation"):
                ET.SubElement(interface, "SourceFiles").extend(ET.Element("File", name=name) for name in sources)
    categories = ET.SubElement(root, "LogCategories")
    for status in LOG_CATEGORIES:
        ET.SubElement(categories, "Category", name=f"logStatus{status}",
                      description=f"Log messages with fmi{fmi}{status} status.")
    ET.SubElement(categories, "Category", name="logAll", description="Log all messages.")
    ET.SubElement(root, "DefaultExperiment", {
        "startTime": repr(experiment.start_time), "stopTime": repr(experiment.stop_time),
        "stepSize": repr(experiment.step_size),
        **({"tolerance": repr(experiment.tolerance)} if experiment.tolerance is not None else {}),
    })
    variables = ET.SubElement(root, "ModelVariables")
    for reference, v in enumerate(spec.variables):
        attributes = {"name": v.name, "valueReference": str(reference), "causality": v.causality,
                      "variability": v.effective_variability}
        start = {} if v.causality in COMPUTED else {"start": number_text(v.start) if v.type != "String" else v.start}
        if fmi3 and v.type == "String":  # FMI 3.0: a String's start is an element
            element = ET.SubElement(variables, "String", attributes)
            if start:
                ET.SubElement(element, "Start", value=start["start"])
        elif fmi3:
            ET.SubElement(variables, _FMI3_TYPES[v.type], {**attributes, **start})
        else:
            ET.SubElement(ET.SubElement(variables, "ScalarVariable", attributes), v.type, start)
    if fmi3:
        ET.SubElement(variables, "Float64", name="time", valueReference=str(len(spec.variables)),
                      causality="independent", variability="continuous", description="Simulation time")
    for k, state in enumerate(() if MODELS[spec.name].co_simulation_only else spec.states):
        source = spec[state.derivative]
        attributes = {"name": state.derivative_name, "valueReference": str(derivative_reference(spec, fmi, k)),
                      "causality": "local", "variability": "continuous",
                      "description": f"Time derivative of the continuous state {state.name}: {state.derivative}"}
        typed = {"unit": source.unit, "derivative": str(spec.variables.index(spec[state.name]) + (0 if fmi3 else 1))}
        if fmi3:
            ET.SubElement(variables, "Float64", {**attributes, **typed})
        else:
            ET.SubElement(ET.SubElement(variables, "ScalarVariable", attributes), "Real", typed)
    ET.SubElement(root, "ModelStructure")
    return root


def derivative_reference(spec: ModelSpec, fmi: str, k: int) -> int:
    """Value reference of ``der(<state k>)``: after the spec's variables (FMI 3.0: and ``time``)."""
    return len(spec.variables) + (1 if fmi == "3" else 0) + k


def jacobian_references(spec: ModelSpec, fmi: str) -> tuple[list[int], list[int]]:
    """The value references of the Jacobian's rows (:func:`jacobian_layout`'s, then ``der(<state>)``) and
    of its columns, in FMI version ``fmi``."""
    outputs, columns = jacobian_layout(spec)
    index = [v.name for v in spec.variables].index
    rows = [index(o) for o in outputs] + [derivative_reference(spec, fmi, k) for k in range(len(spec.states))]
    return rows, [index(c) for c in columns]


def model_description(spec: ModelSpec, fmi: str, token: str, sources: list[str]) -> bytes:
    skeleton = ET.tostring(_skeleton(spec, fmi, token, sources), encoding="UTF-8", xml_declaration=True)
    return (complete_fmi3 if fmi == "3" else complete_fmi2)(skeleton, spec)


MATH_LIBRARY = ("the C math library: link it where it is a library of its own (Linux: -lm; with fmpy's "
                "build_platform_binary, cmake_options=REBUILD_CMAKE_OPTIONS)")
#: What fmpy's ``build_platform_binary`` needs to link libm into a rebuilt binary on Linux: its CMake
#: project links no library, and FMI 2.0 has no place to name one (FMI 3.0: ``<Library name="m"/>``).
REBUILD_CMAKE_OPTIONS = {"CMAKE_C_STANDARD_LIBRARIES:STRING": "-lm"}


def build_description(name: str, sources: list[str]) -> bytes:
    """FMI 3.0 ``sources/buildDescription.xml``: the C sources and their language."""
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    configuration = ET.SubElement(root, "BuildConfiguration", modelIdentifier=name)
    files = ET.SubElement(configuration, "SourceFileSet", language="C99")
    files.extend(ET.Element("SourceFile", name=source) for source in sources)
    ET.SubElement(configuration, "Library", name="m", description=MATH_LIBRARY)
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


# -- build ------------------------------------------------------------------------------------------


def source_paths(name: str) -> list[Path]:
    """The C files an FMU of ``name`` carries besides the generated ones: the layer, the libraries it
    and the model use, the model's folder."""
    own = sorted(path for path in model_folder(name).iterdir() if path.suffix in (".c", ".h") and path.is_file())
    return [*sorted(LAYER_SOURCES.glob("*.[ch]")), *used_library(name), *own]


def _source_files(name: str) -> dict[str, bytes]:
    """:func:`source_paths` by their path below ``fmu_src/native/``."""
    root = NATIVE_SRC.resolve()
    return {path.resolve().relative_to(root).as_posix(): path.read_bytes() for path in source_paths(name)}


def resource_files(name: str) -> dict[str, bytes]:
    """The resource files the model class declares, by their name in the FMU's ``resources/``."""
    return {Path(path).name: Path(path).read_bytes() for path in MODELS[name].resource_files}


def _sources(name: str, fmi: str, model_file: Path) -> dict[str, bytes]:
    """Every source file the FMU carries, by name, with the token computed from all of them."""
    files = {source: data for source, data in _source_files(name).items()
             if source not in LAYER.values() or source == LAYER[fmi]}
    files[CONSTANTS_HEADER] = constants_header().encode()
    files[model_source(name).relative_to(NATIVE_SRC).as_posix()] = model_file.read_bytes()
    untokened = variable_table(MODELS[name], "")
    digest = hashlib.sha256(repr((name, fmi, sorted(files.items()), sorted(untokened.items()),
                                  sorted(resource_files(name).items()))).encode())
    token = str(uuid.uuid5(TOKEN_NAMESPACE, digest.hexdigest()))
    files.update({key: text.encode() for key, text in variable_table(MODELS[name], token).items()})
    files["token"] = token.encode()
    return files


VERSIONED = ("model_variables.c", *LAYER.values())  # compiled per FMI version; the rest once per platform
GENERATED_PER_VERSION = ("model_variables.c",)  # differs between the FMI versions: written apart
SHARED_OBJECTS = ("lib/python_numbers.c",)  # compiled once per platform for every model


def _write(folder: Path, files: dict[str, bytes]) -> None:
    for source, data in files.items():
        (folder / source).parent.mkdir(parents=True, exist_ok=True)
        (folder / source).write_bytes(data)


def _pack(name: str, fmi: str, files: dict[str, bytes], binaries: dict[toolchain.Platform, Path], target: Path) -> None:
    """Zip the FMU: model description, one binary per platform, sources, resources, the model's
    doc page and the licence (``documentation/licenses/``)."""
    token = files["token"].decode()
    sources = {source: data for source, data in files.items() if source != "token"}
    compiled = sorted(source for source in sources if source.endswith(".c"))
    libraries = {p: library.read_bytes() for p, library in binaries.items()}
    intel, arm = toolchain.BY_TUPLE["x86_64-darwin"], toolchain.BY_TUPLE["aarch64-darwin"]
    if fmi == "2" and intel in libraries and arm in libraries:
        # FMI 2.0's darwin64 universal: importers on Apple silicon (fmpy among them) look there
        libraries[intel] = toolchain.universal([libraries[intel], libraries[arm]])
    carried = {f"binaries/{p.folder(fmi)}/{name}{p.suffix}": data for p, data in libraries.items()}
    members = {
        "modelDescription.xml": model_description(MODELS[name].spec, fmi, token, compiled),
        **carried,
        **{f"sources/{source}": data for source, data in sources.items()},
        **{f"resources/{resource}": data for resource, data in resource_files(name).items()},
    }
    members |= documentation.members(name, toolchain.platforms_sentence(members))
    if fmi == "3":
        members["sources/buildDescription.xml"] = build_description(name, compiled)
    write_zip(target, members)


def build_all(dest: Path, names: list[str] | None = None, fmi: tuple[str, ...] = ("2", "3"),
              release: bool | None = None, model_file: Path | None = None, show_progress: bool = False) -> list[Path]:
    """The native FMUs of ``names`` (default: every model with a C port) that have one, for each
    FMI version in ``fmi``, with binaries for every platform (``release``; the default when ziglang
    is installed, :func:`toolchain.chosen_platforms`) or for this machine's alone.

    Each source is compiled once per platform (the FMI layer and the generated table once per FMI
    version), all in parallel, then linked once per FMU and platform. ``model_file`` replaces the
    models' C port (the benchmarks' no-physics twin); ``show_progress``: each step on standard error."""
    chosen = [name for name in (names or native_models()) if has_c_port(name)]
    platforms = toolchain.chosen_platforms(release)
    host_only = len(platforms) == 1 and not (release or (release is None and toolchain.release_available()))
    files = {(name, v): _sources(name, v, model_file or model_source(name)) for name in chosen for v in fmi}
    with tempfile.TemporaryDirectory() as work:
        root = Path(work)
        for (name, v), sources in files.items():  # the FMI version's own generated file apart, the rest shared
            _write(root / "sources" / name / f"fmi{v}",
                   {s: d for s, d in sources.items() if s in GENERATED_PER_VERSION})
            _write(root / "sources" / name / "common",
                   {s: d for s, d in sources.items() if s not in GENERATED_PER_VERSION and s != "token"})
        compiles, links, libraries = [], [], {}
        for target in platforms:
            objects = root / "objects" / target.tuple
            shared = {source: objects / f"{source}.o" for source in SHARED_OBJECTS}
            for name in chosen:
                source_dir = root / "sources" / name
                include = (source_dir / "common", fmi_headers())
                common = sorted(s for s in files[name, fmi[0]] if s.endswith(".c") and s not in VERSIONED)
                model_objects = [shared.get(s, objects / name / f"{s}.o") for s in common]
                compiles += [toolchain.compile_step(target, source_dir / "common" / s, obj, *include, host_only)
                             for s, obj in zip(common, model_objects) if s not in shared or name == chosen[0]]
                for v in fmi:
                    own = [s for s in files[name, v] if s in VERSIONED]
                    own_objects = [objects / name / f"fmi{v}" / f"{s}.o" for s in own]
                    compiles += [toolchain.compile_step(
                        target, source_dir / (f"fmi{v}" if s in GENERATED_PER_VERSION else "common") / s, obj,
                        *include, host_only) for s, obj in zip(own, own_objects)]
                    library = root / "binaries" / target.tuple / f"fmi{v}" / f"{name}{target.suffix}"
                    links.append(toolchain.link_step(target, [*model_objects, *own_objects], library, host_only))
                    libraries.setdefault((name, v), {})[target] = library
        where = ", ".join(p.tuple for p in platforms)
        with Progress(f"native FMUs: compiling for {where}", len(compiles), enabled=show_progress) as shown:
            toolchain.run(compiles, progress=shown)
        with Progress("native FMUs: linking", len(links), enabled=show_progress) as shown:
            toolchain.run(links, progress=shown)
        for (name, v), binaries in libraries.items():
            _pack(name, v, files[name, v], binaries, fmu_path(dest, name, v))
    return [fmu_path(dest, name, v) for v in fmi for name in chosen]


def build(name: str, dest: Path, fmi: str = "2", model_file: Path | None = None, release: bool | None = None) -> Path:
    """Build the native FMU of catalog model ``name`` for FMI ``fmi`` under ``dest`` (see
    :func:`build_all`)."""
    return build_all(dest, [name], (fmi,), release, model_file)[0]
