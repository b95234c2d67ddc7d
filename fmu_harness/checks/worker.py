"""The worker processes of the checks that run an engine or an FMU in a process of its own: one
result line on stdout, found among whatever the engines print, and an exit without exit handlers."""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path
from typing import Any

from ..console import CommandParser


def check_parser(description: str, section: str, worker: tuple[str, ...]) -> CommandParser:
    """The command line of a check that regenerates a docs section from worker processes:
    ``--models``, ``--update PAGE`` (its ``section``) and the hidden ``--worker`` (``worker`` names
    its arguments)."""
    parser = CommandParser(description=description)
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs")
    parser.add_argument("--update", type=Path, metavar="PAGE", help=f"markdown page whose {section} to regenerate")
    parser.add_argument("--worker", nargs=len(worker), metavar=worker, help=argparse.SUPPRESS)
    return parser


def answer(prefix: str, result: Any) -> None:
    """Print ``prefix`` and ``result`` as JSON on one line and leave the process: without exit
    handlers, because a Python FMU's wrapper uses freed memory at exit and may abort the process
    after its result (wrapper defect 10, docs/robustness.md)."""
    print(prefix + json.dumps(result), flush=True)
    sys.stderr.flush()
    os._exit(0)


def answer_in(stdout: str, prefix: str) -> Any:
    """The result a worker printed with :func:`answer` (None if it printed none): the engines' own
    messages may reach the pipe after it, so the line is searched for."""
    line = next((line for line in stdout.splitlines() if line.startswith(prefix)), None)
    return None if line is None else json.loads(line.removeprefix(prefix))
