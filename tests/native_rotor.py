"""The native CriticalSpeeds FMU's rotor library (``fmu_src/native/critical_speeds/``) compiled on its own
(with the shared ``python_numbers.c``), for tests that call its modules through ctypes and compare them
with the Python core.

Compiled with the native FMUs' flags (warnings as errors) except hidden visibility, so that the
library's functions can be called; a test passes the modules it needs and, where ctypes cannot call a
function directly (structures owning arrays), a small C shim of its own.
"""

from __future__ import annotations

import ctypes
import subprocess
from pathlib import Path

from fmu_harness.build import native

ROTOR_SOURCES = native.NATIVE_SRC / "critical_speeds"
TEST_FLAGS = tuple(flag for flag in native.CFLAGS if not flag.startswith("-fvisibility"))


def compile_rotor(folder: Path, modules: list[str], shims: list[Path] = ()) -> ctypes.CDLL:
    """The shared library of the rotor ``modules`` (``"transfer"`` is ``transfer.c``) and ``shims``,
    built in ``folder``."""
    sources = [str(ROTOR_SOURCES / f"{module}.c") for module in modules] + [str(shim) for shim in shims]
    library = folder / f"rotor_{'_'.join(modules)}.so"
    command = [native.compiler(), *TEST_FLAGS, "-shared", "-I", str(ROTOR_SOURCES), *sources,
               str(native.NATIVE_SRC / "python_numbers.c"), "-o", str(library), "-lm"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(f"compiling {', '.join(modules)} failed:\n{done.stderr}")
    return ctypes.CDLL(str(library))
