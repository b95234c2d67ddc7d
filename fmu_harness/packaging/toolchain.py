"""The C toolchain of the native FMUs: the five platforms they are built for, the compilers, and
the compile and link steps, run in parallel.

One cross compiler serves every platform: ``zig cc`` from the ``ziglang`` package on PyPI (clang
with the C libraries of every target: glibc of a chosen version, mingw-w64 for Windows, the macOS
SDK stubs). The Linux targets link against glibc 2.17 (manylinux2014's baseline), so the
libraries load on any Linux of the last decade. ``$CC`` overrides the compiler of the host's own
platform; without ziglang, the machine's ``cc`` builds the host platform alone.
"""

from __future__ import annotations

import os
import platform as _platform
import shlex
import shutil
import struct
import subprocess
import sys
from collections.abc import Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from ..console import Progress

# -ffp-contract=off: no fused multiply-add (clang fuses by default where the CPU has it, aarch64), so
# every platform rounds as the Python core does, operation by operation
CFLAGS = ("-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2", "-ffp-contract=off", "-fvisibility=hidden")
GLIBC = "2.17"  # manylinux2014
MACOS = "11.0"  # Big Sur, the first with Apple silicon
NO_COMPILER = ("no C compiler for the native FMUs: `pip install ziglang` (or install one, e.g. "
               "Debian `apt-get install gcc`, or set $CC)")


class NoCompiler(RuntimeError):
    """Neither ziglang, ``$CC`` nor a ``cc`` on the PATH."""


@dataclass(frozen=True)
class Platform:
    """A platform the native FMUs carry a binary for."""

    tuple: str  # FMI 3.0 platform tuple, the binaries folder of FMI 3.0
    fmi2: str  # FMI 2.0 binaries folder: the standard's name, FMI 2.0.4's platform tuple beyond them
    zig: str  # zig's target triple
    suffix: str  # of the shared library
    name: str  # what a host's user calls it
    oldest: str  # the oldest system the binary runs on


    @property
    def system(self) -> str:
        return self.tuple.split("-")[1]

    def folder(self, fmi: str) -> str:
        return self.tuple if fmi == "3" else self.fmi2


PLATFORMS = (
    Platform("x86_64-linux", "linux64", f"x86_64-linux-gnu.{GLIBC}", ".so", "x86_64 Linux", f"glibc {GLIBC}"),
    Platform("x86_64-windows", "win64", "x86_64-windows-gnu", ".dll", "x86_64 Windows", "Windows 10"),
    Platform("aarch64-linux", "aarch64-linux", f"aarch64-linux-gnu.{GLIBC}", ".so", "aarch64 Linux", f"glibc {GLIBC}"),
    Platform("x86_64-darwin", "darwin64", f"x86_64-macos.{MACOS}", ".dylib", "x86_64 macOS", "macOS 11"),
    Platform("aarch64-darwin", "aarch64-darwin", f"aarch64-macos.{MACOS}", ".dylib", "aarch64 macOS", "macOS 11"),
)
BY_TUPLE = {p.tuple: p for p in PLATFORMS}
RELEASE_COMMAND = "python build_fmu.py --all-platforms"
"""The one command that builds the native FMUs to hand on: every one with the binaries of :data:`PLATFORMS`."""


def carried_platforms(members: Iterable[str]) -> tuple[list[Platform], list[str]]:
    """The platforms whose binaries an FMU's archive ``members`` (its file names) hold, in the order of
    :data:`PLATFORMS`, and the folders of ``binaries/`` that name none of them (another tool's FMU)."""
    members = list(members)
    folders = {parts[1] for parts in (name.split("/") for name in members)
               if len(parts) > 2 and parts[0] == "binaries" and parts[2]}
    known = [p for p in PLATFORMS if {p.tuple, p.fmi2} & folders]
    return known, sorted(folders - {folder for p in known for folder in (p.tuple, p.fmi2)})


def platforms_sentence(members: Iterable[str]) -> str:
    """Which platforms' binaries an FMU carries, by its archive's ``members`` (file names), each with the
    oldest system it runs on; for a native FMU (C sources in ``sources/``) lacking some, the command that
    adds them, for a Python FMU what its host needs besides."""
    members = list(members)
    known, others = carried_platforms(members)
    native = any(name.startswith("sources/") and name.endswith(".c") for name in members)
    names = [f"{p.name} ({p.oldest} or newer)" if native else p.name for p in known] + others
    carried = f"binaries for {_joined(names)}" if names else "no binary"
    if not native:
        return f"{carried}; a Python FMU: the host needs Python with numpy and scipy"
    missing = [p.name for p in PLATFORMS if p not in known]
    return f"{carried}{f' only; `{RELEASE_COMMAND}` adds {_joined(missing)}' if missing else ''}"


def _joined(names: Sequence[str]) -> str:
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"


def host_platform() -> Platform | None:
    """The platform of this machine, if it is one of :data:`PLATFORMS`."""
    machine = {"amd64": "x86_64", "arm64": "aarch64"}.get(_platform.machine().lower(), _platform.machine().lower())
    system = {"win32": "windows", "darwin": "darwin"}.get(sys.platform, "linux" if sys.platform.startswith("linux") else sys.platform)
    return BY_TUPLE.get(f"{machine}-{system}")


def zig() -> Path | None:
    """The zig executable of the installed ``ziglang`` package, if any."""
    try:
        import ziglang
    except ImportError:
        return None
    executable = Path(ziglang.__file__).parent / ("zig.exe" if sys.platform == "win32" else "zig")
    return executable if executable.is_file() else None


def host_compiler() -> list[str]:
    """A C compiler for programs of this machine (test hosts, benchmarks): ``$CC``, else
    ``zig cc``, else ``cc``/``gcc``."""
    if os.environ.get("CC"):
        return shlex.split(os.environ["CC"])
    if (found := zig()) is not None:  # the baseline CPU, not this one's (valgrind knows every instruction)
        return [str(found), "cc", "-mcpu=baseline"]
    system = system_compiler()
    if system is None:
        raise NoCompiler(NO_COMPILER)
    return [system]


def system_compiler() -> str | None:
    """The machine's own C compiler on the PATH, if any."""
    return shutil.which("cc") or shutil.which("gcc")


def release_available() -> bool:
    """Whether the cross compiler for every platform is installed."""
    return zig() is not None


def chosen_platforms(release: bool | None = None) -> list[Platform]:
    """The platforms a build makes binaries for: all five (``release``; the default when ziglang
    is installed) or the host's alone."""
    if release is None:
        release = release_available()
    if release:
        if not release_available():
            raise NoCompiler("the release build needs ziglang: `pip install ziglang`")
        return list(PLATFORMS)
    host = host_platform()
    if host is None:
        raise NoCompiler(f"this machine ({_platform.machine()} {sys.platform}) is none of the native FMUs' platforms")
    host_compiler()  # refuses early, with the message naming what to install
    return [host]


def compiler_for(target: Platform, host_only: bool = False) -> list[str]:
    """The compiler command of ``target``: zig's for its target; in a host-only build ``$CC``, or
    zig, or the machine's ``cc``."""
    if host_only:
        if os.environ.get("CC") or zig() is None:
            return host_compiler()
        return [str(zig()), "cc", "-target", target.zig, "-mcpu=baseline"]
    found = zig()
    if found is None:
        raise NoCompiler(f"building for {target.tuple} needs ziglang: `pip install ziglang`")
    return [str(found), "cc", "-target", target.zig, "-mcpu=baseline"]


def compile_flags(target: Platform) -> list[str]:
    return [*CFLAGS, *(() if target.system == "windows" else ("-fPIC",)), *link_time_optimisation(target)]


def link_time_optimisation(target: Platform) -> tuple[str, ...]:
    """Link-time optimisation (a model's calls across its modules inlined: 5.5 % fewer instructions in a step of
    the vehicle launch, the same results) where zig's linker takes it, Linux's ELF; its Windows and macOS linkers
    do not."""
    return ("-O2", "-flto") if target.system == "linux" else ()


def link_flags(target: Platform, library: Path, by_zig: bool = True) -> list[str]:
    """Shared library, stripped; libm where it is a library of its own (Linux); the name a macOS
    loader records is the file's own; linked by zig, a Windows DLL's header time is a hash of its
    contents (``/Brepro``), not the time of the build, so that a rebuild gives the same bytes."""
    flags = ["-shared", "-s", *link_time_optimisation(target)]
    if target.system == "linux":
        flags.append("-lm")
    elif target.system == "windows" and by_zig:
        flags.append("-Wl,/Brepro")
    elif target.system == "darwin":
        flags.append(f"-Wl,-install_name,@rpath/{library.name}")
    return flags


def universal(slices: Sequence[bytes]) -> bytes:
    """A universal (fat) Mach-O file of thin ones: the big-endian fat header, one entry per slice
    (its CPU type and subtype, read from the slice's own header), each slice aligned to 2^14."""
    align = 14
    header = struct.pack(">II", 0xCAFEBABE, len(slices))
    offset = -(-(len(header) + 20 * len(slices)) // (1 << align)) * (1 << align)
    entries, body = b"", b""
    for thin in slices:
        cpu_type, cpu_subtype = struct.unpack_from("<ii", thin, 4)
        entries += struct.pack(">iiIII", cpu_type, cpu_subtype, offset, len(thin), align)
        padded = -(-len(thin) // (1 << align)) * (1 << align)
        body += thin + bytes(padded - len(thin))
        offset += padded
    start = header + entries
    return start + bytes(-(-len(start) // (1 << align)) * (1 << align) - len(start)) + body


@dataclass(frozen=True)
class Step:
    """One compiler run: ``command`` makes ``output``; ``what`` names it in an error."""

    command: tuple[str, ...]
    output: Path
    what: str


def compile_step(target: Platform, source: Path, output: Path, include: Path, headers: Path, host_only: bool) -> Step:
    """Compile ``source`` with the sources' folder ``include`` and the FMI ``headers`` (as system
    headers: they are not held to this project's warnings)."""
    command = [*compiler_for(target, host_only), *compile_flags(target), "-I", str(include), "-isystem", str(headers),
               "-c", str(source), "-o", str(output)]
    return Step(tuple(command), output, f"{source.name} for {target.tuple}")


def link_step(target: Platform, objects: Iterable[Path], library: Path, host_only: bool) -> Step:
    compiler = compiler_for(target, host_only)
    command = [*compiler, *(() if target.system == "windows" else ("-fPIC",)),
               *(str(o) for o in objects), "-o", str(library), *link_flags(target, library, compiler[0] == str(zig()))]
    return Step(tuple(command), library, f"{library.name} for {target.tuple}")


def run(steps: Sequence[Step], jobs: int | None = None, progress: Progress | None = None) -> None:
    """Run independent compiler steps, ``jobs`` at a time (default: one per core), each done
    step shown on ``progress``."""

    def one(step: Step) -> None:
        step.output.parent.mkdir(parents=True, exist_ok=True)
        done = subprocess.run(step.command, capture_output=True, text=True)
        if done.returncode:
            raise RuntimeError(f"compiling {step.what} failed:\n{done.stderr}")
        if progress is not None:
            progress.advance(step.what)

    with ThreadPoolExecutor(max_workers=jobs or os.cpu_count() or 1) as pool:
        for future in [pool.submit(one, step) for step in steps]:
            future.result()
