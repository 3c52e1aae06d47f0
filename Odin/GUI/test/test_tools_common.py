"""The tools' boundary (gui.tools.common): whatever escapes a tool's main is one line on
stderr and status 2; a bug says it is one; Ctrl-C and a closed pipe pass to
odin_common.tool.run untouched."""
from __future__ import annotations

import argparse

import pytest

from gui.tools.common import (MAX_SECONDS, ToolParser, count, hertz, one_line_errors,
                              reading, seconds)
from gui.errors import GuiError, ProblemError


def _run(raised: BaseException, capsys) -> tuple:
    @one_line_errors("tool")
    def main(argv=None):
        raise raised
    status = main([])
    return status, capsys.readouterr().err.splitlines()


def test_a_refusal_is_its_own_line(capsys):
    status, lines = _run(ProblemError("no <Problem>\nhere", "p.xml", 3), capsys)
    assert status == 2 and lines == ["tool: error: p.xml:3: no <Problem> here"]


@pytest.mark.parametrize("raised", [OverflowError("int too large to convert to float"),
                                    MemoryError(), RecursionError("maximum recursion depth"),
                                    UnicodeDecodeError("utf-8", b"\xff", 0, 1, "invalid"),
                                    IsADirectoryError(21, "Is a directory", "x.xml")])
def test_data_errors_are_one_line_with_their_class(raised, capsys):
    status, lines = _run(raised, capsys)
    assert status == 2 and len(lines) == 1
    assert lines[0].startswith(f"tool: error: {type(raised).__name__}")
    assert "internal error" not in lines[0]


def test_a_bug_says_it_is_one_in_one_line_cut_short(capsys):
    status, lines = _run(KeyError("x" * 100_000), capsys)
    assert status == 2 and len(lines) == 1
    assert lines[0].startswith("tool: error: internal error: KeyError: ")
    assert lines[0].endswith("(please report)") and len(lines[0]) < 500


@pytest.mark.parametrize("raised", [KeyboardInterrupt(), BrokenPipeError(32, "Broken pipe")])
def test_ctrl_c_and_a_closed_pipe_pass_through(raised, capsys):
    with pytest.raises(type(raised)):
        _run(raised, capsys)


def test_reading_names_the_file_a_data_error_came_from():
    with pytest.raises(GuiError, match=r"^deep\.xml: cannot read this problem: RecursionError"):
        with reading("problem", "deep.xml"):
            raise RecursionError("maximum recursion depth exceeded")
    with pytest.raises(ProblemError):            # a reader's own refusal stays as it is
        with reading("problem", "p.xml"):
            raise ProblemError("bad", "p.xml", 1)


def test_option_types_refuse_what_would_overflow_or_mean_nothing():
    for text in ("nan", "inf", "-1", "0", "1e300", f"{MAX_SECONDS * 2:g}", "x" * 10_000):
        with pytest.raises(argparse.ArgumentTypeError):
            seconds(text)
    assert seconds("2.5") == 2.5
    for text in ("-5", "1e-300", "nan", "1e300"):
        with pytest.raises(argparse.ArgumentTypeError):
            hertz(text)
    assert hertz("0") == 0 and hertz("25") == 25
    steps = count(1, 30)
    for text in ("0", "31", "1.5", "9" * 5000):
        with pytest.raises(argparse.ArgumentTypeError):
            steps(text)
    assert steps("30") == 30


def test_a_bad_command_line_is_one_line(capsys):
    parser = ToolParser(prog="tool")
    parser.add_argument("--runs", type=count(1, 10))
    with pytest.raises(SystemExit) as ended:
        parser.parse_args(["--runs", "0"])
    assert ended.value.code == 2
    assert capsys.readouterr().err.splitlines() == [
        "tool: error: --runs 0: at least 1 (--help: usage)"]
