"""Runs every rostest file of the stack (Odin/*/test/rostest/*.test) under pytest, the runner
CI reads.

rostest gives each file a master of its own on a random port; the wrapper gives it a private
ROS_HOME and fails with rostest's own output when any test case failed.
"""
import pathlib
import re

import pytest

from odin_common.ros_master import run_rostest

ROOT = pathlib.Path(__file__).resolve().parents[2]
TEST_FILES = sorted(ROOT.glob("Odin/*/test/rostest/*.test"))


@pytest.mark.parametrize("test_file", TEST_FILES, ids=[f"{p.parents[2].name}/{p.name}"
                                                        for p in TEST_FILES])
def test_rostest_file(test_file):
    result = run_rostest(str(test_file))
    output = result.stdout + result.stderr
    # rostest exits 0 even when a case failed: read its summary as well
    summary = re.search(r"RESULT: (\w+).*?TESTS: (\d+).*?ERRORS: (\d+).*?FAILURES: (\d+)",
                        output, re.S)
    assert result.returncode == 0 and summary, output[-5000:]
    verdict, tests, errors, failures = summary.groups()
    assert (verdict, errors, failures) == ("SUCCESS", "0", "0") and int(tests) > 0, output[-5000:]
