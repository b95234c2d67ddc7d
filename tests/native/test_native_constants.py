"""The constants both cores use exist once, in the Python modules: the native build writes them into
``driveline_constants.h`` (fmu_harness/packaging/native_constants.py), and no C file of
``fmu_src/native`` defines one of them itself, by its name or by its value."""

from __future__ import annotations

import ast
import math
import re
import sys

from fmu_harness.packaging import native
from fmu_harness.packaging.native_constants import SHARED, constants_header, shared_constants

DEFINE = re.compile(r"^[ \t]*#[ \t]*define[ \t]+(\w+)[ \t]+(.+?)[ \t]*(?:/\*.*)?$", re.MULTILINE)
STATIC_CONST = re.compile(r"\bstatic\s+const\s+(?:unsigned\s+|signed\s+)?(?:double|float|int|long|size_t)\s+(\w+)\s*=\s*([^;{]+);")
#: What a C number may be written with besides digits and operators.
C_NAMES = {"FMU_PI": math.pi, "DBL_EPSILON": sys.float_info.epsilon, "DBL_MIN": sys.float_info.min,
           "DBL_MAX": sys.float_info.max}


def _value(expression: str) -> float | tuple | None:
    """The number a C constant expression stands for (literals, the names above, + - * /), the tuple of an
    array's initialiser ``{a, b}``, else None."""
    if expression.strip().startswith("{") and expression.strip().endswith("}"):
        items = [_value(item) for item in expression.strip()[1:-1].split(",")]
        return None if None in items else tuple(items)
    text = re.sub(r"(?<=\d)[uUlLfF]+\b", "", expression.strip())
    for name, value in C_NAMES.items():
        text = re.sub(rf"\b{name}\b", repr(value), text)
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError:
        return None
    allowed = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Constant, ast.Add, ast.Sub, ast.Mult, ast.Div, ast.USub,
               ast.UAdd)
    if not all(isinstance(node, allowed) for node in ast.walk(tree)) or not any(
            isinstance(node, ast.Constant) for node in ast.walk(tree)):
        return None
    value = eval(compile(tree, "<c>", "eval"))  # numbers and arithmetic only (checked above)
    return value if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def _c_numbers() -> list[tuple[str, str, float]]:
    """(file, name, value) of every number a C source of fmu_src/native defines."""
    found = []
    for path in sorted(native.NATIVE_SRC.rglob("*.[ch]")):
        text = path.read_text()
        for name, expression in DEFINE.findall(text) + STATIC_CONST.findall(text):
            value = _value(expression)
            if value is not None:
                found.append((path.relative_to(native.NATIVE_SRC).as_posix(), name, value))
    return found


def test_the_header_holds_every_declared_constant_with_its_python_value():
    header = dict(DEFINE.findall(constants_header()))
    constants = shared_constants()
    assert len(constants) == sum(len(names) for names in SHARED.values())
    assert set(header) == set(constants)
    for name, (python, value) in constants.items():
        written = _value(header[name])
        assert written == value and type(written) is type(value), (name, python)


def test_no_c_file_defines_a_number_the_python_modules_hold():
    constants = shared_constants()
    names = {python.rsplit(".", 1)[1].lstrip("_") for python, _ in constants.values()}
    fractions = {value for _, value in constants.values() if isinstance(value, float) and not value.is_integer()}
    copies = [(path, name, value) for path, name, value in _c_numbers()
              if name in names or any(name.endswith("_" + known) for known in names)
              or (isinstance(value, float) and value in fractions)]
    assert copies == []


def test_the_check_finds_a_copy():
    """The scanner sees the numbers as they were written before the header (a define of a declared
    name, a value written as an expression)."""
    assert _value("(2.0 * FMU_PI / 3.0)") == 2.0 * math.pi / 3.0
    assert _value("(4.0 * DBL_EPSILON)") == 4.0 * sys.float_info.epsilon
    assert _value("16u") == 16 and _value("(-1.0)") == -1.0 and _value("FMU_MESSAGE_SIZE") is None
    assert DEFINE.findall("#define SUBGRID 24          /* roots.SUBGRID */") == [("SUBGRID", "24")]
    assert STATIC_CONST.findall("static const double NOISE = 10.0;") == [("NOISE", "10.0")]


def test_the_rule_of_which_parameter_redoes_which_analysis_part_is_generated_from_python():
    """The C model keeps each part of the CriticalSpeeds analysis for the parameters the Python model
    keys it by (ANALYSIS_PARTS): the table is generated, the C file lists none of its own."""
    from driveline.catalog import MODELS
    from driveline.rotor.model import ANALYSIS_PARTS

    model = MODELS["CriticalSpeeds"]
    assert model.derived_parts is ANALYSIS_PARTS
    generated = native.variable_table(model, "")
    rows = re.findall(r"^    \{((?:V_\w+, )*)-1\},$", generated["model_variables.c"], re.MULTILINE)
    assert [tuple(re.findall(r"V_(\w+)", row)) for row in rows] == list(ANALYSIS_PARTS.values())
    assert [f"PART_{name.upper()}" for name in ANALYSIS_PARTS] == re.findall(
        r"^    (PART_\w+),$", generated["model_variables.h"], re.MULTILINE)
    c_model = native.model_source("CriticalSpeeds").read_text()
    assert "model_part_values" in c_model and not re.search(r"\bPART_\w+\s*[,=]", c_model.split("typedef int Part;")[0])


# ---- the kinds of failure: returned as ErrorKind, never a bare -1 or a cast ------------------------

#: A comment, a string or a character literal of C (blanked before the functions are looked for).
C_NOISE = re.compile(r"/\*.*?\*/|//[^\n]*|\"(?:\\.|[^\"\\\n])*\"|'(?:\\.|[^'\\\n])*'", re.DOTALL)
#: A function definition's head: its return type, name and parameters, up to the opening brace.
C_FUNCTION = re.compile(r"^(?:static\s+)?(?P<type>[A-Za-z_][\w \t*]*?)\s*\b(?P<name>\w+)"
                        r"\((?P<parameters>[^;{}()]*)\)\s*\{", re.MULTILINE)


def _c_functions(text: str) -> list[tuple[str, str, str, str]]:
    """(return type, name, parameters, body) of every function defined in the C ``text``."""
    text = C_NOISE.sub(lambda match: " " if match.group().startswith("/") else match.group()[0] * 2, text)
    found = []
    for head in C_FUNCTION.finditer(text):
        depth, end = 0, head.end() - 1
        for end in range(head.end() - 1, len(text)):
            depth += {"{": 1, "}": -1}.get(text[end], 0)
            if depth == 0:
                break
        found.append((" ".join(head["type"].split()), head["name"], head["parameters"], text[head.end():end]))
    return found


def _kind_seams(sources: dict[str, str]) -> list[tuple[str, str, str]]:
    """(file, function, what) of every failure that is not returned as its ErrorKind: a ``return -1``
    in a function returning ErrorKind, an int function that writes a message (it takes ``char *error``,
    or calls ROTOR_ERROR or a function that writes one), another type of function that takes ``char
    *error`` (a constructor returning NULL), a cast to ErrorKind."""
    functions = [(path, *function) for path, text in sources.items() for function in _c_functions(text)]
    writers = {"ROTOR_ERROR"} | {name for _, _, name, parameters, _ in functions
                                 if re.search(r"\bchar\s*\*\s*error\b", parameters)}
    while True:
        calls = re.compile(rf"\b(?:{'|'.join(sorted(writers))})\s*\(") if writers else None
        more = {name for _, _, name, _, body in functions if calls and calls.search(body)} - writers
        if not more:
            break
        writers |= more
    seams = []
    for path, kind, name, parameters, body in functions:
        if kind == "ErrorKind" and re.search(r"\breturn\s*\(?\s*-\s*1\s*\)?\s*;", body):
            seams.append((path, name, "returns -1"))
        if kind == "int" and name in writers:
            seams.append((path, name, "int with a message"))
        elif kind != "ErrorKind" and re.search(r"\bchar\s*\*\s*error\b", parameters):
            seams.append((path, name, f"{kind} with a message"))
    seams += [(path, "", "casts to ErrorKind") for path, text in sources.items()
              if re.search(r"\(\s*ErrorKind\s*\)", C_NOISE.sub(" ", text))]
    return seams


def test_the_rotor_library_returns_its_failures_as_error_kinds():
    """A function of the CriticalSpeeds C port that fails with a message returns the failure's kind
    (the Python exception, ErrorKind of the generated header), not an int that the model casts: -1
    would be ERROR_VALUE only by the order of ERROR_KINDS."""
    sources = {path.relative_to(native.NATIVE_SRC).as_posix(): path.read_text()
               for path in sorted(native.model_folder("CriticalSpeeds").glob("*.c"))}
    assert _kind_seams(sources) == []


def test_the_error_kind_check_finds_a_seam():
    """The check sees each seam as it was written before the kinds were returned, and not a -1 in a
    comment, a string or a function that returns an index."""
    written = """
int layout_error(char *error, size_t size, const char *format, ...)
{
    va_list args;
    return -1;
}

static int number(const Loader *loader, const char *where, double *out)
{
    if (!(*out > 0.0)) { /* a brace in a comment: { */
        return layout_error(loader->error, loader->size, "%s must be > 0 {", where);
    }
    return 0;
}

static ErrorKind searched_modes(const Driveline *driveline, double *work,
                                char *error)
{
    if (work == NULL) {
        snprintf(error, ERROR_SIZE, "out of memory");
        return -1;
    }
    return ERROR_NONE;
}

static int unheld_piece(const Driveline *d, int plane)
{
    char c = '}';
    return c == '{' ? 0 : -1;
}

static ErrorKind part(char *error)
{
    return (ErrorKind)fe_natural_frequencies(error); /* return -1; */
}

Chain *chain_new(const Driveline *driveline, char *error, size_t size)
{
    return NULL;
}
"""
    assert _kind_seams({"model.c": written}) == [("model.c", "layout_error", "int with a message"),
                                                 ("model.c", "number", "int with a message"),
                                                 ("model.c", "searched_modes", "returns -1"),
                                                 ("model.c", "chain_new", "Chain * with a message"),
                                                 ("model.c", "", "casts to ErrorKind")]
