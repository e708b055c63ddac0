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
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import BinaryIO

from toolkit.errors import ConfigError

__all__ = ["check_regular_file", "open_regular", "probe_writable", "max_bytes", "LIMITS"]

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
    except BaseException:
        os.close(fd)
        raise
    return os.fdopen(fd, "rb")


def probe_writable(folder: str | Path, prefix: str = ".likeme-probe-") -> None:
    """Create and remove a temporary file named ``PREFIX*.tmp`` in ``folder``: the only sure test that this process
    can write there (permissions, read-only mounts, quotas). Raises the :class:`OSError` for the caller to word."""
    import tempfile

    fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=folder)
    os.close(fd)
    Path(tmp).unlink(missing_ok=True)  # (a saving process may have swept it away already)
