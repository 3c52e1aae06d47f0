"""Hostile files: every file the GUI reads may come from someone else. XML entities are refused
(a "billion laughs" file, external entities reading other files), absurd sizes are refused
before anything is loaded (files, binary STL counts, VRML instancing bombs), and a fuzz of the
public Kautham corpus (truncated and mutated copies) gets one clear error or a valid plan from
``problem_info``, never a traceback or a hang."""
from __future__ import annotations

import contextlib
import io
import json
import os
import random
import shutil
import signal
import sys

import pytest

from gui.tools.problem_info import main as problem_info_main
from gui.core import shapes
from gui.core.kautham.corpus import (WHOLE_CORPUS_TESTS, whole_corpus_dir,
                                     whole_missing_message)
from gui.core.kautham.urdf import read_urdf
from gui.core.kautham.xmlfile import read_xml
from gui.core.shapes import ShapeDefaults, read_shape
from gui.errors import ProblemError, ShapeError
from odin_common.limits import MAX_INPUT_FILE_MB

LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE Problem [
 <!ENTITY lol "lol">
 <!ENTITY lol1 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
 <!ENTITY lol2 "&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;">
 <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
 <!ENTITY lol9 "&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;">
]>
<Problem name="&lol9;"><Scene scene="a.iv"/></Problem>
"""


def problem_info(path):
    """problem_info's exit status, stdout and stderr, run in this process."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = problem_info_main([str(path), "--indent", "0"])
    return status, out.getvalue(), err.getvalue()


def one_error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if ": warning: " not in line]
    assert len(lines) == 1 and lines[0].startswith("problem_info: error: "), err
    assert "Traceback" not in err
    return lines[0]


def test_a_billion_laughs_problem_is_refused_at_its_first_entity(tmp_path):
    f = tmp_path / "laughs.xml"
    f.write_text(LAUGHS)
    status, out, err = problem_info(f)
    assert status == 2 and out == ""
    line = one_error_line(err)
    assert f"{f}:3:" in line and "entity 'lol'" in line and "refused" in line


def test_an_external_entity_never_reads_the_file_it_names(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("SECRET-TOKEN")
    for name, text in (
            ("external.xml", f'<!DOCTYPE Problem [<!ENTITY x SYSTEM "file://{secret}">]>'
                             f'<Problem name="&x;">&x;</Problem>'),
            ("parameter.xml", f'<!DOCTYPE Problem [<!ENTITY % x SYSTEM "file://{secret}">%x;]>'
                              f'<Problem/>'),
            ("dtd.xml", f'<!DOCTYPE Problem SYSTEM "file://{secret}"><Problem/>')):
        f = tmp_path / name
        f.write_text(text)
        status, out, err = problem_info(f)
        assert status == 2, (name, out, err)
        assert "SECRET-TOKEN" not in out + err
        one_error_line(err)
    with pytest.raises(ProblemError, match="external.xml:1: declares the entity 'x'"):
        read_xml(tmp_path / "external.xml")


def test_a_robots_urdf_with_entities_is_refused_naming_the_urdf(tmp_path):
    urdf = tmp_path / "r.urdf"
    urdf.write_text(LAUGHS.replace("Problem", "robot"))
    with pytest.raises(ProblemError, match=r"r\.urdf:3: declares the entity"):
        read_urdf(urdf)


def test_files_larger_than_the_limit_are_refused_before_they_are_read(tmp_path):
    size = (MAX_INPUT_FILE_MB + 1) * 2 ** 20
    for name in ("huge.xml", "huge.wrl"):
        with open(tmp_path / name, "wb") as f:
            f.truncate(size)              # sparse: nothing is written
    status, out, err = problem_info(tmp_path / "huge.xml")
    assert status == 2 and f"larger than the {MAX_INPUT_FILE_MB} MB" in one_error_line(err)
    with pytest.raises(ShapeError, match="larger than the"):
        read_shape(tmp_path / "huge.wrl")


def test_a_binary_stl_announcing_too_many_triangles_is_refused_unread(tmp_path):
    count = 50_000
    f = tmp_path / "big.stl"
    with open(f, "wb") as out:
        out.write(b"\0" * 80 + count.to_bytes(4, "little"))
        out.truncate(84 + 50 * count)
    with pytest.raises(ShapeError, match="holds 50,000 triangles, more than the 1,000"):
        read_shape(f, defaults=ShapeDefaults(max_triangles=1_000))


def instancing_bomb(path, levels=12):
    """An Inventor file of 10**levels one-triangle shapes in a few lines (DEF/USE)."""
    lines = ["#Inventor V2.1 ascii", "Separator {",
             " DEF a0 Separator { Coordinate3 { point [0 0 0, 1 0 0, 0 1 0] }"
             " IndexedFaceSet { coordIndex [0, 1, 2, -1] } }"]
    for k in range(1, levels + 1):
        use = " ".join([f"Translation {{ translation 0 0 1 }} USE a{k - 1}"] * 10)
        lines.append(f" DEF a{k} Separator {{ {use} }}")
    path.write_text("\n".join(lines + ["}"]) + "\n")
    return path


def test_a_vrml_instancing_bomb_stops_at_the_shape_and_triangle_limits(tmp_path):
    bomb = instancing_bomb(tmp_path / "bomb.iv")
    with pytest.raises(ShapeError, match="more than 500 shape nodes"):
        read_shape(bomb, defaults=ShapeDefaults(max_shape_nodes=500))
    many = tmp_path / "many.iv"
    many.write_text("#Inventor V2.1 ascii\nSeparator { Coordinate3 { point [0 0 0, 1 0 0, "
                    "0 1 0, 1 1 0] } IndexedFaceSet { coordIndex ["
                    + ", ".join(["0, 1, 2, -1, 1, 3, 2, -1"] * 300) + "] } }\n")
    with pytest.raises(ShapeError, match="more than 100 triangles"):
        read_shape(many, defaults=ShapeDefaults(max_triangles=100))
    assert read_shape(many).mesh is not None     # the defaults hold it


# ------------------------------------------------------------------ fuzzing the corpus

MUTATIONS_PER_FILE = 3


class Hang(Exception):
    pass


@contextlib.contextmanager
def time_limit(seconds):
    def expired(*_):
        raise Hang()
    previous = signal.signal(signal.SIGALRM, expired)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def mutate(data: bytes, rng: random.Random) -> bytes:
    """One of: cut short, bytes flipped, a line dropped or doubled, a number made absurd, a
    wrong encoding (declared or applied)."""
    kind = rng.randrange(6)
    if kind == 5:
        return rng.choice([
            data.decode("latin-1").encode("utf-16"),                  # UTF-16, no declaration
            b'<?xml version="1.0" encoding="klingon"?>\n' + data,       # an unknown encoding
            data.replace(b"?>", b' encoding="UTF-16"?>', 1),          # declared, not applied
            data.decode("latin-1").encode("utf-8").replace(b"e", b"\xe9", 3)])  # stray latin-1
    if kind == 0:
        return data[:rng.randrange(len(data))]
    if kind == 1:
        out = bytearray(data)
        for _ in range(rng.randint(1, 8)):
            out[rng.randrange(len(out))] = rng.randrange(256)
        return bytes(out)
    lines = data.split(b"\n")
    k = rng.randrange(len(lines))
    if kind == 2:
        return b"\n".join(lines[:k] + lines[k + 1:])
    if kind == 3:
        return b"\n".join(lines[:k + 1] + lines[k:])
    import re
    numbers = list(re.finditer(rb"-?\d+(\.\d+)?", data))
    if not numbers:
        return data[:len(data) // 2]
    m = rng.choice(numbers)
    absurd = rng.choice([b"nan", b"1e400", b"-1", b"0", b"1e30", b"abc", b"", b"1e308",
                         b"-1e308", b"1e-308"])
    return data[:m.start()] + absurd + data[m.end():]


def opened_files(problem, root):
    """problem_info's status on ``problem`` and the other files under ``root`` it opened."""
    opened, recording = [], [True]

    def record(event, args):
        if (recording[0] and event == "open" and isinstance(args[0], str)
                and args[0].startswith(str(root))):
            opened.append(args[0])
    shapes._CACHE.clear()
    sys.addaudithook(record)   # cannot be removed: the test runs forked, and stops recording
    try:
        status, _, _ = problem_info(problem)
    finally:
        recording[0] = False
    return status, [type(problem)(p) for p in sorted(set(opened) - {str(problem)})]


def fuzz(copy, mutations: int, rng: random.Random, each_file_once: bool) -> int:
    """Mutates every file each problem under ``copy`` that problem_info accepts opens (the
    problem and what it references, STL meshes aside: binary), ``mutations`` times each, and
    checks problem_info's answer: JSON, or one clear error line; never a traceback or a hang.
    ``each_file_once``: a file several problems share is fuzzed with the first only. Returns
    the number of runs."""
    problems = sorted(p for p in copy.rglob("*.xml") if b"<Problem" in p.read_bytes()[:4000])
    assert len(problems) >= 5
    runs, done = 0, set()
    for problem in problems:
        status, dependencies = opened_files(problem, copy)
        if status != 0:
            continue                       # a problem Odin refuses as it is: nothing to fuzz
        for target in [problem] + [p for p in dependencies if p.suffix.lower() != ".stl"]:
            if each_file_once and target in done:
                continue
            done.add(target)
            original = target.read_bytes()
            for _ in range(mutations):
                target.write_bytes(mutate(original, rng))
                runs += 1
                check_problem_info(problem, target)
            target.write_bytes(original)
        for target in [problem] + dependencies:
            if each_file_once and (target, "replaced") in done:
                continue
            done.add((target, "replaced"))
            for how in REPLACEMENTS:
                with replaced(target, how):
                    runs += 1
                    line = check_problem_info(problem, target)
                assert line is not None and str(target) in line, (how, target, line)
    return runs


REPLACEMENTS = ("fifo", "zero", "loop")
"""What a file a problem names is replaced with, once each: a FIFO (an open would block for
ever), /dev/zero (endless), a symbolic link loop: each refused naming it."""


@contextlib.contextmanager
def replaced(target, how: str):
    aside = target.with_name(target.name + ".aside")
    target.rename(aside)
    try:
        if how == "fifo":
            os.mkfifo(target)
        elif how == "zero":
            target.symlink_to("/dev/zero")
        else:
            target.symlink_to(target.name)
        yield
    finally:
        target.unlink()
        aside.rename(target)


def check_problem_info(problem, target):
    """problem_info's error line on ``problem`` (``target`` mutated), None for a plan (its
    JSON strict: no NaN or Infinity)."""
    shapes._CACHE.clear()
    try:
        with time_limit(60):
            status, out, err = problem_info(problem)
    except Hang:
        pytest.fail(f"problem_info hung on {problem} with {target} mutated")
    except Exception as error:     # what the test is for: nothing escapes
        pytest.fail(f"{type(error).__name__} escaped problem_info on {problem} "
                    f"with {target} mutated: {error}")
    if status == 0:
        strict_json(out)
        return None
    assert status == 2, err
    return one_error_line(err)


@pytest.mark.forked
def test_mutated_and_truncated_corpus_files_get_one_clear_error_or_a_plan(kautham_dir,
                                                                          tmp_path):
    copy = tmp_path / "kautham"
    shutil.copytree(kautham_dir, copy)
    runs = fuzz(copy, MUTATIONS_PER_FILE, random.Random(20261123), each_file_once=False)
    assert runs >= 50


@pytest.mark.forked
@pytest.mark.timeout(3 * 3600)     # thousands of problem_info runs on the whole corpus
@pytest.mark.skipif(os.environ.get(WHOLE_CORPUS_TESTS) != "1",
                    reason=f"the whole Kautham corpus: `make corpus` runs it "
                    f"({WHOLE_CORPUS_TESTS}=1)")
def test_mutated_files_of_kautham_s_whole_corpus_get_one_clear_error_or_a_plan(tmp_path):
    """The same over every problem of Kautham's public repository at the pinned commits
    (tools/get_kautham.sh --all), each file once: about 1,500 runs."""
    whole = whole_corpus_dir()
    if whole is None:
        pytest.fail(whole_missing_message())
    copy = tmp_path / "kautham_all"
    shutil.copytree(whole, copy, symlinks=True)
    runs = fuzz(copy, 1, random.Random(20261125), each_file_once=True)
    assert runs >= 500


def test_an_unknown_encoding_is_one_clear_error(tmp_path):
    f = tmp_path / "encoding.xml"
    f.write_text('<?xml version="1.0" encoding="UTF0"?>\n<Problem/>\n')
    status, _, err = problem_info(f)
    assert status == 2 and "malformed XML" in one_error_line(err)


def test_path_and_control_files_larger_than_the_limit_are_refused_unread(tmp_path):
    from gui.core.control_path import read_control_path
    from gui.core.paths import read_path
    from gui.errors import PathFileError
    huge = tmp_path / "huge.txt"
    with open(huge, "wb") as f:
        f.truncate((MAX_INPUT_FILE_MB + 1) * 2 ** 20)
    with pytest.raises(PathFileError, match="larger than the"):
        read_path(huge)
    with pytest.raises(PathFileError, match="larger than the"):
        read_control_path(huge, 2)


# ------------------------------------------------------------------ scales and lengths

def strict_json(text: str):
    """JSON with no NaN or Infinity (which JSON does not have)."""
    def refuse(name):
        raise AssertionError(f"{name} in problem_info's JSON")
    return json.loads(text, parse_constant=refuse)


CRATE = ('<robot name="crate"><link name="body"><inertial><mass value="{mass}"/>'
         '<inertia ixx="{ixx}" iyy="0.1" izz="0.1"/></inertial><collision>'
         '<origin xyz="{xyz}"/><geometry>{geometry}</geometry></collision></link></robot>\n')
TETRA = ("#Inventor V2.1 ascii\nSeparator { Coordinate3 { point [0 0 0, {far} 0 0, 0 1 0, "
         "0 0 1] } IndexedFaceSet { coordIndex [0, 2, 1, -1, 0, 1, 3, -1, 0, 3, 2, -1, "
         "1, 2, 3, -1] } }\n")


def _scene(folder, obstacle="crate.urdf", scale="1", home='X="0"', mass="2", ixx="0.1",
           xyz="0 0 0", geometry='<box size="0.3 0.2 0.1"/>', far="1", rob=None):
    folder.mkdir()
    (folder / "crate.urdf").write_text(CRATE.format(mass=mass, ixx=ixx, xyz=xyz,
                                                    geometry=geometry))
    (folder / "tetra.iv").write_text(TETRA.replace("{far}", far))
    (folder / "tetra.stl").write_text(
        f"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex {far} 0 0\n"
        "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n")
    if rob is not None:
        (folder / "arm.rob").write_text(rob)
    problem = folder / "p.xml"
    problem.write_text(f'<Problem><Obstacle obstacle="{obstacle}" scale="{scale}">'
                       f'<Home {home}/></Obstacle></Problem>\n')
    return problem


ROB = ('<Robot name="arm" DHType="Standard"><Joints><Joint name="base" ivFile="tetra.iv"/>'
       '<Joint name="j1" ivFile="tetra.iv"><DHPars a="{a}" d="0" alpha="0" theta="0"/>'
       '<Limits Low="-90" Hi="90"/>'
       '</Joint></Joints></Robot>\n')

ABSURD = {     # what the problem or its files say -> what the one error line must quote
    "problem scale 1e308": (dict(scale="1e308"), "scale='1e308'"),
    "problem scale 1e-300": (dict(scale="1e-300"), "scale='1e-300'"),
    "problem scale -2": (dict(scale="-2"), "scale='-2'"),
    "problem scale 0": (dict(scale="0"), "scale='0'"),
    "home X 1e300": (dict(home='X="1e300"'), "<Home> X Y Z"),
    "mesh scale 1e308": (dict(geometry='<mesh filename="tetra.iv" scale="1e308 1e308 1e308"/>'),
                         "scale='1e308 1e308 1e308'"),
    "uneven mesh scale 1e200": (dict(geometry='<mesh filename="tetra.stl" scale="1e200 1 1"/>'),
                                "scale='1e200 1 1'"),
    "mesh scale times problem scale": (dict(scale="1e10", geometry='<mesh filename="tetra.iv" '
                                            'scale="1e10 1e10 1e10"/>'), "tetra.iv"),
    "origin 1e300": (dict(xyz="1e300 0 0"), "<origin xyz='1e300 0 0'>"),
    "box of 1e9 m": (dict(geometry='<box size="1e9 1 1"/>'), "<box> size"),
    "mass 1e300": (dict(mass="1e300"), "<mass value='1e300'>"),
    "inertia 1e300": (dict(ixx="1e300"), "<inertia>"),
    "inertia 1e20 at scale 1e10": (dict(ixx="1e20", scale="1e10"), "<inertia>"),
    "VRML vertex 1e30": (dict(obstacle="tetra.iv", far="1e30"), "a vertex reaches"),
    "STL vertex 1e300": (dict(obstacle="tetra.stl", far="1e300"), "a vertex reaches"),
    "rob DH a 1e305": (dict(obstacle="arm.rob", rob=ROB.format(a="1e305")), "<DHPars a d>"),
}


@pytest.mark.parametrize("case", sorted(ABSURD))
def test_an_absurd_scale_or_scaled_length_is_one_error_naming_file_and_value(case, tmp_path):
    settings, quoted = ABSURD[case]
    problem = _scene(tmp_path / "scene", **settings)
    shapes._CACHE.clear()
    status, out, err = problem_info(problem)
    assert status == 2 and out == "", (out, err)
    line = one_error_line(err)
    assert quoted in line and str(tmp_path / "scene") in line, line


def test_large_but_possible_scales_print_finite_json(tmp_path):
    rob = ROB.format(a="500")
    for k, settings in enumerate([dict(scale="1000"), dict(scale="1e-3"),
                                  dict(obstacle="tetra.iv", scale="1e6"),
                                  dict(geometry='<mesh filename="tetra.stl" scale="1e4 1 1"/>'),
                                  dict(obstacle="arm.rob", rob=rob, scale="100")]):
        problem = _scene(tmp_path / f"scene{k}", **settings)
        shapes._CACHE.clear()
        status, out, err = problem_info(problem)
        assert status == 0, (settings, err)
        strict_json(out)


# ------------------------------------------------------------------ XML of absurd shape

def _rss_of_problem_info(problem, tmp_path) -> tuple:
    """problem_info on ``problem`` in a child process under a 2 GB address-space limit (an
    unbounded parse fails there, not on the host): its status, stderr and peak RSS (MB)."""
    import subprocess
    script = ("import resource, sys\n"
              "resource.setrlimit(resource.RLIMIT_AS, (2 * 2 ** 30, 2 * 2 ** 30))\n"
              "from gui.tools.problem_info import main as problem_info_main\n"
              "status = problem_info_main([sys.argv[1]])\n"
              "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024, "
              "file=sys.stderr)\n"
              "sys.exit(status)\n")
    run = subprocess.run([sys.executable, "-c", script, str(problem)], capture_output=True,
                         text=True, timeout=120)
    lines = run.stderr.strip().splitlines()
    peak = int(lines[-1]) if lines and lines[-1].isdigit() else None
    return run.returncode, "\n".join(lines[:-1]), peak


@pytest.mark.timeout(120)
@pytest.mark.parametrize("kind", ["problem", "Collada mesh"])
def test_a_file_of_millions_of_empty_elements_is_refused_in_bounded_memory(kind, tmp_path):
    import time
    from odin_common.limits import MAX_XML_ELEMENTS
    bomb = tmp_path / ("empty.xml" if kind == "problem" else "empty.dae")
    root = b"Problem" if kind == "problem" else b"COLLADA"
    with open(bomb, "wb") as f:           # 60 MB: 15 million <a/>
        f.write(b"<" + root + b">")
        f.write(b"<a/>" * (15 * 10 ** 6))
        f.write(b"</" + root + b">")
    problem = bomb
    if kind != "problem":
        problem = tmp_path / "p.xml"
        problem.write_text('<Problem><Obstacle obstacle="empty.dae"/></Problem>')
    started = time.monotonic()
    status, err, peak = _rss_of_problem_info(problem, tmp_path)
    assert status == 2 and "Traceback" not in err, err
    assert f"holds more than {MAX_XML_ELEMENTS:,} elements" in err and str(bomb) in err, err
    assert peak is not None and peak < 800, f"peak RSS {peak} MB"
    assert time.monotonic() - started < 60


def test_deep_wide_and_texty_xml_is_refused_or_read_quickly(tmp_path):
    import time
    from odin_common.limits import MAX_XML_ATTRIBUTES, MAX_XML_DEPTH
    deep = tmp_path / "deep.xml"
    deep.write_text("<Problem>" + "<a>" * 100_000 + "</a>" * 100_000 + "</Problem>")
    with pytest.raises(ProblemError, match=f"more than {MAX_XML_DEPTH:,} levels"):
        read_xml(deep)
    wide = tmp_path / "wide.urdf"
    wide.write_text("<robot " + " ".join(f'a{k}="1"' for k in range(5_000)) + "/>")
    with pytest.raises(ProblemError, match=f"more than {MAX_XML_ATTRIBUTES:,} attributes"):
        read_xml(wide)
    for named in ("<Problem><%s/></Problem>" % ("T" * 100_000),
                  '<Problem><Obstacle %s="1"/></Problem>' % ("a" * 300)):
        (tmp_path / "named.xml").write_text(named)
        with pytest.raises(ProblemError, match="longer than 256 bytes") as refused:
            read_xml(tmp_path / "named.xml")
        # short whatever the name's length: the message less the file's path (which depends
        # on where pytest put it) is a line
        assert len(str(refused.value)) - len(str(tmp_path / "named.xml")) < 250
    texty = tmp_path / "texty.xml"           # 5 million pieces of text in one element
    texty.write_text("<Problem>" + "&amp;" * 5_000_000 + "</Problem>")
    started = time.monotonic()
    assert len(read_xml(texty).text) == 5_000_000
    assert time.monotonic() - started < 30


def test_a_megabyte_value_in_a_file_makes_a_short_error_line(tmp_path):
    huge = "9" * 1_000_000
    (tmp_path / "shell.iv").write_text("#Inventor V2.1 ascii\nSeparator { Sphere { radius 1 } }\n")
    (tmp_path / "m.urdf").write_text(f'<robot name="m"><link name="s"><visual><geometry><mesh '
                                     f'filename="package://kit/{huge}.stl"/></geometry>'
                                     f'</visual></link></robot>')
    for k, element in enumerate([f'<Robot robot="{huge}.urdf"/>',
                                 f'<Obstacle obstacle="shell.iv" scale="{huge}"/>',
                                 f'<Obstacle obstacle="shell.iv"><Home X="1 {huge}"/></Obstacle>',
                                 '<Obstacle obstacle="m.urdf"/>']):
        problem = tmp_path / f"p{k}.xml"
        problem.write_text(f"<Problem>{element}</Problem>")
        status, out, err = problem_info(problem)
        line = one_error_line(err)
        assert status == 2 and str(problem.parent) in line and len(line) < 2_000, line[:300]


ARM = ('<robot name="arm"><link name="base"><collision><geometry><box size="0.2 0.2 0.1"/>'
       '</geometry></collision></link><link name="upper"><collision><geometry>'
       '<cylinder radius="0.03" length="0.4"/></geometry></collision></link>'
       '<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>'
       '<axis xyz="0 0 1"/><limit lower="{low}" upper="{high}" effort="5" velocity="1"/>'
       '</joint></robot>\n')
CNTR = ('<ControlSet><Control name="c1" eigValue="{eig}"><DOF name="arm/upper" value="{value}"/>'
        '</Control><Control name="c2"><DOF name="arm/X" value="1"/></Control></ControlSet>\n')
QUERY_PROBLEM = ('<Problem><Robot robot="arm.urdf"><Home X="0" Y="0" Z="0" WX="0" WY="0" WZ="1" '
                 'TH="0"/><Limits name="X" min="{xmin}" max="{xmax}"/></Robot>'
                 '<Controls robot="arm.cntr"/><Planner><Parameters><Name>omplRRTConnect</Name>'
                 '</Parameters><Queries><Query><Init>0.5 0.5</Init><Goal>0.7 0.3</Goal>'
                 '</Query></Queries></Planner></Problem>\n')


@pytest.mark.parametrize("absurd, quoted", [
    (dict(low="-1e308", high="1e308"), "arm.urdf:1: lower and upper"),
    (dict(eig="1e308"), "arm.cntr:1: <Control eigValue=\"1e308\">"),
    (dict(value="-1e300"), "arm.cntr:1: <DOF value=\"-1e300\">"),
    (dict(xmin="-1e308", xmax="1e308"), "p.xml:1: <Limits name=\"X\"> min max")])
def test_limits_and_control_weights_that_overflow_a_query_are_refused(absurd, quoted, tmp_path):
    """A query maps controls through limits (low + p (high - low)) and weights (offset +
    eigValue value (c - 0.5)): values near 1e308 made them infinite or NaN in the JSON."""
    values = {**dict(low="-2", high="2", eig="1", value="1", xmin="-1", xmax="1"), **absurd}
    (tmp_path / "arm.urdf").write_text(ARM.format(**values))
    (tmp_path / "arm.cntr").write_text(CNTR.format(**values))
    problem = tmp_path / "p.xml"
    problem.write_text(QUERY_PROBLEM.format(**values))
    status, out, err = problem_info(problem)
    assert status == 2 and quoted in one_error_line(err), (out[:300], err)
    values = dict(low="-2", high="2", eig="1", value="1", xmin="-1", xmax="1")
    for name, text in (("arm.urdf", ARM), ("arm.cntr", CNTR), ("p.xml", QUERY_PROBLEM)):
        (tmp_path / name).write_text(text.format(**values))
    status, out, err = problem_info(problem)
    assert status == 0, err
    strict_json(out)


MESH_TEXTS = {
    ".obj": lambda n: "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + "f 1 2 3\n" * n,
    ".ply": lambda n: ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty "
                       "float y\nproperty float z\nelement face %d\nproperty list uchar int "
                       "vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n" % n
                       + "3 0 1 2\n" * n),
    ".off": lambda n: "OFF\n3 %d 0\n0 0 0\n1 0 0\n0 1 0\n" % n + "3 0 1 2\n" * n,
}


@pytest.mark.parametrize("suffix", sorted(MESH_TEXTS))
def test_a_text_mesh_listing_too_many_faces_is_refused_before_it_is_parsed(suffix, tmp_path,
                                                                           monkeypatch):
    small, big = tmp_path / f"small{suffix}", tmp_path / f"big{suffix}"
    small.write_text(MESH_TEXTS[suffix](10))
    big.write_text(MESH_TEXTS[suffix](1_500))
    limits = ShapeDefaults(max_triangles=1_000)
    shapes._CACHE.clear()
    assert read_shape(small, defaults=limits).mesh is not None
    monkeypatch.setattr(shapes, "_read_trimesh", lambda *a: pytest.fail("parsed"))
    with pytest.raises(ShapeError, match="holds 1,500 faces and 3 vertices, more than the "
                                         "1,000 triangles"):
        read_shape(big, defaults=limits)


@pytest.mark.timeout(120)
def test_a_60_mb_obj_of_faces_is_refused_in_bounded_memory(tmp_path):
    with open(tmp_path / "faces.obj", "wb") as f:       # 7.5 million faces
        f.write(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n" + b"f 1 2 3\n" * (75 * 10 ** 5))
    problem = tmp_path / "p.xml"
    problem.write_text('<Problem><Obstacle obstacle="faces.obj"/></Problem>')
    status, err, peak = _rss_of_problem_info(problem, tmp_path)
    assert status == 2 and "holds 7,500,000 faces" in err, err
    assert peak is not None and peak < 500, f"peak RSS {peak} MB"


@pytest.mark.timeout(120)
def test_a_vrml_mesh_over_the_triangle_limit_is_refused_before_its_triangles_are_collected(
        tmp_path, monkeypatch):
    """Coin hands triangles to Python one callback each (~0.1 ms): 2.1 million in one face
    set took minutes before the limit refused them. They are counted first, in C++."""
    import time
    big = tmp_path / "big.iv"
    big.write_bytes(b"#Inventor V2.1 ascii\nSeparator { Coordinate3 { point [0 0 0, 1 0 0, "
                    b"0 1 0] } IndexedFaceSet { coordIndex [" + b"0,1,2,-1," * 2_100_000
                    + b"] } }\n")
    shapes._CACHE.clear()
    monkeypatch.setattr(shapes, "_collect", lambda *a: pytest.fail("collected triangles"))
    started = time.monotonic()
    with pytest.raises(ShapeError, match=r"more than 2,000,000 triangles \(2,100,000;"):
        read_shape(big)
    assert time.monotonic() - started < 30
