"""Saving and loading what characters learn: atomic, checksummed, locked against concurrent writers, all or nothing.

A state file is JSON (format version 2)::

    {"format": "likeme-state", "version": 2,
     "checksum": "sha256:5f1c...",
     "frame": 812, "time": 27.07,
     "actors": {"max": {"character": "Max",
                        "components": {"motor": {"plugin": "posegraph", "state": {...}},
                                       "action": {"plugin": "hierarchical", "state": {...}}}}}}

Each component contributes its own :meth:`~toolkit.components.Component.get_state` (learned movements of a
posegraph; drives, beliefs, correspondence and transition maps of an action system...). ``checksum`` is the
SHA-256 of the canonical JSON of everything else in the file (:func:`canonical`: keys sorted, no spaces, UTF-8), so
any change made after likeme wrote the file, valid JSON or not, is detected.

**Loading** (:func:`read_state`, :func:`load_state`) happens in three steps, and nothing changes before the last:

1. the file (at most :data:`MAX_BYTES`) is parsed and checked against the schema: the header, the types of every
   field of every actor and component, nesting at most :data:`MAX_DEPTH` deep, integers within
   :data:`MAX_INT`, finite numbers only (``NaN``, ``Infinity`` and ``1e999`` are refused), strings of at most
   :data:`MAX_STRING` characters; then the checksum;
2. every actor's character must be the one it was saved from (its name) and every component the plugin its state
   was saved by; every component checks its state with ``set_state(state, check=True)``, which changes nothing;
3. only then every component's ``set_state(state)``. A component whose ``set_state`` takes no ``check`` keyword (a
   third-party plugin written before it existed) is applied first, with a snapshot of its ``get_state()`` taken
   before, and restored from the snapshot if a later one fails.

A version-1 file (written before the checksum) is read with the same checks but no checksum; it becomes a
version-2 file at its next save. A version-2 file without a checksum is refused.

**Saving** writes to a temporary file ``.NAME.*.tmp`` in the same folder, flushed and synced, then renamed over
``NAME`` in one step, so a run killed at any moment leaves the previous state or the new one, never half a file;
the temporary file is removed on every failure. The file keeps its permissions when overwritten; a new file gets
the default mode under the umask (0644 under umask 022).

**Concurrent writers** (:class:`StateFile`): every save takes an advisory lock (``fcntl.flock`` on ``.NAME.lock``
beside the file, held only while saving) and, under it, compares the file with the version this process last saw
(its SHA-256 when the run started, or as this process last wrote it). If another process wrote the file since, it
is not overwritten: this run's state goes to ``NAME.conflict-PID.json`` beside it (and every later save of the
run too), a warning says so, and the run ends with an error naming both files, so neither run's learning is lost.
A run's ``--save`` target is checked before the run starts (:func:`check_save_target`); a run that will replace a
state file it did not ``--load`` says so at the start.

:class:`Checkpoint` is a plugin that saves after every step in which something was learned. A save that fails
(a full disk) is reported once, keeps what was learned in memory and is tried again; the final save's failure is
a :class:`~toolkit.errors.ConfigError` naming the file and the reason.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import glob
import hashlib
import inspect
import json
import math
import os
import re
import stat
import sys
import tempfile
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

from toolkit.character import Character
from toolkit.errors import ConfigError, PluginError
from toolkit.files import LIMITS, max_bytes, open_regular, probe_writable, replace_atomically
from toolkit.hookspecs import hookimpl

__all__ = ["FORMAT", "VERSION", "READS", "MAX_BYTES", "MAX_DEPTH", "MAX_INT", "MAX_STRING", "write_atomic",
           "canonical", "checksum", "character_state", "world_state", "state_text", "save_state", "read_state",
           "check_state_data", "apply_state", "load_state", "check_save_target", "lock_path", "StateFile",
           "Checkpoint"]

FORMAT = "likeme-state"
VERSION = 2
READS = (1, 2)  #: the format versions this likeme reads
MAX_BYTES = LIMITS["state"][1] * 2**20  #: the largest state file read by default (LIKEME_MAX_STATE_MB raises it)
MAX_DEPTH = 32  #: how deeply objects and lists may nest, from the top of the file
MAX_INT = 2**53  #: the largest magnitude of an integer (counts, frames)
MAX_STRING = 4096  #: the longest string (names, sources)


# -- writing -----------------------------------------------------------------------------------


def write_atomic(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` so that readers see the old or the new content, never a part
    (:func:`toolkit.files.replace_atomically`, the one writer).

    The temporary file ``.NAME.*.tmp`` is removed whatever fails; an existing file keeps its permission bits, a
    new one gets ``0o666`` under the umask (not :func:`tempfile.mkstemp`'s ``0o600``). An :class:`OSError` is raised
    as it was (a save reports it and tries again).
    """
    replace_atomically(path, text.encode("utf-8"))


def canonical(data: Any) -> bytes:
    """The canonical JSON of ``data`` the checksum is taken of: keys sorted, no spaces, UTF-8, finite numbers."""
    return json.dumps(data, sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False).encode("utf-8")


def checksum(data: Mapping[str, Any]) -> str:
    """``"sha256:<hex>"`` of the canonical JSON of a state file's data without its ``checksum`` key."""
    return "sha256:" + hashlib.sha256(canonical({k: v for k, v in data.items() if k != "checksum"})).hexdigest()


def character_state(character: Character) -> dict[str, Any]:
    """The learned state of one character, by component table."""
    components = {}
    for key, component in character.components().items():
        state = component.get_state()
        if state:
            components[key] = {"plugin": component.name, "state": state}
    return {"character": character.name, "components": components}


def world_state(world: Any) -> dict[str, Any]:
    """The learned state of every actor of a world, with the format header."""
    return {
        "format": FORMAT,
        "version": VERSION,
        "frame": world.frame,
        "time": world.time,
        "actors": {actor_id: character_state(actor.character) for actor_id, actor in world.actors.items()},
    }


def state_text(target: Any) -> str:
    """The text of a state file of a world (every actor) or of one character, with its checksum."""
    if isinstance(target, Character):
        data = {"format": FORMAT, "version": VERSION, "actors": {target.name.lower(): character_state(target)}}
    else:
        data = world_state(target)
    try:
        data["checksum"] = checksum(data)
    except ValueError:  # NaN, infinity or a lone surrogate: a file no likeme could load again
        characters = [target] if isinstance(target, Character) else [a.character for a in target.actors.values()]
        for character in characters:
            for component in character.components().values():
                try:
                    canonical(component.get_state())
                except UnicodeEncodeError as exc:
                    raise PluginError(component.name, "get_state", f"returned a string holding the lone surrogate "
                                      f"{ascii(exc.object[exc.start])[1:-1]}, which is not Unicode text") from None
                except ValueError:
                    raise PluginError(component.name, "get_state", "returned a number that is not finite") from None
        raise
    return json.dumps(data, indent=1, sort_keys=True, allow_nan=False) + "\n"


def lock_path(path: str | Path) -> Path:
    """The advisory lock file of state file ``path``: ``.NAME.lock`` beside it."""
    path = Path(path)
    return path.with_name(f".{path.name}.lock")


def _open_lock(lock: Path) -> int:
    """Open (create) a lock file without following a symbolic link (``O_NOFOLLOW``): a link planted under the
    lock's name would otherwise make every save create or open the file it points to. Anything but a regular file
    is refused too. Raises :class:`OSError` naming the lock."""
    flags = os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(lock, flags, 0o666)
    except OSError as exc:
        if exc.errno == errno.ELOOP or os.path.islink(lock):
            raise OSError(errno.ELOOP, f"the lock file {lock} is a symbolic link; not following it", str(lock)) from None
        raise
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise OSError(errno.EINVAL, f"the lock file {lock} is not a regular file", str(lock))
    os.set_blocking(fd, True)
    return fd


@contextlib.contextmanager
def _locked(path: Path) -> Iterator[None]:
    """Hold the advisory lock of state file ``path`` (``fcntl.flock`` on ``.NAME.lock`` beside it)."""
    lock = lock_path(path)
    fd = _open_lock(lock)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # releases the lock


def _digest(path: Path) -> str | None:
    """SHA-256 of a file's bytes (None if it does not exist): the version a writer compares against."""
    try:
        with open(path, "rb") as handle:
            return hashlib.file_digest(handle, "sha256").hexdigest()
    except FileNotFoundError:
        return None


def _sweep(path: Path) -> None:
    """Remove the temporary files ``.NAME.*.tmp`` a killed writer left beside ``path`` (call under its lock: no
    likeme process is writing one then)."""
    for stale in path.parent.glob(f".{glob.escape(path.name)}.*.tmp"):
        with contextlib.suppress(OSError):
            stale.unlink()


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc)


def save_state(target: Any, path: str | Path) -> None:
    """Save a world's (every actor's) or one character's learned state to ``path`` atomically, under its lock.

    No version check (a plain "save here"); :class:`StateFile` adds it for runs.
    """
    path = Path(path)
    text = state_text(target)
    with _locked(path):
        write_atomic(path, text)


# -- checking a --save target --------------------------------------------------------------------


def _probe_folder(folder: Path, name: str, path: Path) -> None:
    try:
        probe_writable(folder, prefix=f".{name}.")  # named as the saves' own temporary files, which a save sweeps
    except OSError as exc:
        raise ConfigError(f"cannot write in the folder {folder}: {_reason(exc)}", file=path,
                          expected="--save into a folder this user can write") from None


NAME_MARGIN = 32
"""How many bytes a save adds to a state file's name at most: ``.NAME.lock``, ``.NAME.XXXXXXXX.tmp`` and the
temporary file of ``NAME.conflict-PID.json`` (:class:`StateFile`)."""


def _check_name_length(path: Path, folder: Path) -> None:
    """A name the file system takes with every suffix a save adds (``NAME_MAX`` less :data:`NAME_MARGIN` bytes)."""
    try:
        name_max = os.pathconf(folder if folder.is_dir() else ".", "PC_NAME_MAX")
    except (OSError, ValueError):
        name_max = 255
    size = len(os.fsencode(path.name))
    if size + NAME_MARGIN > name_max:
        raise ConfigError(f"a file name of {size} bytes is too long", file=path,
                          expected=f"a name of at most {name_max - NAME_MARGIN} bytes (this file system's "
                                   f"{name_max} less {NAME_MARGIN} for the lock and temporary files beside it)")


def check_save_target(path: str | Path) -> Path:
    """Check that state can be saved to ``path`` before a run starts; :class:`ConfigError` if not.

    Refused: an empty name, a name too long for the lock and temporary files beside it, a loop of symbolic links,
    a lock file that is a symbolic link (a save does not follow it), a folder that does not exist or is a file, a directory as the file, something that is
    not a regular file, a read-only file (no write permission bit, whoever runs), a file that is not a likeme
    state file (it would be overwritten), a folder this user cannot create a file in (probed by creating and
    removing a temporary file). Returns the path to write (a symbolic link's target).
    """
    if not str(path):
        raise ConfigError("an empty file name", key=("--save",), expected="--save FILE (a state file to write)")
    path = Path(path)
    if path.name in ("", ".", ".."):
        raise ConfigError("not a file name", file=path, expected="--save FILE (a state file to write)")
    try:
        return _check_save_target(path)
    except OSError as exc:  # a name too long for the file system, a folder that vanished, ...
        raise ConfigError(f"cannot save here: {_reason(exc)}", file=path,
                          expected="--save FILE (a state file to write)") from None


def _check_save_target(path: Path) -> Path:
    _check_name_length(path, path.parent if str(path.parent) else Path("."))
    if path.is_symlink():
        try:
            path = path.resolve(strict=True)
        except FileNotFoundError:  # a link to a file not written yet: the save creates it
            path = path.resolve()
        except (OSError, RuntimeError):  # RuntimeError: Python before 3.13 on a loop
            raise ConfigError("a loop of symbolic links", file=path,
                              expected="--save FILE (a state file to write, or a link to one)") from None
    folder = path.parent if str(path.parent) else Path(".")
    _check_name_length(path, folder)
    ancestor = folder
    while True:  # the nearest ancestor that exists says why the folder cannot be used
        try:
            info = ancestor.stat()
            break
        except FileNotFoundError:
            if ancestor == ancestor.parent:
                break
            ancestor = ancestor.parent
        except NotADirectoryError:
            ancestor = ancestor.parent
        except OSError as exc:
            raise ConfigError(f"cannot reach the folder {ancestor}: {_reason(exc)}", file=path,
                              expected="--save into a folder this user can write") from None
    if ancestor.exists() and not stat.S_ISDIR(info.st_mode):
        raise ConfigError(f"{ancestor} is a file, not a folder", file=path, expected="--save into an existing folder")
    if ancestor != folder:
        raise ConfigError(f"the folder {folder} does not exist", file=path, expected="--save into an existing folder")
    if path.is_dir():
        raise ConfigError("is a folder, not a file", file=path, expected="--save FILE (a state file to write)")
    if path.exists():
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):
            raise ConfigError("is not a regular file", file=path, expected="--save FILE (a state file to write)")
        if not info.st_mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH) or not os.access(path, os.W_OK):
            raise ConfigError("the file is read-only", file=path,
                              expected="a state file this user may overwrite (chmod u+w), or another file name")
        if info.st_size:
            try:
                with open(path, "rb") as handle:
                    head = json.loads(handle.read(max_bytes("state") + 1)) if info.st_size <= max_bytes("state") else None
            except (OSError, ValueError, RecursionError):
                head = None
            if not isinstance(head, dict) or head.get("format") != FORMAT:
                raise ConfigError("exists and is not a likeme state file; refusing to overwrite it", file=path,
                                  expected="a state file written by --save, or a new file name")
    lock = lock_path(path)
    try:
        lock_mode = os.lstat(lock).st_mode
    except FileNotFoundError:
        lock_mode = None
    if lock_mode is not None and not stat.S_ISREG(lock_mode):
        what = "a symbolic link, which a save does not follow" if stat.S_ISLNK(lock_mode) else "not a regular file"
        raise ConfigError(f"its lock file {lock} is {what}", file=path,
                          expected="no file of that name, or the lock file a save made (remove it)")
    _probe_folder(folder, path.name, path)
    return path


class StateFile:
    """A state file a run saves to: checked before the run, written under its lock with a version check.

    Parameters
    ----------
    path : path
        The ``--save`` target; :func:`check_save_target` is called on it.
    loaded : path, optional
        The state file the run loaded (``--load``). If the target holds a state and is not that file, ``report``
        is told at once that the run will replace it (a run that means to add to a state loads it first).
    report : callable, optional
        Told (one line) when a save goes to a conflict file instead; default: a warning on standard error.
    """

    def __init__(self, path: str | Path, *, loaded: str | Path | None = None,
                 report: Callable[[str], None] | None = None) -> None:
        self.path = check_save_target(path)
        self.known = _digest(self.path)  # the version this process has seen: overwriting it loses nothing
        self.diverted: Path | None = None
        self.report = report or _warn
        if self.path.is_file() and self.path.stat().st_size:
            try:
                same = loaded is not None and os.path.samefile(loaded, self.path)
            except OSError:
                same = False
            if not same:
                self.report(f"{self.path} holds a saved state this run did not load (--load {self.path} adds to it); "
                            f"what this run learns will replace it")

    @property
    def conflict_path(self) -> Path:
        """Where this process's state goes if another process wrote :attr:`path` (``NAME.conflict-PID.json``)."""
        return self.path.with_name(f"{self.path.stem}.conflict-{os.getpid()}{self.path.suffix or '.json'}")

    def save(self, text: str) -> Path:
        """Write ``text``; returns where it went (:attr:`path`, or the conflict file). Raises :class:`OSError`."""
        with _locked(self.path):
            _sweep(self.path)
            if self.diverted is None:
                current = _digest(self.path)
                if current is not None and current != self.known:
                    self.diverted = self.conflict_path
                    self.report(f"{self.path}: another process wrote this state file since this run "
                                f"{'started' if self.known is None else 'read or last saved it'}; not overwriting "
                                f"it: this run's state is saved to {self.diverted} instead")
            if self.diverted is not None:
                write_atomic(self.diverted, text)
                return self.diverted
            write_atomic(self.path, text)
            self.known = hashlib.sha256(text.encode("utf-8")).hexdigest()
            return self.path

    def conflict_error(self) -> ConfigError:
        """The error a run ends with when its state had to go to the conflict file."""
        return ConfigError(f"another process wrote this state file during the run; it was not overwritten: what this "
                           f"run learned is saved in {self.diverted}", file=self.path,
                           expected="one run saving to a state file at a time (merge by loading one and running again)")


def _warn(message: str) -> None:
    print(f"likeme: warning: {message}", file=sys.stderr)


# -- reading -----------------------------------------------------------------------------------------


def _read_bytes(path: str | Path) -> bytes:
    """The file's bytes: a regular file within the state files' size cap (:func:`toolkit.files.open_regular`)."""
    what = "state file written by --save"
    if not str(path):
        raise ConfigError("an empty file name", key=("--load",), expected=f"--load STATE (a {what})")
    try:
        os.lstat(path)
    except FileNotFoundError:
        raise ConfigError("file not found", file=path, expected=f"an existing {what}") from None
    except OSError as exc:  # a name too long, a folder in the path that is a file, ...
        raise ConfigError(f"cannot read file ({_reason(exc)})", file=path, expected=f"a readable {what}") from None
    try:
        with open_regular(path, what, "state") as handle:
            return handle.read()
    except OSError as exc:
        raise ConfigError(f"cannot read file ({_reason(exc)})", file=path, expected=f"a readable {what}") from None


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a finite number")


_SURROGATE = re.compile("[\ud800-\udfff]")


def _text(value: str, what: str, key: tuple, path: Path) -> None:
    """A string that is Unicode text: JSON's ``"\\ud800"`` escape decodes to a lone surrogate, which no UTF-8
    file (nor the checksum's canonical JSON) can hold."""
    found = _SURROGATE.search(value)
    if found:
        raise ConfigError(f"a {what} holding the lone surrogate {ascii(found.group())[1:-1]} at character "
                          f"{found.start()}, which is not Unicode text", file=path, key=key,
                          expected="strings of Unicode characters (a surrogate only in a pair)")


def _walk(value: Any, key: tuple, path: Path) -> None:
    """Every value is JSON of bounded depth, size and magnitude (iteratively: no recursion on hostile input).

    Only objects and lists go on the stack, each with its depth and a link to its parent's entry (the key path is
    spelt out only for an error); numbers and strings are checked where they stand. So the walk costs one step per
    value: a state of 20,000 learned movements holds millions of numbers."""
    stack: list[tuple[Any, int, Any]] = [(value, len(key), (None, key))]
    while stack:
        value, depth, link = stack.pop()
        if depth > MAX_DEPTH or (depth == MAX_DEPTH and isinstance(value, (dict, list)) and value):
            raise ConfigError(f"nested more than {MAX_DEPTH} deep below here", file=path, key=_key(link)[:4],
                              expected="a state file written by likeme")
        if isinstance(value, dict):
            for k in value:
                if len(k) > MAX_STRING:
                    raise ConfigError(f"key of {len(k)} characters", file=path, key=_key(link),
                                      expected=f"at most {MAX_STRING} characters")
                if _SURROGATE.search(k):
                    _text(k, "key", _key(link), path)
            items: Any = value.items()
        elif isinstance(value, list):
            items = enumerate(value)
        else:
            _leaf(value, _key(link), path)
            continue
        below = depth + 1
        for k, v in items:
            kind = type(v)
            if kind is float:
                if v - v != 0.0:  # NaN or infinity (json reads 1e999 as infinity)
                    _leaf(v, (*_key(link), k), path)
            elif kind is dict or kind is list:
                stack.append((v, below, (link, k)))
            elif kind is str:
                if len(v) > MAX_STRING or _SURROGATE.search(v):
                    _leaf(v, (*_key(link), k), path)
            else:
                _leaf(v, (*_key(link), k), path)


def _key(link: Any) -> tuple:
    """The key path of a :func:`_walk` stack entry's link ``(parent link, key)``; the root's link holds the whole
    starting key path."""
    parts = []
    while link[0] is not None:
        link, k = link
        parts.append(k)
    return (*link[1], *reversed(parts))


def _leaf(value: Any, key: tuple, path: Path) -> None:
    """A number, string, boolean or null of a state file, within bounds."""
    if isinstance(value, bool) or value is None:
        return
    if isinstance(value, int):
        if abs(value) > MAX_INT:
            raise ConfigError(f"integer too large ({len(str(abs(value)))} digits)", file=path, key=key,
                              expected=f"an integer of magnitude at most 2**{MAX_INT.bit_length() - 1}")
    elif isinstance(value, float):
        if not math.isfinite(value):
            raise ConfigError(f"not a finite number: {value}", file=path, key=key, expected="a finite number")
    elif isinstance(value, str):
        if len(value) > MAX_STRING:
            raise ConfigError(f"string of {len(value)} characters", file=path, key=key,
                              expected=f"at most {MAX_STRING} characters")
        _text(value, "string", key, path)
    elif isinstance(value, (dict, list)):  # pragma: no cover - _walk puts these on its stack
        _walk(value, key, path)
    else:  # pragma: no cover - json.loads makes nothing else
        raise ConfigError(f"unexpected value {type(value).__name__}", file=path, key=key)


def _table(value: Any, path: Path, key: tuple, what: str, keys: tuple[str, ...] | None = None,
           required: tuple[str, ...] = ()) -> dict:
    if not isinstance(value, dict):
        raise ConfigError(f"{type(value).__name__} instead of a table", file=path, key=key, expected=what)
    if keys is not None:
        for k in value:
            if k not in keys:
                raise ConfigError(f"unknown key {k!r}", file=path, key=(*key, k), expected=what, available=keys)
    for k in required:
        if k not in value:
            raise ConfigError(f"missing {k!r}", file=path, key=key, expected=what)
    return value


def check_state_data(data: Any, path: str | Path) -> dict[str, Any]:
    """Check parsed state-file data against the schema and its checksum (see the module docstring); returns it."""
    path = Path(path)
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise ConfigError("not a likeme state file", file=path, key=("format",), expected=f'"format": "{FORMAT}"')
    version = data.get("version")
    if isinstance(version, bool) or version not in READS:
        raise ConfigError(f"unsupported state format version {version!r}", file=path, key=("version",),
                          expected="a version this likeme reads", available=[str(v) for v in READS])
    header = ("format", "version", "frame", "time", "actors") + (("checksum",) if version >= 2 else ())
    _walk(data, (), path)
    _table(data, path, (), "a likeme state file", header, ("actors",))
    frame = data.get("frame", 0)
    if isinstance(frame, bool) or not isinstance(frame, int) or frame < 0:
        raise ConfigError(f"invalid frame {frame!r}", file=path, key=("frame",), expected="a frame number >= 0")
    time = data.get("time", 0.0)
    if isinstance(time, bool) or not isinstance(time, (int, float)) or time < 0:
        raise ConfigError(f"invalid time {time!r}", file=path, key=("time",), expected="seconds >= 0")
    actors = _table(data["actors"], path, ("actors",), "a table of actors")
    for actor_id, entry in actors.items():
        prefix = ("actors", actor_id)
        _table(entry, path, prefix, "{character, components}", ("character", "components"), ("character", "components"))
        if not isinstance(entry["character"], str) or not entry["character"]:
            raise ConfigError("invalid character name", file=path, key=(*prefix, "character"),
                              expected="the name of the character the state was saved from")
        components = _table(entry["components"], path, (*prefix, "components"), "a table of components")
        for table, item in components.items():
            where = (*prefix, "components", table)
            _table(item, path, where, "{plugin, state}", ("plugin", "state"), ("plugin", "state"))
            if not isinstance(item["plugin"], str) or not item["plugin"]:
                raise ConfigError("invalid plugin name", file=path, key=(*where, "plugin"),
                                  expected="the plugin the state was saved by")
            _table(item["state"], path, (*where, "state"), "a component's state (a table)")
    if version >= 2:
        written = data.get("checksum")
        if not isinstance(written, str):
            raise ConfigError("missing checksum", file=path, key=("checksum",),
                              expected='"checksum": "sha256:..." as written by likeme')
        if written != checksum(data):
            raise ConfigError("checksum does not match the content: the file was changed or damaged after likeme "
                              "wrote it", file=path, key=("checksum",), expected="a state file as likeme wrote it")
    return data


def read_state(path: str | Path) -> dict[str, Any]:
    """Read a state file and check it against the schema and its checksum; :class:`ConfigError` for anything else."""
    raw = _read_bytes(path)
    path = Path(path)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"not UTF-8 text (byte {exc.start})", file=path,
                          expected="a JSON state file written by likeme") from None
    try:
        data = json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as exc:
        raise ConfigError(f"not JSON: {exc.msg}", file=path, line=exc.lineno, column=exc.colno,
                          expected="a JSON state file written by likeme") from None
    except RecursionError:
        raise ConfigError("not JSON likeme reads: nested too deeply", file=path,
                          expected=f"at most {MAX_DEPTH} levels of nesting") from None
    except ValueError as exc:  # NaN, Infinity; an integer of more than 4300 digits
        raise ConfigError(f"not JSON likeme reads: {exc}", file=path,
                          expected="finite numbers of sensible size") from None
    return check_state_data(data, path)


# -- applying ------------------------------------------------------------------------------------------


def _takes_check(component: Any) -> bool:
    try:
        return "check" in inspect.signature(component.set_state).parameters
    except (TypeError, ValueError):
        return False


def _call(component: Any, state: dict, path: Path, prefix: tuple, **kwargs: Any) -> None:
    try:
        component.set_state(state, **kwargs)
    except ConfigError as err:
        raise err.within(file=path, prefix=prefix) from None
    except Exception as exc:  # noqa: BLE001 - a set_state that does not check its input itself
        raise ConfigError(f"{component.kind} {component.name!r} cannot use this state ({type(exc).__name__}: {exc})",
                          file=path, key=prefix, expected="a state written by the same plugin") from None


def _pairs(target: Any, actors: Mapping[str, Any], path: Path) -> list[tuple[str, Character]]:
    """(actor id, character) for every saved actor; the characters must be the ones the state was saved from."""
    held = [f"{actor_id} ({entry['character']})" for actor_id, entry in actors.items()]
    if isinstance(target, Character):
        same = [actor_id for actor_id, entry in actors.items() if entry["character"] == target.name]
        if len(same) != 1:
            raise ConfigError(f"no state of {target.name} in the file" if not same else
                              f"{len(same)} actors of character {target.name} in the file", file=path, key=("actors",),
                              expected=f"the state of one character named {target.name}", available=held)
        return [(same[0], target)]
    pairs = []
    for actor_id, entry in actors.items():
        if actor_id not in target.actors:
            raise ConfigError(f"unknown actor {actor_id!r}", file=path, key=("actors", actor_id),
                              expected="an actor of this world", available=list(target.actors))
        character = target.actors[actor_id].character
        if entry["character"] != character.name:
            raise ConfigError(f"state saved from {entry['character']}, but actor {actor_id!r} is {character.name}",
                              file=path, key=("actors", actor_id, "character"),
                              expected=f"a state file saved from {character.name}", available=held)
        pairs.append((actor_id, character))
    return pairs


def apply_state(target: Any, data: Mapping[str, Any], path: str | Path) -> None:
    """Restore checked state-file ``data`` (from :func:`read_state`) into a world or one character, all or nothing.

    Raises :class:`ConfigError`; when it does, every component is as it was.
    """
    path = Path(path)
    plans = []
    for actor_id, character in _pairs(target, data["actors"], path):
        components = character.components()
        for key, item in data["actors"][actor_id]["components"].items():
            prefix = ("actors", actor_id, "components", key)
            component = components.get(key)
            if component is None:
                raise ConfigError(f"{character.name} has no {key} component", file=path, key=prefix,
                                  expected="a component table of the character", available=list(components))
            if item["plugin"] != component.name:
                raise ConfigError(f"state saved for plugin {item['plugin']!r}", file=path, key=(*prefix, "plugin"),
                                  expected=f"state of {component.name!r} (the plugin of {character.name}'s {key})")
            plans.append((component, item["state"], (*prefix, "state")))
    checked = [plan for plan in plans if _takes_check(plan[0])]
    unchecked = [plan for plan in plans if not _takes_check(plan[0])]
    for component, state, prefix in checked:  # nothing changes yet
        _call(component, state, path, prefix, check=True)
    done: list[tuple[Any, dict]] = []
    try:
        for component, state, prefix in unchecked + checked:
            snapshot = component.get_state() if not _takes_check(component) else None
            _call(component, state, path, prefix)
            done.append((component, snapshot))
    except BaseException:
        for component, snapshot in done:
            if snapshot is not None:
                with contextlib.suppress(Exception):
                    component.set_state(snapshot)
        raise


def load_state(target: Any, path: str | Path) -> dict[str, Any]:
    """Restore learned state from ``path`` into a world (actors matched by id) or one character (matched by name).

    Everything is checked before anything changes (see the module docstring); returns the file's data.
    """
    data = read_state(path)
    apply_state(target, data, path)
    return data


# -- checkpoints -----------------------------------------------------------------------------------------


class Checkpoint:
    """A plugin that saves a world's learned state after every step in which something was learned,
    and at least every ``every`` seconds of world time (drives and habits change all the time).

    Register it with ``pm.register(Checkpoint(world, path))``; a run killed in the middle then loses at most what
    was being learned when it died. A save that fails (a full disk, a folder made read-only) is reported once
    through ``report`` and tried again after ``every`` seconds (at least one) of world time; what was learned stays
    in memory. :meth:`finish` makes the last save and raises :class:`ConfigError` if it fails.
    """

    def __init__(self, world: Any, path: str | Path | StateFile, every: float = 5.0,
                 report: Callable[[str], None] | None = None) -> None:
        self.world = world
        self.report = report or _warn
        self.file = path if isinstance(path, StateFile) else StateFile(path, report=self.report)
        self.path = self.file.path
        self.every = every
        self.dirty = False
        self.saves = 0
        self.error: str | None = None  # the last save's failure, while it lasts
        self.reason = ""  # the operating system's reason for it
        self._last = world.frame
        self._retry = world.frame

    @hookimpl
    def likeme_movement_learned(self, character, movement, details):
        self.dirty = True

    @hookimpl
    def likeme_behaviour_identified(self, world, observer, target, behaviour):
        if behaviour.learned:
            self.dirty = True

    @hookimpl
    def likeme_world_stepped(self, world):
        if world is not self.world or (self.error is not None and world.frame < self._retry):
            return
        if self.dirty or (self.every > 0 and world.frame - self._last >= self.every * world.fps):
            self.save()

    def save(self) -> bool:
        """Save now; False (reported once per reason) if it failed: the state stays in memory for the next try."""
        try:
            self.file.save(state_text(self.world))
        except OSError as exc:
            self.reason = _reason(exc)
            error = f"{self.path}: could not save state: {self.reason}"
            if error != self.error:
                self.report(f"{error}; what was learned is kept and saved again at the next checkpoint")
            self.error = error
            self._retry = self.world.frame + max(self.every, 1.0) * self.world.fps
            return False
        if self.error is not None:
            self.report(f"{self.path}: saved after all")
        self.error = None
        self.dirty = False
        self._last = self.world.frame
        self.saves += 1
        return True

    def finish(self) -> None:
        """The last save of a run: :class:`ConfigError` if it fails, or if the state had to go to a conflict file."""
        if not self.save():
            name = f"{self.path.stem}.unsaved-{os.getpid()}{self.path.suffix or '.json'}"
            fallback = Path(tempfile.gettempdir()) / name
            try:
                write_atomic(fallback, state_text(self.world))
                where = f"what this run learned is saved in {fallback} instead"
            except OSError:
                where = "what this run learned could not be saved anywhere"
            raise ConfigError(f"could not save state: {self.reason}; {where}",
                              file=self.path, expected="a folder with space this user can write")
        if self.file.diverted is not None:
            raise self.file.conflict_error()
