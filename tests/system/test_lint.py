"""The Python of the repository passes `ruff check` with its config (ruff.toml: pyflakes, 100
columns), so that `make test` catches a finding as `make lint` does; the executables without a
.py suffix (ROS nodes, rosrun scripts) are among the files it reads."""
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _ruff(*arguments: str) -> subprocess.CompletedProcess:
    """ruff (the venv's, tools/requirements.txt) run in the repository root, which picks
    ruff.toml; at most 60 s (it takes well under 2 s)."""
    return subprocess.run([sys.executable, "-m", "ruff", *arguments], cwd=ROOT,
                          capture_output=True, text=True, timeout=60)


def test_ruff_finds_nothing_in_the_repository():
    result = _ruff("check", "--output-format", "concise")
    assert result.returncode == 0, result.stdout + result.stderr


def test_ruff_reads_the_executables_that_have_no_py_suffix():
    result = _ruff("check", "--show-files")
    assert result.returncode == 0, result.stderr
    read = {pathlib.Path(line.strip()).resolve() for line in result.stdout.splitlines()
            if line.strip()}
    executables = sorted(path.resolve() for pattern in ("Odin/*/scripts/*", "Odin/*/nodes/*")
                         for path in ROOT.glob(pattern) if path.is_file())
    assert len(executables) >= 9       # the GUI's six tools and the three nodes
    assert [path for path in executables if path not in read] == []
    assert ROOT.joinpath("conftest.py").resolve() in read
