"""The native sources by role (``fmu_src/native/``: ``fmi/`` the FMI layer, ``lib/`` the shared libraries,
``models/<model>/`` one folder per model), their ``#include`` graph, and what each native FMU carries of
them: its model's folder, the layer and the libraries these include, enough to compile it with a plain C
compiler and nothing more."""

from __future__ import annotations

import ctypes
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

from driveline.catalog import MODELS
from fmu_harness.packaging import native
from fmu_harness.packaging.documentation import snake_case
from fmu_harness.packaging.native_constants import HEADER as CONSTANTS_HEADER

NATIVE = native.native_models()
ROLES = {"fmi", "lib", "models"}
#: What the build writes into every FMU's sources/ besides the files of fmu_src/native/
GENERATED = {"model_variables.h", "model_variables.c", CONSTANTS_HEADER}
#: The FMI standard's headers, which a host brings
FMI_HEADERS = {"fmi2Functions.h", "fmi3Functions.h"}


def _graph(root: Path) -> dict[str, set[str]]:
    """Each C file below ``root`` and the files below ``root`` it includes, by their paths from it."""
    return {path.relative_to(root).as_posix(): {found.relative_to(root.resolve()).as_posix()
                                                for found in native.included(path, root)}
            for path in sorted(root.rglob("*.[ch]"))}


def _modules(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """The graph of modules: a module is a C file with its header (``toml.c`` and ``toml.h``)."""
    module = {path: path.rsplit(".", 1)[0] for path in graph}
    edges = {name: set() for name in module.values()}
    for path, includes in graph.items():
        edges[module[path]] |= {module[found] for found in includes} - {module[path]}
    return edges


def _circle(graph: dict[str, set[str]]) -> list[str]:
    """A circle of ``graph`` (its nodes, the first again at the end), or [] for none: depth first."""
    state, path = {}, []

    def visit(node: str) -> list[str]:
        state[node] = "open"
        path.append(node)
        for following in sorted(graph.get(node, ())):
            if state.get(following) == "open":
                return [*path[path.index(following):], following]
            if following not in state and (found := visit(following)):
                return found
        state[node] = "done"
        path.pop()
        return []

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return []


def test_the_sources_lie_by_role():
    """No C file at the top; the layer, the libraries, and one folder per model, each holding its model
    file (a catalog model's name in snake case)."""
    top = native.NATIVE_SRC
    assert sorted(path.name for path in top.glob("*.[ch]")) == []
    assert {path.name for path in top.iterdir() if path.is_dir() and path.name != "__pycache__"} == ROLES
    folders = {path.name for path in native.MODEL_SOURCES.iterdir() if path.is_dir()}
    assert folders == {snake_case(name) for name in NATIVE} and NATIVE == list(MODELS)
    for name in NATIVE:
        assert native.model_source(name).parent == native.MODEL_SOURCES / snake_case(name)
    assert sorted(path.name for path in native.LAYER_SOURCES.glob("*.c")) == sorted(
        ["fmi2_functions.c", "fmi3_functions.c", "fmu_checks.c", "fmu_derivatives.c", "fmu_instance.c",
         "fmu_messages.c", "fmu_model_exchange.c", "fmu_state.c", "fmu_values.c"])


def test_the_include_graph_has_no_circle():
    """Neither two files nor two modules (a C file and its header) use each other, followed through any
    number of others: the layer's messages (fmu_messages.c) are below its checks and its instances."""
    graph = _graph(native.NATIVE_SRC)
    assert _circle(graph) == []
    assert _circle(_modules(graph)) == []
    modules = _modules(graph)
    assert "fmi/fmu_messages" in modules["fmi/fmu_checks"] | modules["fmi/fmu_instance"]
    assert modules["fmi/fmu_messages"] == set()


def test_the_circle_check_finds_a_circle(tmp_path):
    """The check fails on a circle of headers, and on two modules that use each other through their
    headers (``a.c`` includes ``b.h``, ``b.c`` includes ``a.h``), as fmu_instance.c and fmu_checks.c did."""
    (tmp_path / "fmi").mkdir()
    (tmp_path / "fmi" / "a.h").write_text('#include "b.h"\n')
    (tmp_path / "fmi" / "b.h").write_text('#include "fmi/a.h"\n')
    assert _circle(_graph(tmp_path)) == ["fmi/a.h", "fmi/b.h", "fmi/a.h"]
    (tmp_path / "fmi" / "b.h").write_text("int b(void);\n")
    (tmp_path / "fmi" / "a.c").write_text('#include "a.h"\n')
    (tmp_path / "fmi" / "b.c").write_text('#include "a.h"\n')
    assert _circle(_graph(tmp_path)) == [] and _circle(_modules(_graph(tmp_path))) == ["fmi/a", "fmi/b", "fmi/a"]


def _role(path: str) -> str:
    """``fmi``, ``lib`` or ``models/<model>``: the room a file lies in."""
    parts = path.split("/")
    return "/".join(parts[:2]) if parts[0] == "models" else parts[0]


def test_each_role_includes_only_what_lies_below_it():
    """A model's files include the layer, the libraries and their own folder, never another model's; the
    layer includes the libraries; the libraries include themselves only."""
    allowed = {"fmi": {"fmi", "lib"}, "lib": {"lib"}}
    for path, includes in _graph(native.NATIVE_SRC).items():
        room = _role(path)
        assert {_role(found) for found in includes} <= allowed.get(room, {"fmi", "lib", room}), path


def test_the_role_check_finds_a_model_including_another(tmp_path):
    folder = tmp_path / "models" / "one"
    folder.mkdir(parents=True)
    (tmp_path / "models" / "two").mkdir()
    (tmp_path / "models" / "two" / "two.h").write_text("int two(void);\n")
    (folder / "one.c").write_text('#include "models/two/two.h"\n')
    rooms = {_role(found) for found in _graph(tmp_path)["models/one/one.c"]}
    assert rooms == {"models/two"} and not rooms <= {"fmi", "lib", "models/one"}


def _carried(fmu: Path) -> tuple[set[str], list[str]]:
    """The files of an FMU's sources/ and the C files its model description (FMI 2.0) or build description
    (FMI 3.0) lists."""
    with zipfile.ZipFile(fmu) as archive:
        names = {name.removeprefix("sources/") for name in archive.namelist() if name.startswith("sources/")}
        if "buildDescription.xml" in names:
            listed = [element.get("name") for element in
                      ET.fromstring(archive.read("sources/buildDescription.xml")).iter("SourceFile")]
        else:
            description = ET.fromstring(archive.read("modelDescription.xml"))
            listed = [element.get("name") for element in description.find("CoSimulation").iter("File")]
    return names - {"buildDescription.xml"}, listed


@pytest.mark.parametrize("name", NATIVE)
def test_an_fmu_carries_its_folder_the_layer_and_the_libraries_they_include(native_dir, tmp_path, name, fmi):
    """An FMU's sources/ hold its model's folder, the layer (its FMI version's functions) and what these
    include in ``lib/``, followed through each header to the modules it declares, and nothing else; its
    model description lists every C file of them."""
    fmu = native.fmu_path(native_dir, name, fmi)
    names, listed = _carried(fmu)
    folder = f"models/{snake_case(name)}"
    other = native.LAYER["3" if fmi == "2" else "2"]
    layer = {f"fmi/{path.name}" for path in native.LAYER_SOURCES.glob("*.[ch]")} - {other}
    own = {f"{folder}/{path.name}" for path in native.model_folder(name).glob("*.[ch]")}
    assert {path for path in names if path.startswith(("fmi/", "models/"))} == layer | own
    assert names - layer - own - GENERATED <= {path for path in names if path.startswith("lib/")}
    assert sorted(listed) == sorted(path for path in names if path.endswith(".c"))
    # what the model and the layer include, walked in the FMU's own sources
    sources = tmp_path / "sources"
    with zipfile.ZipFile(fmu) as archive:
        for path in names:
            (sources / path).parent.mkdir(parents=True, exist_ok=True)
            (sources / path).write_bytes(archive.read(f"sources/{path}"))
    starts = [sources / path for path in layer | own | {"model_variables.c"}]
    used = {path.relative_to(sources.resolve()).as_posix() for path in native.used_sources(starts, sources)}
    assert used == names
    for path in names:  # every file included is carried, next to the file or from the top, but the FMI headers
        written = set(re.findall(r'^\s*#\s*include\s+"([^"]+)"', (sources / path).read_text(), re.MULTILINE))
        missing = {header for header in written - FMI_HEADERS
                   if not (sources / path).parent.joinpath(header).is_file() and not (sources / header).is_file()}
        assert missing == set(), path


def test_powertrain_mounts_carries_the_layout_reader_and_no_rotor_file(native_dir, fmi):
    names, _ = _carried(native.fmu_path(native_dir, "PowertrainMounts", fmi))
    assert {"lib/toml.h", "lib/toml.c", "lib/layout_file.c", "lib/messages.c", "lib/pyrepr.c", "lib/arena.c"} <= names
    rotor = {path.read_bytes() for path in native.model_folder("CriticalSpeeds").iterdir()}
    with zipfile.ZipFile(native.fmu_path(native_dir, "PowertrainMounts", fmi)) as archive:
        assert not [path for path in names if path.startswith("models/critical_speeds/")
                    or archive.read(f"sources/{path}") in rotor]
    assert {path for path in names if path.startswith("models/")} == {
        f"models/powertrain_mounts/{path.name}" for path in native.model_folder("PowertrainMounts").iterdir()}
    cardan, _ = _carried(native.fmu_path(native_dir, "CardanJoint", fmi))
    assert {path for path in cardan if path.startswith("lib/")} == {"lib/python_numbers.h", "lib/python_numbers.c"}


GCC = shutil.which("gcc")
#: The warnings a host's strict build may turn on, each an error: the C99 the sources promise, and nothing else
STRICT = ("-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror")


@pytest.mark.skipif(GCC is None, reason="the plain compile uses gcc (Debian: apt-get install gcc)")
@pytest.mark.parametrize("name", NATIVE)
def test_an_fmu_compiles_from_its_sources_alone_with_a_plain_compiler(native_dir, tmp_path, name, fmi):
    """What a host that builds source FMUs does: the C files the model description (FMI 2.0) or build
    description (FMI 3.0) lists, the sources/ folder as the one include folder (and the standard's headers),
    no flag of the project's build but gcc's strict C99 warnings as errors, optimised so that gcc follows
    the values a ``snprintf`` may cut (the project's build holds clang to the same); the library loads and exports the FMI functions."""
    fmu = native.fmu_path(native_dir, name, fmi)
    names, listed = _carried(fmu)
    sources = tmp_path / "sources"
    with zipfile.ZipFile(fmu) as archive:
        for path in names:
            (sources / path).parent.mkdir(parents=True, exist_ok=True)
            (sources / path).write_bytes(archive.read(f"sources/{path}"))
    library = tmp_path / f"{name}.so"
    done = subprocess.run([GCC, *STRICT, "-shared", "-fPIC", "-O2", "-I", str(sources),
                           "-isystem", str(native.fmi_headers()), *(str(sources / path) for path in listed),
                           "-o", str(library), "-lm"],
                          capture_output=True, text=True)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    loaded = ctypes.CDLL(str(library))
    get_version = getattr(loaded, f"fmi{fmi}GetVersion")
    get_version.restype = ctypes.c_char_p
    assert get_version() == f"{fmi}.0".encode()
