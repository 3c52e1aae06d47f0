"""Runs every rostest file of the stack (Odin/*/test/*.test) under pytest, the runner CI reads.

rostest gives each file a master of its own on a random port; the wrapper gives it a private
ROS_HOME and fails with rostest's own output when any test case failed.
"""
import pathlib

import pytest

from ros_harness import run_rostest

ROOT = pathlib.Path(__file__).resolve().parent.parent
TEST_FILES = sorted(ROOT.glob("Odin/*/test/*.test"))


@pytest.mark.parametrize("test_file", TEST_FILES, ids=[f"{p.parent.parent.name}/{p.name}"
                                                        for p in TEST_FILES])
def test_rostest_file(test_file):
    result = run_rostest(str(test_file))
    output = result.stdout + result.stderr
    assert result.returncode == 0 and "FAILURE" not in output, output[-5000:]
    assert "SUCCESS" in output, output[-5000:]
