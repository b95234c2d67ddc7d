"""The package and its FMUs: what each FMU ships, its script, hosts holding several FMUs, the console script."""

from __future__ import annotations

import ast
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

from fmu_harness import cli
from fmu_harness.packaging import FMI_VERSIONS, documentation, fmu_path, native, toolchain

from conftest import SLOW_SECONDS, measured
from support.fmu_documentation import assert_documentation

ROOT = Path(__file__).resolve().parents[2]


def members(path: Path) -> set[str]:
    with zipfile.ZipFile(path) as archive:
        return {name.removeprefix("resources/") for name in archive.namelist() if name.startswith("resources/")}


@pytest.mark.parametrize("version", ["2", "3"])
def test_each_fmu_ships_the_modules_its_model_imports(fmu_path, version):
    tripod, rotor = members(fmu_path("TripodCoupling", version)), members(fmu_path("CriticalSpeeds", version))
    assert {"driveline/tripod/model.py", "driveline/tripod/exact.py", "driveline/model.py"} <= tripod
    assert not any(name.startswith("driveline/rotor/") for name in tripod)
    assert {"driveline/rotor/model.py", "driveline/rotor/data/two_piece_propshaft.toml"} <= rotor
    assert not any(name.startswith("driveline/tripod/") for name in rotor)
    adapter, other = ("fmi2_slave", "fmi3_slave") if version == "2" else ("fmi3_slave", "fmi2_slave")
    for shipped in (tripod, rotor):
        assert {f"fmu_src/{adapter}.py", "fmu_src/loading.py", "fmu_src/model_adapter.py"} <= shipped
        assert f"fmu_src/{other}.py" not in shipped
        assert not any(name.startswith("fmu_harness/") or "__pycache__" in name for name in shipped)


@pytest.mark.parametrize("version", ["2", "3"])
def test_each_fmu_carries_its_doc_page_as_index_html_and_the_licence(fmu_path, model_name, version):
    """``documentation/index.html`` from the model's page, the page, the licence; no other page,
    in ``documentation/`` or among the resources (the 14 pages were 217 kB of each Python FMU)."""
    assert_documentation(fmu_path(model_name, version), model_name)


@pytest.mark.parametrize("version", ["2", "3"])
def test_the_fmu_script_is_one_class_statement(fmu_path, version):
    suffix = FMI_VERSIONS[version].module_suffix
    with zipfile.ZipFile(fmu_path("SpeedSource", version)) as archive:
        tree = ast.parse(archive.read(f"resources/SpeedSource{suffix}.py"))
    kinds = [type(node).__name__ for node in tree.body]
    assert kinds == ["Expr", "ImportFrom", "ImportFrom", "Assign", "ClassDef"]  # docstring, imports, base, class
    slave = tree.body[-1]
    assert [base.id for base in slave.bases] == ["ModelSlave", FMI_VERSIONS[version].base]
    assert [type(node).__name__ for node in slave.body] == ["Expr"]


HOLD_ALL = """
import sys
from fmpy import extract, instantiate_fmu, read_model_description
instances = []
for path in sys.argv[1:]:
    description = read_model_description(path)
    fmu = instantiate_fmu(extract(path), description)
    if description.fmiVersion == "2.0":
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    else:
        fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()
    instances.append(fmu)
for fmu in instances:
    fmu.doStep(0.0, 1e-3)
for fmu in instances:
    fmu.terminate()
    fmu.freeInstance()
print("stepped", len(instances))
"""


def test_different_fmus_alive_at_once_in_one_host(fmu_path, tmp_path):
    """The first FMU (no rotor modules) defines the host's ``driveline``; the FMUs after it find
    their own modules next to it, in either FMI version."""
    paths = [fmu_path("CardanJoint", "2"), fmu_path("CriticalSpeeds", "3"), fmu_path("TripodCoupling", "3"),
             fmu_path("CriticalSpeeds", "2")]
    host = subprocess.run([sys.executable, "-c", HOLD_ALL, *map(str, paths)], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path)
    assert host.returncode == 0, host.stderr[-2000:]
    assert host.stdout.splitlines()[-1].split() == ["stepped", str(len(paths))]  # after the FMUs' log lines


def test_console_script_is_the_cli():
    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts == {"driveline-fmus": "fmu_harness.cli:main"}


@pytest.mark.parametrize("command", [*cli.COMMANDS, None])
def test_every_command_has_help(command, capsys):
    with pytest.raises(SystemExit) as exit:
        cli.main([command, "--help"] if command else ["--help"])
    assert exit.value.code == 0
    usage = capsys.readouterr().out.splitlines()[0]
    assert usage.startswith(f"usage: driveline-fmus {command or ''}".rstrip())


@pytest.mark.fmu
def test_build_command_builds_one_model(tmp_path):
    """The console script's build, in a process of its own as a user runs it: by default the native
    FMU's binary for this machine alone, each stage's progress shown, n of N."""
    run = subprocess.run([sys.executable, "-m", "fmu_harness.cli", "build", "--dest", str(tmp_path), "--fmi", "2",
                          "--no-references", "SpeedSource"], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert run.returncode == 0, run.stderr[-2000:]
    progress = run.stderr.splitlines()
    assert progress[0] == "Python FMUs [1/1] SpeedSource FMI 2.0"
    host = toolchain.host_platform()
    compiled = [line.split("[")[1].split("]")[0].split("/") for line in progress
                if line.startswith(f"native FMUs: compiling for {host.tuple} [")]
    assert compiled[0][0] == "1" and compiled[-1][0] == compiled[-1][1] == compiled[0][1]
    assert f"native FMUs: linking [1/1] SpeedSource{host.suffix} for {host.tuple}" in progress
    built = fmu_path(tmp_path, "SpeedSource")
    native_built = native.fmu_path(tmp_path, "SpeedSource")  # the model has a C port too
    assert run.stdout.split() == [str(built), str(native_built)]
    assert sorted(tmp_path.rglob("*.fmu")) == sorted([built, native_built])
    assert "driveline/source/model.py" in members(built)


def collected(*options: str) -> set[str]:
    run = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", *options,
                          "tests/project/test_packaging.py", "tests/core/test_validity.py"],
                         capture_output=True, text=True, timeout=300, cwd=ROOT)
    return {line.split("::")[1].split("[")[0] for line in run.stdout.splitlines() if "::" in line}


def test_markers_follow_what_the_tests_use():
    """Assigned in conftest.py: a built FMU makes an ``fmu`` test, none a ``core`` one, a measured
    cost of SLOW_SECONDS or more a ``slow`` one; ``--fmi 2`` drops the FMI 3.0 variants."""
    fmu, core = collected("-m", "fmu"), collected("-m", "core")
    assert {"test_each_fmu_ships_the_modules_its_model_imports", "test_build_command_builds_one_model"} <= fmu
    assert {"test_every_command_has_help", "test_a_declared_rule_refuses_with_its_message"} <= core
    assert not fmu & core and "test_markers_follow_what_the_tests_use" in core
    measured_slow = {nodeid.split("::")[1].split("[")[0] for nodeid, seconds in measured().items()
                     if nodeid.startswith(("tests/project/test_packaging.py", "tests/core/test_validity.py"))
                     and seconds >= SLOW_SECONDS}
    assert measured_slow and measured_slow <= collected("-m", "slow")
    run = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", "--fmi", "2",
                          "tests/project/test_packaging.py"], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert "[2]" in run.stdout and "[3]" not in run.stdout


def test_doc_page_rendering():
    """Each construct the doc pages use, rendered; a link to another page of the repository is its
    text and path, a link to a section of the page stays a link."""
    page = "\n".join([
        "# Model — a title", "", "Text with `a | b`, **bold**, *italic* and 2 * 3 * 4,", "joined lines.", "",
        "* item one", "  continued", "* item [two](other_page.md#a-section)", "", "1. first", "2. [back](#model--a-title)",
        "", "| name | rule |", "|---|---|", "| `x` | `|x| <= 1` |", "", "```bash", "a < b && c", "```", "",
        "    indented code", "", "<!-- variables:start -->", "## Variables", "See [the web](https://fmi-standard.org).",
    ])
    rendered = documentation.to_html(page, "model.md")
    body = rendered.split("<body>\n", 1)[1].split("\n</body>", 1)[0]
    assert body.splitlines() == [
        '<h1 id="model--a-title">Model — a title</h1>',
        "<p>Text with <code>a | b</code>, <strong>bold</strong>, <em>italic</em> and 2 * 3 * 4, joined lines.</p>",
        "<ul>", "<li>item one continued</li>",
        "<li>item two (<code>docs/other_page.md</code> in the repository)</li>", "</ul>",
        "<ol>", "<li>first</li>", '<li><a href="#model--a-title">back</a></li>', "</ol>",
        "<table>", "<tr><th>name</th><th>rule</th></tr>", "<tr><td><code>x</code></td><td><code>|x| &lt;= 1</code></td></tr>",
        "</table>",
        "<pre><code>a &lt; b &amp;&amp; c</code></pre>", "<pre><code>indented code</code></pre>",
        '<h2 id="variables">Variables</h2>', '<p>See <a href="https://fmi-standard.org">the web</a>.</p>',
    ]
    assert "<title>Model — a title</title>" in rendered


@pytest.mark.parametrize("folders, words", [
    (["linux64"], "binaries for x86_64 Linux (glibc 2.17 or newer) only; `python build_fmu.py --all-platforms` adds "
                  "x86_64 Windows, aarch64 Linux, x86_64 macOS and aarch64 macOS"),
    ([p.fmi2 for p in toolchain.PLATFORMS], "binaries for x86_64 Linux (glibc 2.17 or newer), x86_64 Windows (Windows "
                                            "10 or newer), aarch64 Linux (glibc 2.17 or newer), x86_64 macOS (macOS 11 "
                                            "or newer) and aarch64 macOS (macOS 11 or newer)"),
    (["x86_64-windows", "riscv64-linux"], "binaries for x86_64 Windows (Windows 10 or newer) and riscv64-linux only; "),
])
def test_the_platforms_a_native_fmu_carries_are_named_from_its_binaries(folders, words):
    names = ["modelDescription.xml", "sources/model.c", *(f"binaries/{folder}/Model.so" for folder in folders)]
    assert toolchain.platforms_sentence(names).startswith(words)


def test_a_python_fmu_names_what_its_host_needs():
    names = ["resources/model.py", "binaries/win64/Model.dll", "binaries/linux64/Model.so"]
    assert toolchain.platforms_sentence(names) == ("binaries for x86_64 Linux and x86_64 Windows; a Python FMU: the host "
                                                   "needs Python with numpy and scipy")


def test_check_names_the_platforms_each_fmu_carries(native_dir, tmp_path):
    """The host-only build the README's set-up makes: this machine's binary alone, and the release command."""
    fmu = native.fmu_path(native_dir, "SpeedSource")
    done = subprocess.run([str(Path(sys.executable).with_name("driveline-fmus")), "check", str(fmu)],
                          capture_output=True, text=True, timeout=120, cwd=tmp_path)
    host = toolchain.host_platform()
    assert done.returncode == 0 and done.stdout.splitlines()[1] == (
        f"SpeedSource.fmu: binaries for {host.name} ({host.oldest} or newer) only; "
        f"`python build_fmu.py --all-platforms` adds "
        f"{toolchain._joined([p.name for p in toolchain.PLATFORMS if p is not host])}")
