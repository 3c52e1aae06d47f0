"""The disk cache of shapes: the same shape as reading the file, by content, never trusted
blindly (corrupt and concurrent entries, files that name other files, --no-cache)."""
from __future__ import annotations

import multiprocessing
import os
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from gui.core import shape_cache, shapes

SCENE = ("#Inventor V2.1 ascii\nSeparator {\n Material { diffuseColor 0 1 0 }\n"
         " Coordinate3 { point [ 0 0 0, 1 0 0, 0 1 0, 0 0 1 ] }\n"
         " IndexedFaceSet { coordIndex [ 0, 2, 1, -1, 0, 1, 3, -1, 0, 3, 2, -1, 1, 2, 3, -1 ] }\n"
         " Translation { translation 0 0 5 }\n Sphere { radius 2 }\n}\n")


@pytest.fixture
def cache(tmp_path, monkeypatch):
    folder = tmp_path / "cache"
    monkeypatch.setenv("ODIN_CACHE_DIR", str(folder))
    monkeypatch.delenv("ODIN_NO_CACHE", raising=False)
    monkeypatch.setattr(shape_cache, "_enabled", None)
    shapes._CACHE.clear()
    yield folder / "shapes"
    shapes._CACHE.clear()


def _read(path, scale=0.001):
    shapes._CACHE.clear()          # this process's own cache would hide the disk's
    return shapes.read_shape(path, scale)


def _same(a, b) -> None:
    assert a.source == b.source
    np.testing.assert_array_equal(a.mesh.vertices, b.mesh.vertices)
    np.testing.assert_array_equal(a.mesh.triangles, b.mesh.triangles)
    assert a.mesh.triangles.dtype == b.mesh.triangles.dtype == np.uint32
    assert a.mesh.color == b.mesh.color
    assert [(p.kind, p.parameters, p.color) for p in a.primitives] == \
        [(p.kind, p.parameters, p.color) for p in b.primitives]
    for p, q in zip(a.primitives, b.primitives):
        np.testing.assert_array_equal(p.pose, q.pose)


def test_a_cached_shape_is_the_shape_read_bit_for_bit_and_is_not_read_again(cache, tmp_path,
                                                                            monkeypatch):
    model = tmp_path / "model.iv"
    model.write_text(SCENE)
    first = _read(model)
    assert len(list(cache.glob("*.shape"))) == 1
    monkeypatch.setattr(shapes, "_read_raw", lambda *a: pytest.fail("read the file again"))
    _same(_read(model), first)
    copy = tmp_path / "elsewhere.iv"           # the same content elsewhere: the same entry
    copy.write_text(SCENE)
    _same(_read(copy), replace(first, source=str(copy)))
    assert len(list(cache.glob("*.shape"))) == 1


def test_another_scale_or_an_edited_file_is_read_again(cache, tmp_path):
    model = tmp_path / "model.iv"
    model.write_text(SCENE)
    small = _read(model, 0.001)
    assert _read(model, 1.0).mesh.vertices.max() == pytest.approx(1000 * small.mesh.vertices.max())
    model.write_text(SCENE.replace("radius 2", "radius 3"))
    assert _read(model).primitives[0].parameters == pytest.approx((0.003,))
    assert len(list(cache.glob("*.shape"))) == 3


def test_a_corrupt_entry_is_dropped_and_the_file_read_again(cache, tmp_path):
    model = tmp_path / "model.iv"
    model.write_text(SCENE)
    first = _read(model)
    (entry,) = cache.glob("*.shape")
    whole = entry.read_bytes()
    header_end = whole.index(b"}}") + 2 if b"}}" in whole else 80
    damages = [b"", b"not an entry", whole[:100], whole[:-1], whole + b"\0",
               whole[:header_end - 5] + whole[header_end:],           # header cut
               whole[:-12] + (4000).to_bytes(4, "little") * 3]        # vertex out of range
    for damage in damages:
        entry.write_bytes(damage)
        _same(_read(model), first)
        assert entry.read_bytes() == whole              # written whole again


def test_a_planted_entry_with_objects_is_refused_not_run(cache, tmp_path):
    model = tmp_path / "model.iv"
    model.write_text(SCENE)
    first = _read(model)
    (entry,) = cache.glob("*.shape")
    with entry.open("wb") as planted:                                # needs pickle to load
        np.savez(planted, has_mesh=np.array([object()], dtype=object))
    _same(_read(model), first)


def test_a_file_that_only_mentions_file_or_inline_is_cached(cache, tmp_path):
    model = tmp_path / "model.iv"
    model.write_text(SCENE.replace("Separator {", "# a File written by Inline Tools\nSeparator {"))
    _read(model)
    assert len(list(cache.glob("*.shape"))) == 1


def _read_in_child(path: str, folder: str, queue) -> None:
    import os
    os.environ["ODIN_CACHE_DIR"] = folder
    shapes._CACHE.clear()
    shape = shapes.read_shape(path, 0.001)
    queue.put((shape.mesh.vertices.tobytes(), len(shape.primitives)))


def test_processes_reading_at_once_all_get_the_whole_shape(cache, tmp_path):
    model = tmp_path / "model.iv"
    model.write_text(SCENE)
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    children = [context.Process(target=_read_in_child,
                                args=(str(model), str(cache.parent), queue)) for _ in range(6)]
    for child in children:
        child.start()
    results = [queue.get(timeout=60) for _ in children]
    for child in children:
        child.join(30)
        assert child.exitcode == 0
    expected = _read(model)
    assert set(results) == {(expected.mesh.vertices.tobytes(), 1)}
    assert [p.name for p in cache.iterdir()] == [p.name for p in cache.glob("*.shape")]


def test_files_that_name_other_files_and_no_cache_are_read_every_time(cache, tmp_path,
                                                                      monkeypatch):
    inline = tmp_path / "with_inline.wrl"
    inline.write_text("#VRML V2.0 utf8\nInline { url \"other.wrl\" }\n"
                      "Shape { geometry Sphere { radius 1 } }\n")
    _read(inline)
    assert not cache.exists() or not list(cache.glob("*.shape"))
    model = tmp_path / "model.iv"
    model.write_text(SCENE)
    monkeypatch.setenv("ODIN_NO_CACHE", "1")
    _read(model)
    assert not cache.exists() or not list(cache.glob("*.shape"))


def test_an_unwritable_cache_folder_costs_only_the_speed(tmp_path, monkeypatch):
    blocker = tmp_path / "file_not_folder"
    blocker.write_text("")
    monkeypatch.setenv("ODIN_CACHE_DIR", str(blocker))
    monkeypatch.setattr(shape_cache, "_enabled", None)
    model = tmp_path / "model.iv"
    model.write_text(SCENE)
    assert _read(model).primitives[0].kind == "sphere"


def test_the_oldest_entries_go_past_the_limit(cache, tmp_path, monkeypatch):
    monkeypatch.setattr(shape_cache, "MAX_ENTRIES", 2)
    for radius in (1, 2, 3, 4):
        model = tmp_path / f"m{radius}.iv"
        model.write_text(SCENE.replace("radius 2", f"radius {radius}"))
        _read(model)
    assert len(list(cache.glob("*.shape"))) == 2


def test_problem_info_no_cache_gives_the_same_answer(cache, kautham_dir):
    problem = kautham_dir / "legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml"
    script = shapes.pathlib.Path(shapes.__file__).parents[3] / "scripts" / "problem_info"
    runs = [subprocess.run([sys.executable, str(script), str(problem), *extra],
                           capture_output=True, text=True, timeout=300)
            for extra in ([], [], ["--no-cache"])]
    assert all(run.returncode == 0 for run in runs), runs[0].stderr
    assert runs[0].stdout == runs[1].stdout == runs[2].stdout
    assert len(list(cache.glob("*.shape"))) == 16       # the distinct geometry files it reads


def _rewritten(whole: bytes, edit=None, payload=None) -> bytes:
    """An entry with its JSON header passed through ``edit`` (a function changing the parsed
    header in place) and/or its arrays replaced by ``payload``."""
    import json
    import struct
    magic = shape_cache._MAGIC
    (size,) = struct.unpack_from("<Q", whole, len(magic))
    start = len(magic) + 8
    header = json.loads(whole[start:start + size])
    if edit is not None:
        edit(header)
    text = json.dumps(header).encode()     # NaN and Infinity written as JSON cannot
    rest = whole[start + size:] if payload is None else payload(whole[start + size:])
    return magic + struct.pack("<Q", len(text)) + text + rest


def _set(path, value):
    def edit(header):
        target = header
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value
    return edit


def _vertex(value):
    return lambda arrays: np.array([value], "<f8").tobytes() + arrays[8:]


DAMAGED = {
    "colour NaN": _set(("mesh", "color", 0), float("nan")),
    "colour 7": _set(("mesh", "color", 1), 7.0),
    "radius negative": _set(("primitives", 0, "parameters", 0), -2.0),
    "radius Infinity": _set(("primitives", 0, "parameters", 0), float("inf")),
    "radius a string": _set(("primitives", 0, "parameters", 0), "2"),
    "two radii": _set(("primitives", 0, "parameters"), [1.0, 2.0]),
    "a teapot": _set(("primitives", 0, "kind"), "teapot"),
    "a pose scaled": _set(("primitives", 0, "pose", 0), 2.0),
    "a pose of 15 values": lambda h: h["primitives"][0]["pose"].pop(),
    "a pose at 1e300": _set(("primitives", 0, "pose", 3), 1e300),
    "sizes as strings": _set(("mesh", "sizes"), ["4", "4"]),
    "sizes true": lambda h: h["mesh"]["sizes"].__setitem__(1, True),
    "sizes not matching": lambda h: h["mesh"]["sizes"].__setitem__(0, 3),
    "empty": lambda h: h.update(mesh=None, primitives=[]),
    "a list": None,
}


@pytest.mark.timeout(60)
def test_a_damaged_entry_is_verified_dropped_and_the_file_read_again(cache, tmp_path, caplog):
    model = tmp_path / "model.iv"
    model.write_text(SCENE)
    first = _read(model)
    (entry,) = cache.glob("*.shape")
    whole = entry.read_bytes()
    variants = {name: _rewritten(whole, edit) for name, edit in DAMAGED.items() if edit}
    variants["a list"] = whole.replace(b'{"mesh"', b'[{"mesh"', 1)
    variants["a vertex NaN"] = _rewritten(whole, payload=_vertex(float("nan")))
    variants["a vertex Infinity"] = _rewritten(whole, payload=_vertex(float("inf")))
    variants["a vertex at 1e300"] = _rewritten(whole, payload=_vertex(1e300))
    with caplog.at_level("INFO", logger="gui.core"):
        for name, damaged in variants.items():
            entry.write_bytes(damaged)
            _same(_read(model), first)
            assert entry.read_bytes() == whole, name          # written whole again
    assert [r.getMessage() for r in caplog.records if r.levelname != "DEBUG"] == []
    for planted in ("fifo", "directory", "zero"):              # never opened, never waited on
        entry.unlink()
        if planted == "fifo":
            os.mkfifo(entry)
        elif planted == "directory":
            entry.mkdir()
        else:
            entry.symlink_to("/dev/zero")
        _same(_read(model), first)
        if planted == "directory":
            entry.rmdir()
            _read(model)
        assert entry.is_file() and entry.read_bytes() == whole, planted
