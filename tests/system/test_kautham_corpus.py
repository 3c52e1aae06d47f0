"""tools/get_kautham.sh lays out the corpus byte for byte from a Kautham repository at the
commits its MANIFEST pins, checks every size, and leaves nothing behind when it fails; the
MANIFEST it uses is the corpus's own. With --all it lays out both pinned trees whole, listing
the files whose content the repository copy lacks."""
import pathlib
import re
import shutil
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "tools" / "get_kautham.sh"
MANIFEST = ROOT / "tools" / "kautham" / "MANIFEST.md"
SAMPLE = ["legacy_2012/examples/TRO/2DRR_obstacle.xml", "legacy_2012/examples/robots/2DRR.rob",
          "current_2025/demos/OMPL_ode_demos/Sphere/controls/sp3.cntr"]


def _git(repo: pathlib.Path, *args: str) -> str:
    return subprocess.run(["git", "-C", str(repo), *args], check=True, capture_output=True,
                          text=True).stdout.strip()


def _rows() -> dict:
    """local path -> (repo path, bytes) of the MANIFEST's table."""
    rows = {}
    for line in MANIFEST.read_text().splitlines():
        cells = [c.strip() for c in line.split("|")[1:-1]]
        if len(cells) == 6 and cells[1] == "iocroblab/kautham":
            rows[cells[0]] = (cells[3], cells[4])
    return rows


@pytest.fixture
def fake_kautham(tmp_path, kautham_dir):
    """A git repository holding a few corpus files at their repository paths, and a MANIFEST
    that pins them to its commit."""
    repo = tmp_path / "kautham"
    repo.mkdir()
    _git(repo, "init", "-q")
    rows = _rows()
    for local in SAMPLE:
        target = repo / rows[local][0]
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(kautham_dir / local, target)
    _git(repo, "add", "-A")
    _git(repo, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "corpus")
    commit = _git(repo, "rev-parse", "HEAD")
    table = [f"| {local} | iocroblab/kautham | {commit} | {rows[local][0]} | {rows[local][1]} | "
             "sample |" for local in SAMPLE]
    manifest = tmp_path / "MANIFEST.md"
    manifest.write_text("# sample corpus\n\n| local path | repo | commit | repo path | bytes | "
                        "role |\n|---|---|---|---|---|---|\n" + "\n".join(table) + "\n")
    return repo, manifest


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", str(SCRIPT), *args], capture_output=True, text=True,
                          timeout=120)


def test_the_script_lays_out_every_file_byte_for_byte(fake_kautham, tmp_path, kautham_dir):
    repo, manifest = fake_kautham
    dest = tmp_path / "corpus"
    result = _run("--repo", str(repo), "--dest", str(dest), "--manifest", str(manifest))
    assert result.returncode == 0, result.stderr
    for local in SAMPLE:
        assert (dest / local).read_bytes() == (kautham_dir / local).read_bytes(), local
    assert (dest / "MANIFEST.md").read_text() == manifest.read_text()
    again = _run("--repo", str(repo), "--dest", str(dest), "--manifest", str(manifest))
    assert again.returncode == 0 and "already" in again.stdout


def test_a_size_that_differs_from_the_manifest_fails_and_leaves_nothing(fake_kautham,
                                                                         tmp_path):
    repo, manifest = fake_kautham
    manifest.write_text(manifest.read_text().replace(" | sample |", "1 | sample |", 1))
    dest = tmp_path / "corpus"
    result = _run("--repo", str(repo), "--dest", str(dest), "--manifest", str(manifest))
    assert result.returncode == 1
    assert "the MANIFEST says" in result.stderr and len(result.stderr.splitlines()) == 1
    assert not dest.exists()


def test_the_manifest_beside_the_script_is_the_corpus_own(kautham_dir):
    assert MANIFEST.read_text() == (kautham_dir / "MANIFEST.md").read_text()
    rows = _rows()
    assert len(rows) > 80
    assert all((kautham_dir / local).stat().st_size == int(size)
               for local, (_, size) in rows.items())


# -- the whole corpus (--all) ------------------------------------------------------------------

LFS_POINTER = ("version https://git-lfs.github.com/spec/v1\noid sha256:"
               + "0" * 64 + "\nsize 123\n")


@pytest.fixture
def partial_mirror(tmp_path):
    """A bare mirror of a repository whose tree holds a problem, a mesh, an executable, a file
    in a folder with a space, a Git LFS pointer and a blob the mirror lacks (a partial copy),
    and a MANIFEST pinning both trees to its commit."""
    work = tmp_path / "work"
    work.mkdir()
    _git(work, "init", "-q")
    files = {"demos/p.xml": "<Problem/>\n", "demos/models/m.stl": "solid m\nendsolid m\n",
             "tools/run.sh": "#!/bin/sh\n", "docs/a b/readme.txt": "hello\n",
             "demos/big.dae": LFS_POINTER, "demos/lost.wrl": "#VRML V1.0 ascii\n"}
    for name, text in files.items():
        (work / name).parent.mkdir(parents=True, exist_ok=True)
        (work / name).write_text(text)
    (work / "tools/run.sh").chmod(0o755)
    _git(work, "add", "-A")
    _git(work, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "tree")
    commit = _git(work, "rev-parse", "HEAD")
    mirror = tmp_path / "mirror.git"
    subprocess.run(["git", "clone", "-q", "--mirror", "--no-local", str(work), str(mirror)],
                   check=True)
    lost = _git(work, "rev-parse", "HEAD:demos/lost.wrl")
    for pack in (mirror / "objects" / "pack").glob("*"):     # every object but one, loose
        pack.unlink()
    for obj in _git(work, "rev-list", "--objects", "--all").splitlines():
        oid = obj.split()[0]
        if oid == lost:
            continue
        kind = _git(work, "cat-file", "-t", oid)
        data = subprocess.run(["git", "-C", str(work), "cat-file", kind, oid], check=True,
                              capture_output=True).stdout
        subprocess.run(["git", "-C", str(mirror), "hash-object", "-w", "-t", kind, "--stdin",
                        "--literally"], input=data, check=True, capture_output=True)
    manifest = tmp_path / "MANIFEST.md"
    manifest.write_text("| local path | repo | commit | repo path | bytes | role |\n|---|---|---|"
                        "---|---|---|\n"
                        f"| legacy_2012/x | iocroblab/kautham | {commit} | x | 1 | sample |\n"
                        f"| current_2025/y | iocroblab/kautham | {commit} | y | 1 | sample |\n")
    return mirror, manifest, files


def test_all_lays_out_every_file_of_both_pinned_trees_and_lists_what_it_skips(partial_mirror,
                                                                              tmp_path):
    mirror, manifest, files = partial_mirror
    dest = tmp_path / "all"
    result = _run("--all", "--repo", str(mirror), "--dest", str(dest), "--manifest",
                  str(manifest))
    assert result.returncode == 0, result.stderr
    for tree in ("legacy_2012", "current_2025"):
        for name, text in files.items():
            laid = dest / tree / name
            if name in ("demos/big.dae", "demos/lost.wrl"):
                assert not laid.exists(), laid
            else:
                assert laid.read_text() == text, laid
        assert (dest / tree / "tools/run.sh").stat().st_mode & 0o111
    skipped = (dest / "SKIPPED.md").read_text()
    assert "| legacy_2012 | demos/big.dae | a Git LFS pointer" in skipped
    assert "| current_2025 | demos/lost.wrl | absent from the repository copy" in skipped
    assert "| legacy_2012 |" in (dest / "ALL.md").read_text()
    assert " | 4 | 2 |" in (dest / "ALL.md").read_text()
    again = _run("--all", "--repo", str(mirror), "--dest", str(dest), "--manifest",
                 str(manifest))
    assert again.returncode == 0 and "already" in again.stdout


def test_all_refuses_a_commit_the_repository_lacks_and_leaves_nothing(partial_mirror,
                                                                      tmp_path):
    mirror, manifest, _ = partial_mirror
    text = manifest.read_text()
    commit = re.search(r"[0-9a-f]{40}", text).group()
    manifest.write_text(text.replace(commit, "f" * 40, 1))
    dest = tmp_path / "all"
    result = _run("--all", "--repo", str(mirror), "--dest", str(dest), "--manifest",
                  str(manifest))
    assert result.returncode == 1 and "has no commit" in result.stderr
    assert not dest.exists()
