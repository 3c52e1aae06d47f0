"""What the documents say of the services agrees with the service tables
(odin_common.interface.WORLD_SERVICES and VIEWER_SERVICES) and with Odin/Services/srv: the
README's Layout counts them, ARCHITECTURE.md's drawing numbers them, and the VirtualWorld
Portal's docstring points to the table instead of listing them by hand."""
import ast
import pathlib
import re

from odin_common.interface import VIEWER_SERVICES, WORLD_SERVICES

ROOT = pathlib.Path(__file__).resolve().parents[2]
PORTAL = ROOT / "Odin/VirtualWorld/src/virtual_world/portal"


def _layout_services_line() -> str:
    """The README Layout's entry for Services/, its continuation lines joined."""
    layout = ROOT.joinpath("README.md").read_text().split("## Layout", 1)[1]
    entry = re.search(r"^  Services/ (.*\n(?: {20,}\S.*\n)*)", layout, re.MULTILINE)
    assert entry, "README's Layout has no Services/ entry"
    return " ".join(entry.group(1).split())


def _types_the_world_calls() -> set:
    """The Viewer's service types the world's viewer link imports (it calls those)."""
    tree = ast.parse(PORTAL.joinpath("viewer_link.py").read_text())
    imported = {alias.name for node in ast.walk(tree)
                if isinstance(node, ast.ImportFrom) and node.module == "Services.srv"
                for alias in node.names}
    return imported & set(VIEWER_SERVICES.values())


def test_every_srv_file_is_in_one_service_table():
    files = {p.stem for p in ROOT.joinpath("Odin/Services/srv").glob("*.srv")}
    world, viewer = set(WORLD_SERVICES.values()), set(VIEWER_SERVICES.values())
    assert not world & viewer
    assert files == world | viewer


def test_the_readme_layout_counts_the_services_of_the_tables():
    line = _layout_services_line()
    counts = re.search(r"(\d+) served by the world .*?(\d+) by the Viewer .*?(\d+) the world "
                       r"calls, (\d+) more", line)
    assert counts, f"README's Layout says of Services/: {line!r}"
    world, viewer, called, more = map(int, counts.groups())
    called_types = _types_the_world_calls()
    assert (world, viewer) == (len(WORLD_SERVICES), len(VIEWER_SERVICES)), line
    assert (called, more) == (len(called_types), len(VIEWER_SERVICES) - len(called_types)), line


def test_the_architecture_drawing_numbers_the_services_of_the_tables():
    drawing = ROOT.joinpath("docs/ARCHITECTURE.md").read_text().split("```")[1]
    assert [int(n) for n in re.findall(r"(\d+) srv\b", drawing)] == \
        [len(WORLD_SERVICES), len(VIEWER_SERVICES)]


def test_the_portal_docstring_points_to_the_table_and_lists_no_service():
    docstring = ast.get_docstring(ast.parse(PORTAL.joinpath("node.py").read_text()))
    assert "WORLD_SERVICES" in docstring
    listed = [name for name in WORLD_SERVICES if f"``~{name}``" in docstring]
    assert listed == [], f"the Portal's docstring lists services by hand: {listed}"
