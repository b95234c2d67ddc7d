"""What the commands show their user: a mistake in one line, the progress of long work, a missing
optional package named with its extra.

A mistake is found before any work starts and ends the command with one line and a non-zero exit
(:class:`CommandParser`, :func:`optional`); work taking more than a few seconds reports ``n of N``
and what it is at (:class:`Progress`).
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import re
import shutil
import sys
import threading
import time
from types import ModuleType
from typing import TextIO

DISTRIBUTION = "driveline-fmus"


NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")
"""A negative number as a value, ``-2``, ``-.5``, ``-2e-4`` (argparse's own misses the exponent and
takes ``--step -2e-4`` for an option)."""

REFUSED = 1
"""The exit status of start values an FMU would refuse (a command-line mistake exits with 2)."""


class CommandParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line, ``prog: error: message``, exit 2 (argparse's
    own print the usage first); a negative number is a value, and ``--help`` shows every option's
    default (:class:`DefaultsShown`)."""

    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("formatter_class", DefaultsShown)
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message}\n")


class DefaultsShown(argparse.HelpFormatter):
    """Help that ends each option's text with ``(default X)`` unless the text names its default or it
    has none to show (None, False, an empty list or text)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        shown = action.default not in (None, False, [], "", argparse.SUPPRESS) and action.option_strings
        if not shown or "default" in text:
            return text
        return f"{text} (default %(default)s)".lstrip()


def refused(command: str, reason: str) -> SystemExit:
    """The end of a command whose start values an FMU would refuse: ``command: refused: reason``, one
    line, exit status :data:`REFUSED` (``driveline-fmus check``, ``system``, ``sweep`` and ``map`` alike)."""
    print(f"{command}: refused: {reason}", file=sys.stderr)
    return SystemExit(REFUSED)


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


def require(module: str, extra: str, command: str) -> None:
    """End ``command`` as :func:`optional` does unless ``module`` can be imported, without importing it
    (Ecos's module loads only once its TBB library is)."""
    try:
        found = importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        found = False
    if not found:
        raise SystemExit(f"{command} needs {module}, which is not installed: pip install '{DISTRIBUTION}[{extra}]'")


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

    def start(self, item: str) -> None:
        """The next of the ``total`` starts: ``what [n/N] item ...``, shown at once, for work whose items
        each take long (a study of the main job)."""
        with self._lock:
            if self.enabled:
                self._show(f"{self.what} [{self.done + 1}/{self.total}] {item} ...")

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
            self._show(f"{self.what} [{self.done}/{self.total}] {item}".rstrip())

    def _show(self, line: str) -> None:
        """``line`` on the stream: in place of the last on a terminal, else a line of its own."""
        if self.terminal:  # cut to the terminal's width: a wrapped line cannot be rewritten
            line = line[:shutil.get_terminal_size().columns - 1]
            self.stream.write("\r" + line.ljust(self._width))
            self._width = len(line)
        else:
            self.stream.write(line + "\n")
        self.stream.flush()
