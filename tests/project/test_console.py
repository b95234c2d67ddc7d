"""What the commands show: progress rewritten in place on a terminal, throttled lines in a log,
a missing optional package named with its extra."""

from __future__ import annotations

import importlib
import io
from pathlib import Path

import pytest

from fmu_harness.console import CommandParser, Progress, optional, refused, require, summary


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_on_a_terminal_rewrites_one_line(monkeypatch):
    monkeypatch.setenv("COLUMNS", "30")
    stream = Terminal()
    with Progress("build", 3, stream) as shown:
        for item in ("a long name of the first item", "b", "c"):
            shown.advance(item)
    first = "build [1/3] a long name of the first item"[:29]  # cut to the terminal's width less one
    assert stream.getvalue() == f"\r{first}\r{'build [2/3] b':<29}\r{'build [3/3] c':<13}\n"  # the longer one blanked


def test_progress_in_a_log_shows_the_first_and_last_and_at_most_one_line_per_interval():
    stream = io.StringIO()
    with Progress("sweep", 100, stream, interval=3600.0) as shown:
        for n in range(100):
            shown.advance(f"run {n}")
    assert stream.getvalue() == "sweep [1/100] run 0\nsweep [100/100] run 99\n"
    every = io.StringIO()
    with Progress("sweep", 3, every, interval=0.0) as shown:
        for n in range(3):
            shown.advance()
    assert every.getvalue() == "sweep [1/3]\nsweep [2/3]\nsweep [3/3]\n"


def test_a_start_is_shown_at_once_before_its_end():
    stream = io.StringIO()
    with Progress("main job", 2, stream, interval=3600.0) as shown:
        for study in ("tripod", "launch"):
            shown.start(study)
            shown.advance(f"{study} done")
    assert stream.getvalue().splitlines() == ["main job [1/2] tripod ...", "main job [1/2] tripod done",
                                              "main job [2/2] launch ...", "main job [2/2] launch done"]


def test_disabled_progress_counts_silently():
    stream = Terminal()
    with Progress("build", 2, stream, enabled=False) as shown:
        shown.advance("a")
    assert stream.getvalue() == "" and shown.done == 1


def test_a_missing_optional_package_ends_the_command_naming_its_extra():
    with pytest.raises(SystemExit) as exited:
        optional("a_package_that_is_not_there", "sweep", "driveline-fmus sweep")
    assert exited.value.code == ("driveline-fmus sweep needs a_package_that_is_not_there, which is not installed: "
                                 "pip install 'driveline-fmus[sweep]'")
    assert optional("json", "sweep", "driveline-fmus sweep").__name__ == "json"
    with pytest.raises(SystemExit) as exited:
        require("a_package_that_is_not_there", "interop", "driveline-fmus system --engine ecos")
    assert exited.value.code == ("driveline-fmus system --engine ecos needs a_package_that_is_not_there, which is not "
                                 "installed: pip install 'driveline-fmus[interop]'")
    require("json", "interop", "driveline-fmus system")


def test_a_negative_number_in_exponent_form_is_a_value():
    parser = CommandParser(prog="x")
    parser.add_argument("--step", type=float)
    assert parser.parse_args(["--step", "-2e-4"]).step == -2e-4
    assert parser.parse_args(["--step", "-.5"]).step == -0.5


def test_help_shows_each_options_default_once(capsys):
    parser = CommandParser(prog="x")
    parser.add_argument("--steps", type=int, default=360, help="steps of a turn")
    parser.add_argument("--step", type=float, default=1e-3, help="the step (default 1e-3)")
    parser.add_argument("--flag", action="store_true", help="a flag")
    parser.add_argument("--set", action="append", default=[], help="repeatable")
    parser.add_argument("--layout", default="", help="a layout")
    text = " ".join(parser.format_help().split())
    assert "steps of a turn (default 360)" in text and "the step (default 1e-3) " in text
    assert "a flag " in text and "a flag (default" not in text and "repeatable (default" not in text
    assert text.endswith("a layout")


def test_a_refusal_is_one_line_and_status_1(capsys):
    with pytest.raises(SystemExit) as exited:
        raise refused("driveline-fmus check", "joint (TripodCoupling): parameter r = -10 mm must be positive")
    assert exited.value.code == 1
    assert capsys.readouterr().err == "driveline-fmus check: refused: joint (TripodCoupling): parameter r = -10 mm must be positive\n"


def _commands() -> list[str]:
    """The modules whose ``--help`` describes them by :func:`summary` of their docstring."""
    root = Path(__file__).resolve().parents[2]
    return sorted(str(path.relative_to(root).with_suffix("")).replace("/", ".")
                  for folder in ("benchmarks", "fmu_harness") for path in (root / folder).rglob("*.py")
                  if "summary(__doc__)" in path.read_text())


@pytest.mark.parametrize("module", _commands())
def test_a_commands_help_opens_with_a_whole_sentence(module):
    """Its docstring's first paragraph on one line, a sentence ending with a period, short enough to read."""
    described = summary(importlib.import_module(module).__doc__)
    assert described.endswith(".") and "\n" not in described and 20 <= len(described) <= 200, described
