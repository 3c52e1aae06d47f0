"""tools/get_kautham.sh lays out the corpus byte for byte from a Kautham repository at the
commits its MANIFEST pins, checks every size, and leaves nothing behind when it fails; the
MANIFEST it uses is the corpus's own."""
import pathlib
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
