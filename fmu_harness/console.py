"""What the commands show their user: a mistake in one line, the progress of long work, a missing
optional package named with its extra.

A mistake is found before any work starts and ends the command with one line and a non-zero exit
(:class:`CommandParser`, :func:`optional`); work taking more than a few seconds reports ``n of N``
and what it is at (:class:`Progress`).
"""

from __future__ import annotations

import argparse
import importlib
import shutil
import sys
import threading
import time
from types import ModuleType
from typing import TextIO

DISTRIBUTION = "driveline-fmus"


class CommandParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line, ``prog: error: message``, exit 2 (argparse's
    own print the usage first)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message}\n")


def summary(doc: str | None) -> str:
    """A command's description for ``--help``: its module docstring's first paragraph on one line."""
    return " ".join((doc or "").strip().split("\n\n", 1)[0].split())


def optional(module: str, extra: str, command: str) -> ModuleType:
    """Import ``module`` of the optional dependencies ``extra``; without it, end ``command`` in one
    line that names what to install."""
    try:
        return importlib.import_module(module)
    except ImportError as missing:
        raise SystemExit(f"{command} needs {missing.name or module}, which is not installed: "
                         f"pip install '{DISTRIBUTION}[{extra}]'") from None


class Progress:
    """``what [n/N] item`` on ``stream`` (standard error): rewritten in place on a terminal,
    elsewhere (a log, a pipe) one line per item at most every ``interval`` seconds, the first and
    the last always; nothing unless ``enabled``. Safe to advance from several threads."""

    def __init__(self, what: str, total: int, stream: TextIO | None = None, interval: float = 2.0,
                 enabled: bool = True):
        self.what, self.total, self.done, self.enabled = what, total, 0, enabled
        self.stream = stream or sys.stderr
        self.interval = interval
        self.terminal = self.stream.isatty()
        self._shown = -float("inf")
        self._width = 0
        self._lock = threading.Lock()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.terminal and self._width:
            self.stream.write("\n")
            self.stream.flush()

    def advance(self, item: str = "") -> None:
        """One more of the ``total`` done; ``item`` names it."""
        with self._lock:
            self.done += 1
            if not self.enabled:
                return
            now = time.monotonic()
            if not self.terminal and self.done not in (1, self.total) and now - self._shown < self.interval:
                return
            self._shown = now
            line = f"{self.what} [{self.done}/{self.total}] {item}".rstrip()
            if self.terminal:  # cut to the terminal's width: a wrapped line cannot be rewritten
                line = line[:shutil.get_terminal_size().columns - 1]
                self.stream.write("\r" + line.ljust(self._width))
                self._width = len(line)
            else:
                self.stream.write(line + "\n")
            self.stream.flush()
