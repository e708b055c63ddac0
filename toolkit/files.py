"""Checks for the files a user names: only regular files of a bounded size are read.

A device (``/dev/zero``), a FIFO, a socket or a directory given where a file is expected would be read forever, block
until a writer appears, or fail with an unclear message; a huge file would fill memory. Every reader calls
:func:`check_regular_file` before it opens a file, and :func:`open_regular` opens one without blocking on a FIFO that
appeared in the meantime.

The size caps (``docs/conventions.md``) have defaults a user can raise with environment variables:

- motion files (BVH): ``LIKEME_MAX_MOTION_MB``, default 4096 (a 60-minute 120 fps capture of 60 joints with six
  channels each is about 2 GB of text);
- configuration files (TOML: characters, profiles, scenarios): ``LIKEME_MAX_CONFIG_MB``, default 16;
- state files (JSON written by ``--save``: what characters learned): ``LIKEME_MAX_STATE_MB``, default 64.

Every file likeme writes goes through one writer: :func:`atomic_path` gives a temporary file beside the target
(``.NAME.XXXXXX.tmp.SUFFIX``, the suffix kept for the libraries that choose a format by it), and renames it onto the
target once it is written and flushed to disk, so that a reader sees the old file or the new one, never a part; the
temporary file is removed whatever fails. :func:`writing`, :func:`write_output` and :func:`writing_folder` (a folder
of renders staged the same way) turn a failure to write (a full disk, a read-only or missing folder, a quota, no
permission) into one :class:`~toolkit.errors.ConfigError` naming the target.
"""

from __future__ import annotations

import contextlib
import io
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any, BinaryIO

from toolkit.errors import ConfigError

__all__ = ["check_regular_file", "open_regular", "probe_writable", "max_bytes", "LIMITS", "atomic_path", "writing",
           "write_output", "writing_folder", "write_error", "replace_atomically",
           "scratch_folder"]

LIMITS: dict[str, tuple[str, int]] = {"motion": ("LIKEME_MAX_MOTION_MB", 4096), "config": ("LIKEME_MAX_CONFIG_MB", 16),
                                      "state": ("LIKEME_MAX_STATE_MB", 64)}
"""The size cap of each kind of file: (environment variable in MB, default MB)."""


def max_bytes(kind: str = "config") -> int:
    """The size cap in bytes of a kind of file (a key of :data:`LIMITS`), from its environment variable."""
    variable, default = LIMITS[kind]
    raw = os.environ.get(variable, "")
    if not raw.strip():
        return default * 2**20
    try:
        mb = float(raw)
    except ValueError:
        mb = float("nan")
    if not (mb > 0 and mb < 2**43):  # NaN, inf, zero, negative
        raise ConfigError(f"invalid size cap {raw!r}", key=(variable,), expected="a positive number of megabytes")
    return int(mb * 2**20)


def _kind_of(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def _check_stat(st: os.stat_result, path: Path, what: str, kind: str) -> None:
    if not stat.S_ISREG(st.st_mode):
        raise ConfigError(f"is {_kind_of(st.st_mode)}, not a file", file=path, expected=f"a regular file ({what})")
    limit = max_bytes(kind)
    if st.st_size > limit:
        variable = LIMITS[kind][0]
        raise ConfigError(f"{what} of {st.st_size:,} bytes is larger than the cap of {limit:,} bytes", file=path,
                          expected="a smaller file, or a higher cap in megabytes in the environment variable "
                                   f"{variable}")


def check_regular_file(path: str | Path, what: str = "file", kind: str = "config") -> Path:
    """Refuse anything but an existing regular file within the size cap of ``kind``; return the path.

    Parameters
    ----------
    path : str or Path
    what : str
        What the file should be, for the message ("BVH file", "body profile").
    kind : {"config", "motion", "state"}
        Which size cap applies (:data:`LIMITS`).

    Raises
    ------
    ConfigError
        Naming the file: missing, unreadable, a directory, FIFO, device or socket, or larger than the cap.
    """
    path = Path(path)
    try:
        st = os.stat(path)
    except OSError as exc:
        raise ConfigError(f"cannot read ({exc.strerror or exc})", file=path, expected=f"a readable {what}") from None
    _check_stat(st, path, what, kind)
    return path


def open_regular(path: str | Path, what: str = "file", kind: str = "config") -> BinaryIO:
    """Open a file for reading in binary after :func:`check_regular_file`'s checks, made on the open file.

    The file is opened without blocking (a FIFO put in its place after a check would otherwise wait for a writer)
    and checked with ``fstat``, so what is read is what was checked.
    """
    path = check_regular_file(path, what, kind)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        raise ConfigError(f"cannot read ({exc.strerror or exc})", file=path, expected=f"a readable {what}") from None
    try:
        _check_stat(os.fstat(fd), path, what, kind)
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        raw = _CheckedFile(fd, path, what)
    except BaseException:
        os.close(fd)
        raise
    return io.BufferedReader(raw)


class _CheckedFile(io.FileIO):
    """A file opened for reading whose read errors (``EIO`` from ``/proc/self/mem`` behind a link, a failing disk)
    are a :class:`ConfigError` naming it, as an unreadable file is when it is opened: whichever reader reads it (BVH,
    CSV, C3D, TOML, state), the message is the same one line."""

    def __init__(self, fd: int, path: Path, what: str) -> None:
        super().__init__(fd, "rb", closefd=True)
        self._path, self._what = path, what

    def _failed(self, exc: OSError) -> ConfigError:
        return ConfigError(f"cannot read ({exc.strerror or exc})", file=self._path, expected=f"a readable {self._what}")

    def read(self, size: int = -1) -> bytes:
        try:
            return super().read(size)
        except OSError as exc:
            raise self._failed(exc) from None

    def readall(self) -> bytes:
        try:
            return super().readall()
        except OSError as exc:
            raise self._failed(exc) from None

    def readinto(self, buffer: Any) -> int:
        try:
            return super().readinto(buffer)
        except OSError as exc:
            raise self._failed(exc) from None


def probe_writable(folder: str | Path, prefix: str = ".likeme-probe-") -> None:
    """Create and remove a temporary file named ``PREFIX*.tmp`` in ``folder``: the only sure test that this process
    can write there (permissions, read-only mounts, quotas). Raises the :class:`OSError` for the caller to word."""
    import tempfile

    fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=folder)
    os.close(fd)
    Path(tmp).unlink(missing_ok=True)  # (a saving process may have swept it away already)


# -- writing -----------------------------------------------------------------------------------


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_folder(folder: Path) -> None:
    """Make a rename in ``folder`` durable (best effort: some file systems refuse to open a folder)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError:
        pass


@contextlib.contextmanager
def _temporary(path: Path, keep_suffix: bool) -> Iterator[tuple[int, Path]]:
    """The open descriptor and name of a new temporary file beside ``path``, renamed onto it after the block."""
    folder = path.parent if str(path.parent) else Path(".")
    try:
        mode = stat.S_IMODE(os.stat(path).st_mode)
    except OSError:
        mode = 0o666 & ~_umask()
    # mkstemp opens with O_CREAT | O_EXCL | O_NOFOLLOW: always a new file, never one a link points to
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + (path.suffix if keep_suffix else ""),
                                dir=folder)
    tmp = Path(name)
    try:
        try:
            yield fd, tmp
            os.fchmod(fd, mode)
            os.fsync(fd)  # the file's data, whichever descriptor wrote it
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync_folder(folder)


@contextlib.contextmanager
def atomic_path(path: str | Path, *, keep_suffix: bool = False) -> Iterator[Path]:
    """A temporary path beside ``path`` to write to; renamed onto ``path`` when the block ends without an error.

    The temporary file is created new (``O_EXCL``, never following a link), named ``.NAME.XXXXXX.tmp`` (with
    ``keep_suffix``, ``.NAME.XXXXXX.tmp.SUFFIX``: for a library that chooses the format by the suffix); after the
    block it is flushed to disk, given the target's permission bits (an existing file's, else ``0o666`` under the
    umask) and renamed onto ``path``. Whatever fails, the temporary file is removed and the error (an
    :class:`OSError` for a full disk, a read-only folder...) raised as it was: the target keeps its old content.
    """
    with _temporary(Path(path), keep_suffix) as (_, tmp):
        yield tmp


def replace_atomically(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through :func:`atomic_path`'s temporary file, written through the descriptor that
    created it (nothing reopened by name); an :class:`OSError` as it was, the target unchanged."""
    with _temporary(Path(path), False) as (fd, _):
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]


def write_error(exc: OSError, target: str | Path, what: str = "output",
                expected: str = "a writable folder on a file system with room for it") -> ConfigError:
    """The one-line error of a failed write to ``target``: the reason (``No space left on device``, ``Read-only file
    system``, ``Permission denied``...) and what would do."""
    reason = exc.strerror or type(exc).__name__
    return ConfigError(f"cannot write the {what} ({reason})", file=target, expected=expected)


@contextlib.contextmanager
def writing(path: str | Path, what: str = "output") -> Iterator[Path]:
    """:func:`atomic_path` (keeping the suffix; the folder created if missing) whose failure to write is one
    :class:`ConfigError` naming ``path`` (see :func:`write_error`): for libraries that write a file themselves
    (``fig.savefig(tmp)``, ``np.save(tmp, ...)``)."""
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(path, keep_suffix=True) as tmp:
            yield tmp
    except OSError as exc:
        raise write_error(exc, path, what) from None


def write_output(path: str | Path, data: str | bytes, what: str = "output") -> Path:
    """Write ``data`` (text as UTF-8, or bytes) to ``path`` atomically; a failure is one :class:`ConfigError` naming
    it. Returns the path."""
    try:
        replace_atomically(path, data.encode("utf-8") if isinstance(data, str) else data)
    except OSError as exc:
        raise write_error(exc, path, what) from None
    return Path(path)


@contextlib.contextmanager
def scratch_folder(prefix: str = "likeme-") -> Iterator[Path]:
    """A temporary folder for work files (:class:`tempfile.TemporaryDirectory`, removed after the block); that none
    can be made (the temporary folder full or read-only) is one :class:`ConfigError` naming it."""
    try:
        scratch = tempfile.TemporaryDirectory(prefix=prefix)
    except OSError as exc:
        where = os.environ.get("TMPDIR") or "/tmp"
        raise write_error(exc, where, "work files",
                          expected="a writable temporary folder with room (TMPDIR names another)") from None
    with scratch as name:
        yield Path(name)


@contextlib.contextmanager
def writing_folder(folder: str | Path, what: str = "output") -> Iterator[Path]:
    """A staging folder inside ``folder`` (created if missing) to write a set of files to; when the block ends
    without an error each file is flushed to disk and renamed into ``folder`` at the same relative place (an existing
    file of that name replaced). Whatever fails, the staging folder and everything in it is removed, and a failure to
    write is one :class:`ConfigError` naming the folder: no half-written frame, GIF or movie is left behind.

    A library's writer that fails in its finaliser (a GIF writer closed by the garbage collector on a full disk) is
    such a failure too, not a message on standard error: while the block runs, the :class:`OSError` a finaliser
    raises is kept (:data:`sys.unraisablehook`) and raised at its end.
    """
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        stage = Path(tempfile.mkdtemp(prefix=".likeme-", suffix=".tmp", dir=folder))
    except OSError as exc:
        raise write_error(exc, folder, what) from None
    with _finalisers_kept() as lost:
        try:
            yield stage
            _collect()
            if lost:
                raise lost[0]
            files = sorted(Path(top, name) for top, _, names in os.walk(stage) for name in names)
            mode = 0o666 & ~_umask()
            for f in files:
                if f.is_symlink():  # a link made on purpose (to a clip): moved as it is, what it points to untouched
                    continue
                fd = os.open(f, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
                try:
                    os.fchmod(fd, mode)
                    os.fsync(fd)
                finally:
                    os.close(fd)
            for f in files:
                target = folder / f.relative_to(stage)
                target.parent.mkdir(parents=True, exist_ok=True)
                os.replace(f, target)
            _fsync_folder(folder)
        except OSError as exc:
            _release(exc)
            raise write_error(exc, folder, what) from None
        finally:
            shutil.rmtree(stage, ignore_errors=True)


@contextlib.contextmanager
def _finalisers_kept() -> Iterator[list[OSError]]:
    """The :class:`OSError` s finalisers raise while the block runs, kept in the list yielded instead of printed."""
    import sys

    lost: list[OSError] = []
    hook = sys.unraisablehook

    def keep(unraisable: Any) -> None:
        if isinstance(unraisable.exc_value, OSError):
            lost.append(unraisable.exc_value)
        else:
            hook(unraisable)

    sys.unraisablehook = keep
    try:
        yield lost
    finally:
        sys.unraisablehook = hook


def _collect() -> None:
    import gc

    gc.collect()


def _release(exc: BaseException | None) -> None:
    """Free, now, what the frames of a failed write still hold (a GIF or movie writer a library left open): the
    failure and those it happened during (their finalisers' errors are kept by :func:`_finalisers_kept`)."""
    import traceback

    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        traceback.clear_frames(exc.__traceback__)
        exc = exc.__context__
    _collect()
