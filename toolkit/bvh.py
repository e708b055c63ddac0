"""BVH motion files: read, write, and forward kinematics to joint positions.

A BVH file is a joint hierarchy followed by one line of channel values per
frame. This reader accepts what real files contain (``docs/conventions.md``
is the full list of conventions):

- per-joint channel counts and rotation orders that differ within one file;
- position channels on any joint, not only the root: they *replace* the
  joint's OFFSET in that frame (the Bandai-Namco clips have six channels on
  every joint);
- ``End Site`` blocks, kept as leaf points named ``<parent>_end``;
- numbers in scientific notation, CRLF or LF line ends, tabs;
- the frame rate from ``Frame Time``.

Rotation channels compose as *intrinsic* rotations in the order they are
listed (``Zrotation Xrotation Yrotation`` is ``Rz @ Rx @ Ry``), in degrees.
Positions are in the file's own units and axes; :mod:`toolkit.profile` maps
them to likeme's metres with ``+y`` up.

Every problem is a :class:`~toolkit.errors.ConfigError` with the file, line and
column, what was expected and what was found.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from toolkit.errors import ConfigError

__all__ = ["Joint", "BVH", "read_bvh", "parse_bvh", "write_bvh", "format_bvh", "from_joint_positions", "CHANNEL_NAMES"]

CHANNEL_NAMES = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")


@dataclass(frozen=True)
class Joint:
    """One point of the hierarchy.

    ``parent`` is the index of the parent joint (-1 for a root); ``channels``
    is empty for end sites, which are leaf points with only an offset.
    """

    name: str
    parent: int
    offset: tuple[float, float, float]
    channels: tuple[str, ...] = ()
    end_site: bool = False


@dataclass(eq=False)
class BVH:
    """A parsed BVH file.

    Attributes
    ----------
    joints : list of Joint
        In file order (parents before children), end sites included.
    frame_time : float
        Seconds per frame.
    values : array, shape (F, C)
        The channel values, columns in the order of the joints' channels.
    source : str
        Where it came from (file name), for messages.
    """

    joints: list[Joint]
    frame_time: float
    values: np.ndarray
    source: str = "<bvh>"
    _columns: list[np.ndarray] = field(default_factory=list, repr=False)

    def __post_init__(self) -> None:
        self.values = np.asarray(self.values, dtype=float).reshape(-1, self.n_channels)
        start, self._columns = 0, []
        for joint in self.joints:
            self._columns.append(np.arange(start, start + len(joint.channels)))
            start += len(joint.channels)

    @property
    def n_channels(self) -> int:
        return sum(len(j.channels) for j in self.joints)

    @property
    def n_frames(self) -> int:
        return int(self.values.shape[0])

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time

    @property
    def names(self) -> list[str]:
        return [j.name for j in self.joints]

    def index(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise ConfigError(f"no joint {name!r}", file=self.source, expected="a joint of this file",
                              available=self.names) from None

    def channel(self, joint: str, channel: str) -> np.ndarray:
        """The values (F,) of one channel of one joint."""
        j = self.index(joint)
        channels = self.joints[j].channels
        if channel not in channels:
            raise ConfigError(f"joint {joint!r} has no channel {channel!r}", file=self.source, available=channels)
        return self.values[:, self._columns[j][channels.index(channel)]]

    def forward_kinematics(self) -> tuple[np.ndarray, np.ndarray]:
        """World positions (F, J, 3) and rotations (F, J, 3, 3) of every joint, vectorised over frames.

        A joint's translation is its position channels where it has them (each
        one replaces the matching OFFSET component), else its OFFSET; its
        rotation is the intrinsic product of its rotation channels in order.
        """
        from scipy.spatial.transform import Rotation

        n = self.n_frames
        positions = np.empty((n, len(self.joints), 3))
        rotations = np.empty((n, len(self.joints), 3, 3))
        for j, joint in enumerate(self.joints):
            local_t = np.broadcast_to(np.asarray(joint.offset, dtype=float), (n, 3)).copy()
            order, angles = "", []
            for c, column in zip(joint.channels, self._columns[j]):
                axis = "XYZ".index(c[0])
                if c.endswith("position"):
                    local_t[:, axis] = self.values[:, column]
                else:
                    order += c[0]
                    angles.append(self.values[:, column])
            if order:
                local_r = Rotation.from_euler(order, np.stack(angles, axis=1), degrees=True).as_matrix()
            else:
                local_r = np.broadcast_to(np.eye(3), (n, 3, 3))
            if joint.parent < 0:
                positions[:, j] = local_t
                rotations[:, j] = local_r
            else:
                parent_r = rotations[:, joint.parent]
                positions[:, j] = positions[:, joint.parent] + np.einsum("fij,fj->fi", parent_r, local_t)
                rotations[:, j] = parent_r @ local_r
        return positions, rotations

    def positions(self) -> np.ndarray:
        """World positions (F, J, 3) of every joint and end site, in the file's units and axes."""
        return self.forward_kinematics()[0]


# -- reading ----------------------------------------------------------------------------------------

_TOKEN = re.compile(r"\S+")
# the line boundaries of str.splitlines, so that line numbers are the same as reading the file line by line
_BREAK = re.compile("\r\n|[\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029]")


def _lines(text: str):
    """(line number, line, offset in ``text`` after the line and its break), lazily, as ``text.splitlines()``."""
    start, number = 0, 0
    for m in _BREAK.finditer(text):
        number += 1
        yield number, text[start:m.start()], m.end()
        start = m.end()
    if start < len(text):
        yield number + 1, text[start:], len(text)


class _Tokens:
    """Whitespace-separated tokens with their line and column, for messages.

    Lines are tokenized on demand: the header is read token by token, and the
    MOTION block's numbers can be taken as one array (:meth:`rest`) without a
    tuple per number.
    """

    def __init__(self, text: str, source: str) -> None:
        self.source = source
        self.text = text
        self.items: list[tuple[str, int, int]] = []
        self._lines = _lines(text)
        self.offset = 0  # where the first line not yet tokenized starts in ``text``
        self.pos = 0

    def _fill(self, i: float) -> None:
        """Tokenize lines until there is a token ``i`` or the text ends."""
        while len(self.items) <= i:
            try:
                number, line, self.offset = next(self._lines)
            except StopIteration:
                self.offset = len(self.text)
                return
            for m in _TOKEN.finditer(line):
                self.items.append((m.group(), number, m.start() + 1))

    def fill_all(self) -> None:
        self._fill(float("inf"))

    def rest(self) -> list[str]:
        """The tokens from ``pos`` to the end, without line and column (not consuming them)."""
        return [t for t, _, _ in self.items[self.pos:]] + self.text[self.offset:].split()

    def error(self, problem: str, expected: str | None = None, at: int | None = None) -> ConfigError:
        i = self.pos if at is None else at
        self._fill(i)
        if i < len(self.items):
            _, line, column = self.items[i]
        else:
            line = (self.items[-1][1] if self.items else 0) + 1
            column = 1
        return ConfigError(problem, file=self.source, line=line, column=column, expected=expected)

    def peek(self) -> str | None:
        self._fill(self.pos)
        return self.items[self.pos][0] if self.pos < len(self.items) else None

    def take(self, expected: str) -> str:
        self._fill(self.pos)
        if self.pos >= len(self.items):
            raise self.error("unexpected end of file", expected)
        token = self.items[self.pos][0]
        self.pos += 1
        return token

    def expect(self, word: str) -> None:
        token = self.take(repr(word))
        if token != word:
            self.pos -= 1
            raise self.error(f"found {token!r}", repr(word))

    def number(self, what: str) -> float:
        token = self.take(what)
        try:
            value = float(token)
        except ValueError:
            self.pos -= 1
            raise self.error(f"found {token!r}", what) from None
        if not np.isfinite(value):
            self.pos -= 1
            raise self.error(f"found {token!r}", f"a finite {what}")
        return value

    def integer(self, what: str) -> int:
        token = self.take(what)
        if not token.isdigit():
            self.pos -= 1
            raise self.error(f"found {token!r}", what)
        return int(token)


def parse_bvh(text: str, source: str = "<bvh>") -> BVH:
    """Parse the text of a BVH file; ``source`` names it in error messages."""
    return _parse(text, source)


def _parse(text: str, source: str, fast: bool = True) -> BVH:
    """``parse_bvh``; ``fast=False`` reads the MOTION block token by token (the reference for the fast path)."""
    tokens = _Tokens(text, source)
    tokens.expect("HIERARCHY")
    joints: list[Joint] = []
    while tokens.peek() == "ROOT":
        tokens.take("ROOT")
        _parse_joint(tokens, joints, parent=-1)
    if not joints:
        raise tokens.error(f"found {tokens.peek()!r}" if tokens.peek() else "unexpected end of file", "'ROOT'")
    tokens.expect("MOTION")
    tokens.expect("Frames:")
    n_frames = tokens.integer("the number of frames")
    tokens.expect("Frame")
    tokens.expect("Time:")
    at = tokens.pos
    frame_time = tokens.number("the frame time in seconds")
    if frame_time <= 0:
        raise tokens.error(f"frame time {frame_time}", "a positive number of seconds", at=at)
    n_channels = sum(len(j.channels) for j in joints)
    if fast:
        # the MOTION block as one array; any problem (a count, a token, a value) is located token by token below
        rest, values = tokens.rest(), None
        if len(rest) == n_frames * n_channels:
            try:
                values = np.array(rest, dtype=float).reshape(n_frames, n_channels)
            except ValueError:
                pass
        del rest
        if values is not None and np.isfinite(values).all():
            return BVH(joints, frame_time, values, source)
    tokens.fill_all()
    return BVH(joints, frame_time, _motion_values(tokens, n_frames, n_channels), source)


def _motion_values(tokens: _Tokens, n_frames: int, n_channels: int) -> np.ndarray:
    """The MOTION block's values from the tokens after ``Frame Time``, with the line and column of any problem."""
    source = tokens.source
    first = tokens.pos
    rest = tokens.items[first:]
    if len(rest) != n_frames * n_channels:
        # find the line that is too short or too long, to name it
        lines: dict[int, int] = {}
        for _, line, _ in rest:
            lines[line] = lines.get(line, 0) + 1
        for k, (line, count) in enumerate(sorted(lines.items())):
            if count != n_channels:
                raise ConfigError(f"frame {k + 1} has {count} values", file=source, line=line, column=1,
                                  expected=f"{n_channels} channel values per frame line")
        raise tokens.error(f"{len(lines)} frame lines after 'Frames: {n_frames}'", f"{n_frames} frame lines",
                           at=first + len(rest) if len(lines) < n_frames else first + n_frames * n_channels)
    try:
        values = np.array([t for t, _, _ in rest], dtype=float).reshape(n_frames, n_channels)
    except ValueError:
        for k, (token, line, column) in enumerate(rest):
            try:
                float(token)
            except ValueError:
                raise ConfigError(f"found {token!r}", file=source, line=line, column=column,
                                  expected="a number (a channel value)") from None
        raise
    bad = ~np.isfinite(values)
    if bad.any():
        k = int(np.flatnonzero(bad.reshape(-1))[0])
        token, line, column = rest[k]
        raise ConfigError(f"found {token!r}", file=source, line=line, column=column, expected="a finite channel value")
    return values


def _parse_joint(tokens: _Tokens, joints: list[Joint], parent: int) -> None:
    at = tokens.pos
    name = tokens.take("a joint name")
    if name in ("{", "}", "OFFSET", "CHANNELS"):
        raise tokens.error(f"found {name!r}", "a joint name", at=at)
    if any(j.name == name for j in joints):
        raise tokens.error(f"duplicate joint name {name!r}", "unique joint names", at=at)
    tokens.expect("{")
    tokens.expect("OFFSET")
    offset = tuple(tokens.number("an OFFSET coordinate") for _ in range(3))
    tokens.expect("CHANNELS")
    count = tokens.integer("the number of channels")
    channels = []
    for _ in range(count):
        at = tokens.pos
        c = tokens.take("a channel name")
        if c not in CHANNEL_NAMES:
            raise tokens.error(f"found {c!r}", "a channel name (" + ", ".join(CHANNEL_NAMES) + ")", at=at)
        if c in channels:
            raise tokens.error(f"channel {c!r} listed twice for joint {name!r}", "each channel once", at=at)
        channels.append(c)
    index = len(joints)
    joints.append(Joint(name, parent, offset, tuple(channels)))
    while True:
        token = tokens.peek()
        if token == "JOINT":
            tokens.take("JOINT")
            _parse_joint(tokens, joints, index)
        elif token == "End":
            tokens.take("End")
            tokens.expect("Site")
            tokens.expect("{")
            tokens.expect("OFFSET")
            end = tuple(tokens.number("an OFFSET coordinate") for _ in range(3))
            tokens.expect("}")
            joints.append(Joint(f"{name}_end", index, end, (), end_site=True))
        elif token == "}":
            tokens.take("}")
            return
        else:
            raise tokens.error(f"found {token!r}" if token else "unexpected end of file",
                               f"'JOINT', 'End Site' or '}}' closing joint {name!r}")


def read_bvh(path: str | Path) -> BVH:
    """Read a BVH file; a missing, unreadable or malformed file is a :class:`ConfigError`."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise ConfigError(f"cannot read ({exc.strerror or exc})", file=path, expected="a readable BVH file") from None
    return parse_bvh(text, str(path))


# -- writing ----------------------------------------------------------------------------------------


def _number(x: float) -> str:
    return format(float(x), ".9g")


def format_bvh(bvh: BVH, *, precision: int = 6) -> str:
    """The text of a BVH file for ``bvh`` (values to ``precision`` significant digits)."""
    children: dict[int, list[int]] = {}
    for i, j in enumerate(bvh.joints):
        children.setdefault(j.parent, []).append(i)
    out = ["HIERARCHY"]

    def emit(i: int, depth: int) -> None:
        joint, pad = bvh.joints[i], "  " * depth
        off = " ".join(_number(v) for v in joint.offset)
        if joint.end_site:
            out.extend([f"{pad}End Site", f"{pad}{{", f"{pad}  OFFSET {off}", f"{pad}}}"])
            return
        out.append(f"{pad}{'ROOT' if joint.parent < 0 else 'JOINT'} {joint.name}")
        out.append(f"{pad}{{")
        out.append(f"{pad}  OFFSET {off}")
        out.append(f"{pad}  CHANNELS {len(joint.channels)} {' '.join(joint.channels)}".rstrip())
        for c in children.get(i, []):
            emit(c, depth + 1)
        out.append(f"{pad}}}")

    for root in children.get(-1, []):
        emit(root, 0)
    out += ["MOTION", f"Frames: {bvh.n_frames}", f"Frame Time: {bvh.frame_time:.9g}"]
    fmt = f"%.{precision}g"
    out.extend(" ".join(fmt % v for v in row) for row in bvh.values)
    return "\n".join(out) + "\n"


def write_bvh(bvh: BVH, path: str | Path, *, precision: int = 6) -> Path:
    """Write ``bvh`` to ``path`` atomically (temporary file, flush, rename); returns the path."""
    from toolkit.state import write_atomic

    path = Path(path)
    write_atomic(path, format_bvh(bvh, precision=precision))
    return path


def from_joint_positions(names: Sequence[str], parents: Sequence[int], positions: np.ndarray, fps: float,
                         source: str = "<generated>") -> BVH:
    """A BVH that reproduces given joint positions (F, J, 3) with position channels only.

    Every joint gets ``Xposition Yposition Zposition`` channels relative to its
    parent (world-aligned, no rotations), which is how likeme writes its own
    characters' motions: forward kinematics of the result gives back ``positions``.
    """
    positions = np.asarray(positions, dtype=float)
    joints, columns = [], []
    for j, (name, parent) in enumerate(zip(names, parents)):
        local = positions[:, j] - (positions[:, parent] if parent >= 0 else 0.0)
        joints.append(Joint(name, parent, tuple(float(v) for v in local[0]), ("Xposition", "Yposition", "Zposition")))
        columns.append(local)
    return BVH(joints, 1.0 / fps, np.concatenate(columns, axis=1), source)
