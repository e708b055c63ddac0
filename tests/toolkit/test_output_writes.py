"""Every output write reports a full or read-only target in one line naming it, exit status 1, nothing half-written
left (issue 38): the one writer (:mod:`toolkit.files`: ``write_output``, ``writing``, ``writing_folder``), standard
output (:class:`likeme.cli.common.StandardOutput`), and the pipe items of issue 37.

A full disk is a file size limit of 0 bytes (``RLIMIT_FSIZE``: every write to a file fails, ``File too large``, as
on a full disk) or ``/dev/full``; a read-only folder is a folder of mode 0o555 (as root, a read-only file system mounted
there)."""

from __future__ import annotations

import errno
import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from tests.likeme.test_errors import BVH
from toolkit.errors import ConfigError
from toolkit.files import write_output, writing, writing_folder

ROOT = Path(__file__).resolve().parents[2]
ENV = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "LIKEME_DISABLE_PLUGIN_AUTOLOAD": "1"}


def _full_disk() -> None:
    """In the child: every write to a file fails (``EFBIG``; the signal that would kill the process ignored)."""
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))


def likeme(args, cwd, *, preexec=None, stdout=subprocess.DEVNULL, env=None):
    return subprocess.run([sys.executable, "-m", "likeme", *map(str, args)], cwd=cwd, preexec_fn=preexec,
                          stdout=stdout, stderr=subprocess.PIPE, text=True, env=env or ENV, timeout=600)


def _one_line(result, *fragments):
    lines = result.stderr.splitlines()
    assert result.returncode == 1 and len(lines) == 1 and lines[0].startswith("likeme: error: "), result.stderr
    for fragment in fragments:
        assert fragment in lines[0], result.stderr


def _files(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if not p.is_dir())


# -- the one writer ------------------------------------------------------------------------------------------------


def test_a_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path, monkeypatch):
    target = tmp_path / "r.json"
    target.write_text("old\n")
    real = os.write

    def full(fd, data):
        real(fd, bytes(data[:3]))
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "write", full)
    with pytest.raises(ConfigError) as err:
        write_output(target, "new content\n")
    assert str(err.value) == (f"{target}: cannot write the output (No space left on device); expected a writable "
                              "folder on a file system with room for it")
    monkeypatch.undo()
    assert target.read_text() == "old\n" and _files(tmp_path) == ["r.json"]
    assert write_output(target, "new\n") == target and target.read_text() == "new\n" and _files(tmp_path) == ["r.json"]


def test_writing_keeps_the_suffix_for_the_library_and_renames_whole(tmp_path):
    with writing(tmp_path / "sub" / "p.png", "picture") as tmp:
        assert tmp.suffix == ".png" and tmp.parent == tmp_path / "sub" and tmp.name.startswith(".p.png.")
        tmp.write_bytes(b"png")
    assert _files(tmp_path) == ["sub/p.png"]
    with pytest.raises(ConfigError, match=r"p\.png: cannot write the picture \(Read-only file system\)"):
        with writing(tmp_path / "sub" / "p.png", "picture") as tmp:
            tmp.write_bytes(b"half")
            raise OSError(errno.EROFS, os.strerror(errno.EROFS))
    assert _files(tmp_path) == ["sub/p.png"] and (tmp_path / "sub" / "p.png").read_bytes() == b"png"


def test_a_folder_of_files_appears_whole_or_not_at_all(tmp_path):
    out = tmp_path / "render"
    with pytest.raises(ConfigError, match="render: cannot write the render"):
        with writing_folder(out, "render") as stage:
            (stage / "frame_00000.png").write_bytes(b"1")
            (stage / "movie").mkdir()
            (stage / "movie" / "a.gif").write_bytes(b"2")
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert _files(tmp_path) == [] and os.listdir(out) == []
    clip = tmp_path / "clip.bvh"
    clip.write_text("x")
    clip.chmod(0o400)
    with writing_folder(out, "render") as stage:
        (stage / "frame_00000.png").write_bytes(b"1")
        (stage / "movie").mkdir()
        (stage / "movie" / "a.gif").write_bytes(b"2")
        (stage / "link.bvh").symlink_to(clip)
    assert _files(out) == ["frame_00000.png", "link.bvh", "movie/a.gif"]
    assert (out / "link.bvh").is_symlink() and (clip.stat().st_mode & 0o777) == 0o400  # the link's target untouched
    assert [p.name for p in out.iterdir() if p.name.startswith(".")] == []


def test_a_writer_that_fails_in_its_finaliser_is_the_error_not_a_message(tmp_path, capsys):
    class Writer:  # a library's GIF writer that flushes on a full disk when it is collected
        def __del__(self):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    with pytest.raises(ConfigError, match=r"cannot write the render \(No space left on device\)"):
        with writing_folder(tmp_path / "r", "render") as stage:
            (stage / "a.gif").write_bytes(b"GIF8")
            writer = Writer()
            writer.cycle = writer  # only the garbage collector frees it
            del writer
    assert capsys.readouterr().err == "" and _files(tmp_path) == []


# -- full and read-only targets, every command that writes ---------------------------------------------------------

WRITERS = [
    ("profile --out", ["profile", "m.bvh", "--out", "OUT/p.toml"], "cannot write the work files"),
    ("show --out", ["show", "max", "--view", "body", "--out", "OUT/x.png"], "OUT: cannot write the picture x.png"),
    ("run --render", ["run", "demo", "--duration", "0.2", "--render", "OUT/r", "--set", 'formats=["png", "gif"]'],
     "OUT/r: cannot write the render"),
    ("bench make-data", ["bench", "make-data", "OUT/gen"], "OUT/gen: cannot write the benchmark data"),
    ("bench make-gestures", ["bench", "make-gestures", "OUT/ges", "--performers", "1", "--takes", "1"],
     "OUT/ges: cannot write the benchmark data"),
    ("bench posegraph --json", ["bench", "posegraph", "--nodes", "1000", "--json", "OUT/p.json"],
     "OUT/p.json: cannot write the output"),
    ("bench fuzz --out", ["bench", "fuzz", "--n", "1", "--out", "OUT/f"], "cannot write the work files"),
]


@pytest.mark.parametrize("what, args, fragment", WRITERS, ids=[w[0] for w in WRITERS])
def test_a_full_disk_is_one_line_naming_the_target_and_nothing_is_left(tmp_path, what, args, fragment):
    (tmp_path / "m.bvh").write_text(BVH)
    (tmp_path / "OUT").mkdir()
    result = likeme(args, tmp_path, preexec=_full_disk)
    if fragment == "cannot write the work files":  # a work folder is written first (and fails first): it is named
        _one_line(result, fragment, "expected a writable temporary folder")
    else:
        _one_line(result, fragment, "(File too large)", "expected a writable folder on a file system with room")
    assert _files(tmp_path / "OUT") == []


@pytest.fixture
def read_only(tmp_path):
    """A read-only folder: mode 0o555 for a user other than root; for root (whom modes do not stop) a read-only
    file system mounted there (``EROFS``), or the test is skipped where mounting is not allowed."""
    folder = tmp_path / "ro"
    folder.mkdir()
    (tmp_path / "m.bvh").write_text(BVH)
    if os.geteuid() != 0:
        folder.chmod(0o555)
        yield folder
        folder.chmod(0o755)
        return
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "ro,size=64k", "tmpfs", str(folder)],
                             capture_output=True, text=True)
    if mounted.returncode != 0:
        pytest.skip(f"root cannot be refused by a folder's mode, and mounting a read-only one failed: "
                    f"{mounted.stderr.strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)


def test_a_read_only_folder_is_one_line_naming_it(read_only):
    reason = "Permission denied" if os.geteuid() != 0 else "Read-only file system"
    result = likeme(["show", "max", "--view", "body"], read_only)  # the picture goes here: it cannot
    _one_line(result, ".: cannot write the picture max-body.png", reason)
    result = likeme(["profile", "../m.bvh", "--out", "p.toml"], read_only)
    _one_line(result, "p.toml", reason)
    result = likeme(["run", "demo", "--duration", "0.2", "--render", "r"], read_only)
    _one_line(result, "r", reason)
    assert os.listdir(read_only) == []


# -- standard output -------------------------------------------------------------------------------------------------


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
@pytest.mark.parametrize("args", [["plugins"], ["--version"], ["--help"], ["validate", ROOT / "characters/max.toml"]])
def test_standard_output_on_a_full_device_is_one_line(tmp_path, args):
    with open("/dev/full", "w") as full:
        result = likeme(args, tmp_path, stdout=full)
    _one_line(result, "standard output: cannot write the output (No space left on device)")


def test_a_closed_standard_output_is_one_line_when_something_is_written(tmp_path):
    result = likeme(["plugins"], tmp_path, preexec=lambda: os.close(1))
    _one_line(result, "standard output: cannot write the output (closed)")
    (tmp_path / "m.bvh").write_text(BVH)
    result = likeme(["profile", "m.bvh", "--out", "p.toml"], tmp_path, preexec=lambda: os.close(1))
    assert result.returncode == 0 and (tmp_path / "p.toml").is_file(), result.stderr


def test_a_reader_that_goes_away_leaves_the_files_written(tmp_path):
    """Issue 37: ``likeme bench posegraph ... --json F | head -n 1`` still writes F (the table is printed first)."""
    proc = subprocess.Popen([sys.executable, "-m", "likeme", "bench", "posegraph", "--nodes", "300", "--nodes", "600",
                             "--nodes", "900", "--no-scan", "--json", "p.json"], cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, env=ENV)
    proc.stdout.readline()
    proc.stdout.close()  # head -n 1 is done
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=600) == 0 and err == ""
    assert (tmp_path / "p.json").read_text().endswith("]\n")


def test_profile_writes_a_final_newline_and_bench_no_blank_line(tmp_path):
    (tmp_path / "m.bvh").write_text(BVH)
    result = likeme(["profile", "m.bvh", "--out", "p.toml"], tmp_path)
    assert result.returncode == 0 and (tmp_path / "p.toml").read_text().endswith("\n")
    result = likeme(["bench", "watch", "--movements", "1", "--json", "w.json"], tmp_path)
    assert result.returncode == 0 and result.stderr == "", result.stderr
