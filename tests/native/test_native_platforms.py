"""The native FMUs as released, a binary for each of five platforms, built once per session with
zig (:mod:`fmu_harness.packaging.toolchain`): the Linux binaries need glibc 2.17 at most; the Windows
binaries run under wine and the aarch64 Linux ones under qemu-aarch64, through builds of
``tests/support/native_host.c`` for those platforms, and reproduce the x86_64 Linux binary's outputs on the
standard scenarios; the macOS binaries, which cannot run here, are checked structurally (lief)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest
from fmpy.validation import validate_fmu

from fmu_harness.packaging import native, toolchain
from support.native_host import HOST_SOURCE, RUNS, host_command, host_tolerance

lief = pytest.importorskip("lief", reason="the binaries' structural checks need lief (pip install lief)")

EMULATED = {"x86_64-windows": "wine (Debian: apt-get install wine wine64)",
            "aarch64-linux": "qemu-aarch64 (Debian: apt-get install qemu-user) and the aarch64 C library "
                             "(Debian: apt-get install libc6-arm64-cross)"}

#: Where an emulated binary may depart from the x86_64 Linux one more than host_tolerance allows: the
#: tripod's exact kinematics with friction, where the last-bit differences of the Windows C library's
#: trigonometric functions from glibc's reach the outputs as 1e-10 relative (1.9e-10 measured with the
#: closure's analytic Jacobian, 2.4e-10 with the forward-difference one it replaced: the closure is
#: not what amplifies them; the seed reactions' mode gives 5.1e-14); the aarch64 glibc gives 1.4e-16.
PLATFORM_TOLERANCES = {("x86_64-windows", "TripodCoupling"): 1e-9}


def _members(release_dir: Path, name: str, fmi: str) -> dict[str, bytes]:
    with zipfile.ZipFile(native.fmu_path(release_dir, name, fmi)) as archive:
        return {member: archive.read(member) for member in archive.namelist() if member.startswith("binaries/")}


def _binary(release_dir: Path, name: str, fmi: str, platform: toolchain.Platform) -> bytes:
    return _members(release_dir, name, fmi)[f"binaries/{platform.folder(fmi)}/{name}{platform.suffix}"]


@pytest.mark.parametrize("name", native.native_models())
def test_every_native_fmu_carries_the_five_platforms(release_dir, name, fmi):
    expected = {f"binaries/{p.folder(fmi)}/{name}{p.suffix}" for p in toolchain.PLATFORMS}
    assert set(_members(release_dir, name, fmi)) == expected
    assert validate_fmu(str(native.fmu_path(release_dir, name, fmi))) == []


def test_a_rebuild_gives_the_same_five_platform_fmu_byte_for_byte(release_dir, tmp_path, fmi):
    """The Windows DLL's header time (a hash of its contents), the zip entries' times and order:
    nothing of the build's moment or folder enters the FMU."""
    rebuilt = native.build_all(tmp_path, ["SpeedSource"], (fmi,), release=True)[0]
    assert rebuilt.read_bytes() == native.fmu_path(release_dir, "SpeedSource", fmi).read_bytes()


def _glibc_versions(binary: lief.ELF.Binary) -> set[tuple[int, ...]]:
    names = {aux.name for requirement in binary.symbols_version_requirement
             for aux in requirement.get_auxiliary_symbols()}
    return {tuple(int(part) for part in n.removeprefix("GLIBC_").split(".")) for n in names if n.startswith("GLIBC_")}


@pytest.mark.parametrize("name", native.native_models())
@pytest.mark.parametrize("platform", [p for p in toolchain.PLATFORMS if p.system == "linux"], ids=lambda p: p.tuple)
def test_linux_binaries_load_on_glibc_2_17(release_dir, name, fmi, platform):
    """The highest GLIBC_ symbol version a Linux binary needs is 2.17 (manylinux2014): it loads on
    RHEL/Rocky 7 to 9, Ubuntu 14.04 and newer, SLES 12 and newer."""
    binary = lief.ELF.parse(list(_binary(release_dir, name, fmi, platform)))
    versions = _glibc_versions(binary)
    assert versions and max(versions) <= (2, 17)
    assert binary.header.machine_type.name == {"x86_64": "X86_64", "aarch64": "AARCH64"}[platform.tuple.split("-")[0]]
    assert "libc.so.6" in binary.libraries and set(binary.libraries) <= {"libc.so.6", "libm.so.6"}  # libm if called
    assert {s.name for s in binary.exported_symbols if s.name}.issubset({s.name for s in binary.dynamic_symbols})
    assert all(s.name.startswith(f"fmi{fmi}") for s in binary.exported_symbols)


#: What zig's Mach-O linker adds to every dylib's exports (ld64 keeps them private): the image's
#: own header and the handle of its C++ static destructors; neither is an FMI function a host looks up.
MACHO_LINKER_SYMBOLS = {"__mh_dylib_header", "___dso_handle"}


@pytest.mark.parametrize("name", native.native_models())
@pytest.mark.parametrize("platform", [p for p in toolchain.PLATFORMS if p.system == "darwin"], ids=lambda p: p.tuple)
def test_macos_binaries_are_dylibs_of_the_right_architecture(release_dir, name, fmi, platform):
    """macOS binaries cannot run here: Mach-O dylibs of the platform's CPU, for macOS 11 or newer,
    exporting the FMI functions only, linked against libSystem alone; the arm64 ones code-signed
    (ad hoc), as Apple silicon requires of any code it loads. FMI 2.0's ``darwin64`` is universal
    (x86_64 and arm64: importers on Apple silicon look there), its arm64 slice the
    ``aarch64-darwin`` binary."""
    fat = lief.MachO.parse(list(_binary(release_dir, name, fmi, platform)))
    slices = [fat.at(index) for index in range(fat.size)]
    architectures = {"x86_64": ["X86_64"], "aarch64": ["ARM64"]}[platform.tuple.split("-")[0]]
    if platform.folder(fmi) == "darwin64":
        architectures = ["X86_64", "ARM64"]
        arm = _binary(release_dir, name, fmi, toolchain.BY_TUPLE["aarch64-darwin"])
        offset = fat.at(1).fat_offset
        assert _binary(release_dir, name, fmi, platform)[offset:offset + len(arm)] == arm
    assert [binary.header.cpu_type.name for binary in slices] == architectures
    for binary in slices:
        assert binary.header.file_type == lief.MachO.Header.FILE_TYPE.DYLIB
        loaded = [c.name for c in binary.commands if c.command == lief.MachO.LoadCommand.TYPE.LOAD_DYLIB]
        assert loaded == ["/usr/lib/libSystem.B.dylib"]
        exported = {s.name for s in binary.exported_symbols} - MACHO_LINKER_SYMBOLS
        assert exported and all(symbol.startswith(f"_fmi{fmi}") for symbol in exported)
        assert tuple(binary.build_version.minos) <= (11, 0, 0)
        assert binary.has_code_signature or binary.header.cpu_type.name == "X86_64"


@pytest.mark.parametrize("name", native.native_models())
def test_windows_binary_exports_only_fmi(release_dir, name, fmi):
    binary = lief.PE.parse(list(_binary(release_dir, name, fmi, toolchain.BY_TUPLE["x86_64-windows"])))
    assert binary.header.machine == lief.PE.Header.MACHINE_TYPES.AMD64
    exported = [entry.name for entry in binary.get_export().entries]
    assert exported and all(symbol.startswith(f"fmi{fmi}") for symbol in exported)


# -- running the Windows and aarch64 binaries ---------------------------------------------------------


def aarch64_sysroot() -> Path | None:
    """The aarch64 C library qemu-aarch64 loads the programs' libraries from: ``$QEMU_LD_PREFIX``,
    else the folder Debian's libc6-arm64-cross installs (the dynamic loader's ``lib/`` parent)."""
    if os.environ.get("QEMU_LD_PREFIX"):
        return Path(os.environ["QEMU_LD_PREFIX"])
    if shutil.which("dpkg-query") is None:
        return None
    listed = subprocess.run(["dpkg-query", "-L", "libc6-arm64-cross"], capture_output=True, text=True).stdout
    loaders = [Path(line) for line in listed.splitlines() if line.endswith("/lib/ld-linux-aarch64.so.1")]
    return loaders[0].parent.parent if loaders else None


def _runner(platform: str, host: Path) -> list[str]:
    if platform == "x86_64-windows":
        return ["wine", str(host)]
    return ["qemu-aarch64", "-L", str(aarch64_sysroot()), str(host)]


def _missing(platform: str) -> bool:
    if platform == "x86_64-windows":
        return shutil.which("wine") is None
    return shutil.which("qemu-aarch64") is None or aarch64_sysroot() is None


@pytest.fixture(scope="module")
def hosts(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """tests/support/native_host.c for x86_64 Linux, Windows and aarch64 Linux, built with zig."""
    if toolchain.zig() is None:
        pytest.skip("the platforms' test hosts need ziglang (pip install ziglang)")
    folder = tmp_path_factory.mktemp("hosts")
    built = {}
    for platform in ("x86_64-linux", "x86_64-windows", "aarch64-linux"):
        target = toolchain.BY_TUPLE[platform]
        built[platform] = folder / f"native_host_{platform}{'.exe' if target.system == 'windows' else ''}"
        libraries = ["-ldl", "-lm"] if target.system == "linux" else []
        subprocess.run([*toolchain.compiler_for(target), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2",
                        "-isystem", str(native.fmi_headers()), str(HOST_SOURCE), "-o", str(built[platform]),
                        *libraries], check=True, capture_output=True, text=True)
    return built


_REFERENCES: dict[tuple, tuple[list[str], Path]] = {}


def _x86_64_run(hosts, release_dir, fmu_path, name, fmi, parameters, work: Path) -> tuple[list[str], Path]:
    """The x86_64 Linux binary's run of the scenario (checked against the Python FMU): the host
    arguments and the file of its outputs, once per case."""
    key = (name, fmi, repr(sorted(parameters.items())))
    if key not in _REFERENCES:
        work.mkdir()
        arguments = host_command(release_dir, fmu_path, name, fmi, work, parameters)
        outputs = work / "x86_64-linux.txt"
        done = subprocess.run([str(hosts["x86_64-linux"]), *arguments, str(outputs)], capture_output=True, text=True,
                              timeout=300)
        assert done.returncode == 0, done.stdout + done.stderr
        _REFERENCES[key] = arguments, outputs
    return _REFERENCES[key]


def _with_expected(scenario: Path, outputs: Path, tolerance: float, target: Path) -> Path:
    """``scenario`` with the x86_64 binary's outputs as the expected rows and ``tolerance``."""
    lines = [f"tolerance {tolerance!r}" if line.startswith("tolerance ") else line
             for line in scenario.read_text().splitlines()]
    steps = int(next(line for line in lines if line.startswith("steps ")).split()[1])
    inputs = int(lines[0].split()[1])
    header, rows = lines[:-(steps + 1)], lines[-(steps + 1):]
    expected = outputs.read_text().splitlines()
    target.write_text("\n".join([*header, *(" ".join(row.split()[:1 + inputs] + [values])
                                            for row, values in zip(rows, expected))]) + "\n")
    return target


@pytest.mark.parametrize("platform", sorted(EMULATED))
@pytest.mark.parametrize("name, parameters", RUNS)
def test_emulated_binary_reproduces_the_x86_64_binary(hosts, release_dir, fmu_path, tmp_path_factory, platform,
                                                      name, parameters, fmi):
    """The standard scenario (and the modes it leaves out) through the platform's binary, in the
    platform's build of the C host under wine or qemu: two instances, a state stored, serialized
    and restored, a refused step; outputs equal to the x86_64 Linux binary's within host_tolerance
    (relative to each output's largest magnitude; PLATFORM_TOLERANCES where a model amplifies the
    C libraries' last-bit differences). Bit for bit where the platform's C library
    rounds its functions as glibc's x86_64 build does (printed: ``pytest -s``)."""
    if _missing(platform):
        pytest.skip(f"running the {platform} binaries needs {EMULATED[platform]}")
    work = tmp_path_factory.mktemp(f"{name}_{fmi}")
    arguments, reference = _x86_64_run(hosts, release_dir, fmu_path, name, fmi, parameters, work / "x86_64")
    library = native.library_path(Path(arguments[4]).parent, name, fmi, toolchain.BY_TUPLE[platform])
    tolerance = PLATFORM_TOLERANCES.get((platform, name), host_tolerance(name))
    scenario = _with_expected(Path(arguments[3]), reference, tolerance, work / f"{platform}.scenario")
    outputs = work / f"{platform}.txt"
    # on Windows the resources folder as a Windows path (wine's drive Z: is /): FMI 2.0 hands it
    # over as file:///Z:/..., FMI 3.0 as Z:/...
    resources = f"Z:{arguments[4]}" if platform == "x86_64-windows" else arguments[4]
    done = subprocess.run([*_runner(platform, hosts[platform]), str(library), fmi, arguments[2], str(scenario), resources,
                           str(outputs)], capture_output=True, text=True, timeout=600,
                          env={**os.environ, "WINEDEBUG": "-all"})
    assert done.returncode == 0, done.stdout + done.stderr[-3000:]
    deviation = float(re.search(r"deviation (\S+),", done.stdout).group(1))
    identical = outputs.read_text() == reference.read_text()
    print(f"{platform} {name} FMI {fmi}.0 {parameters or ''}: largest relative deviation {deviation:.3g}"
          f"{', bit for bit' if identical else ''}")
    assert deviation <= tolerance
