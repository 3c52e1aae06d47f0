"""The crane of our own the GUI's tests use (Odin/GUI/test/kautham_files.py: a 1 m mast and a
1 m boom slewing +-3 rad about z at 0.6 m up the mast), for node tests, each writing the problem
it needs around it."""
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "Odin" / "GUI" / "test"))
from kautham_files import crane_and_post, crane_urdf  # noqa: E402

CRANE_URDF = crane_urdf()

__all__ = ["CRANE_URDF", "crane_and_post"]
