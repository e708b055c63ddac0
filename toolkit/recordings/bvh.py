"""BVH motion files: read, and forward kinematics to joint positions (:mod:`toolkit.recordings.bvh_writer` writes them).

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
Positions are in the file's own units and axes; :mod:`toolkit.recordings.profile` maps
them to likeme's metres with ``+y`` up.

Every problem is a :class:`~toolkit.errors.ConfigError` with the file, line and
column, what was expected and what was found.
"""

from __future__ import annotations

import codecs
import itertools
import os
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from toolkit.errors import ConfigError
from toolkit.files import check_regular_file, open_regular
from toolkit.recordings.recording import BLOCK, MAX_FPS, MIN_FPS, Recording

__all__ = ["Joint", "BVH", "BVHStream", "read_bvh", "open_bvh", "open_file", "iter_bvh_blocks", "parse_bvh",
           "CHANNEL_NAMES", "MAX_DEPTH"]

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
        return self.kinematics(self.values)

    def kinematics(self, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`forward_kinematics` of channel values (n, C); each frame on its own (the same bits in any block)."""
        from scipy.spatial.transform import Rotation

        n = len(values)
        positions = np.empty((n, len(self.joints), 3))
        rotations = np.empty((n, len(self.joints), 3, 3))
        for j, joint in enumerate(self.joints):
            local_t = np.broadcast_to(np.asarray(joint.offset, dtype=float), (n, 3)).copy()
            order, angles = "", []
            for c, column in zip(joint.channels, self._columns[j]):
                axis = "XYZ".index(c[0])
                if c.endswith("position"):
                    local_t[:, axis] = values[:, column]
                else:
                    order += c[0]
                    angles.append(values[:, column])
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

    def positions(self, block: int = BLOCK) -> np.ndarray:
        """World positions (F, J, 3) of every joint and end site, in the file's units and axes.

        Computed ``block`` frames at a time, so the rotations (frames x joints x 9 numbers) are never held for the
        whole file; the same bits as :meth:`forward_kinematics`.
        """
        out = np.empty((self.n_frames, len(self.joints), 3))
        for f in range(0, self.n_frames, max(1, block)):
            out[f : f + block] = self.kinematics(self.values[f : f + block])[0]
        return out


# -- reading ----------------------------------------------------------------------------------------

MAX_DEPTH = 256
"""The deepest nesting of joints read (real skeletons are under 30 deep, fingers included)."""
MAX_CHANNELS = len(CHANNEL_NAMES)
"""The most channels one joint can have (each channel name once)."""
_CHUNK = 1 << 18  # characters of text taken at a time
_PIECE = 1 << 15  # values converted from text at a time
_HISTORY = 64  # header tokens kept for messages about a token already taken

_TOKEN = re.compile(r"\S+")
# the line boundaries of str.splitlines, so that line numbers are the same as reading the file line by line
_BREAK = re.compile("\r\n|[\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029]")


def _shown(token: str | None) -> str:
    """A token as a message shows it: quoted, cut to 40 characters."""
    return repr(token) if token is None or len(token) <= 40 else repr(token[:40]) + "..."


def _text_chunks(text: str) -> Iterator[str]:
    """A text in pieces of ``_CHUNK`` characters, a leading byte-order mark dropped."""
    start = 1 if text.startswith("\ufeff") else 0
    for i in range(start, len(text), _CHUNK):
        yield text[i : i + _CHUNK]


def _file_chunks(path: Path) -> Iterator[str]:
    """The decoded text of a regular file in pieces (UTF-8, a byte-order mark dropped, bad bytes replaced)."""
    decoder = codecs.getincrementaldecoder("utf-8-sig")(errors="replace")
    with open_regular(path, "BVH file", "motion") as f:
        while True:
            try:
                raw = f.read(_CHUNK)
            except OSError as exc:
                raise ConfigError(f"cannot read ({exc.strerror or exc})", file=path,
                                  expected="a readable BVH file") from None
            if not raw:
                break
            yield decoder.decode(raw)
    yield decoder.decode(b"", final=True)


class _Lines:
    """Lines of text arriving in chunks, numbered as ``str.splitlines`` numbers them; the rest taken as chunks."""

    def __init__(self, chunks: Iterator[str]) -> None:
        self._chunks = chunks
        self._buf = ""
        self._pos = 0
        self._eof = False
        self.number = 0

    def _more(self) -> bool:
        for chunk in self._chunks:
            if chunk:
                self._buf = self._buf[self._pos :] + chunk
                self._pos = 0
                return True
        self._eof = True
        return False

    def next(self) -> tuple[int, str] | None:
        """The next (line number, line) without its break, or None at the end."""
        while True:
            m = _BREAK.search(self._buf, self._pos)
            # a '\r' at the end of what has arrived may be the first half of '\r\n'
            if m is not None and (m.end() < len(self._buf) or m.group() != "\r" or self._eof):
                line, self._pos = self._buf[self._pos : m.start()], m.end()
                self.number += 1
                return self.number, line
            if not self._eof and self._more():
                continue
            if self._pos < len(self._buf):
                line, self._pos = self._buf[self._pos :], len(self._buf)
                self.number += 1
                return self.number, line
            return None

    def __iter__(self) -> Iterator[tuple[int, str]]:
        while (item := self.next()) is not None:
            yield item

    def rest(self) -> Iterator[str]:
        """The text not yet taken as lines, in chunks."""
        if self._pos < len(self._buf):
            yield self._buf[self._pos :]
        self._buf, self._pos = "", 0
        yield from self._chunks


class _Tokens:
    """The header's whitespace-separated tokens with their line and column, for messages.

    Lines are tokenized one at a time as tokens are taken; only the last few tokens are kept (a message names a
    token taken a moment ago), so a long header costs no memory per token.
    """

    def __init__(self, lines: _Lines, source: str) -> None:
        self.source = source
        self.lines = lines
        self.items: dict[int, tuple[str, int, int]] = {}
        self.count = 0  # tokens tokenized so far
        self.pos = 0
        self.last_line = 0  # the line of the last token tokenized
        self.line_number, self.line_text = 0, ""
        self._matches: Iterator[re.Match] | None = None

    def _fill(self, i: float) -> None:
        """Tokenize until there is a token ``i`` or the text ends."""
        while self.count <= i:
            m = next(self._matches, None) if self._matches is not None else None
            if m is not None:
                self.items[self.count] = (m.group(), self.line_number, m.start() + 1)
                self.last_line = self.line_number
                self.count += 1
                continue
            item = self.lines.next()
            if item is None:
                return
            self.line_number, self.line_text = item
            self._matches = _TOKEN.finditer(self.line_text)
        if len(self.items) > 4 * _HISTORY:
            for k in [k for k in self.items if k < self.pos - _HISTORY]:
                del self.items[k]

    def error(self, problem: str, expected: str | None = None, at: int | None = None) -> ConfigError:
        """The error at token ``at`` (default: the next one), or on the line after the last token at the end."""
        i = self.pos if at is None else at
        self._fill(i)
        if i < self.count:
            _, line, column = self.items[i]
        else:
            line, column = self.last_line + 1, 1
        return ConfigError(problem, file=self.source, line=line, column=column, expected=expected)

    def peek(self) -> str | None:
        self._fill(self.pos)
        return self.items[self.pos][0] if self.pos < self.count else None

    def take(self, expected: str) -> str:
        self._fill(self.pos)
        if self.pos >= self.count:
            raise self.error("unexpected end of file", expected)
        token = self.items[self.pos][0]
        self.pos += 1
        return token

    def expect(self, word: str) -> None:
        token = self.take(repr(word))
        if token != word:
            self.pos -= 1
            raise self.error(f"found {_shown(token)}", repr(word))

    def number(self, what: str) -> float:
        token = self.take(what)
        try:
            value = float(token)
        except ValueError:
            self.pos -= 1
            raise self.error(f"found {_shown(token)}", what) from None
        if not np.isfinite(value):
            self.pos -= 1
            raise self.error(f"found {_shown(token)}", f"a finite {what}")
        return value

    def integer(self, what: str, most: int) -> int:
        """A count in ASCII digits (``str.isdigit`` would take '²'), at most ``most``."""
        token = self.take(what)
        if not (token.isascii() and token.isdigit()) or len(token) > 18 or int(token) > most:
            self.pos -= 1
            raise self.error(f"found {_shown(token)}", f"{what} (ASCII digits, at most {most})")
        return int(token)


@dataclass
class _Header:
    """What comes before the MOTION block's values, and where they start."""

    joints: list[Joint]
    frame_time: float
    n_frames: int
    line: int  # the line of 'Frame Time', where the values may start
    column: int  # the character after the frame time's number on that line (0-based)
    first: str  # that line's text


def _parse_header(tokens: _Tokens) -> _Header:
    """HIERARCHY to the frame time, with every bound checked where it is read (iteratively: no recursion)."""
    tokens.expect("HIERARCHY")
    joints: list[Joint] = []
    names: dict[str, str] = {}  # every name so far (joints and end sites), with where it was given, for messages
    while tokens.peek() == "ROOT":
        tokens.take("ROOT")
        open_joints = [_parse_joint_head(tokens, joints, names, parent=-1)]
        while open_joints:
            index = open_joints[-1]
            name = joints[index].name
            token = tokens.peek()
            if token == "JOINT":
                if len(open_joints) >= MAX_DEPTH:
                    raise tokens.error(f"joints nested deeper than {MAX_DEPTH}", f"at most {MAX_DEPTH} levels of JOINT")
                tokens.take("JOINT")
                open_joints.append(_parse_joint_head(tokens, joints, names, parent=index))
            elif token == "End":
                at = tokens.pos
                tokens.take("End")
                tokens.expect("Site")
                end_name = f"{name}_end"  # an end site is named after its parent: it must not shadow another point
                if end_name in names:
                    raise tokens.error(f"the end site of joint {_shown(name)} is named {_shown(end_name)}, like "
                                       f"{names[end_name]}", "unique joint names (end sites are named <parent>_end: "
                                       "rename the joint)", at=at)
                names[end_name] = f"the end site of joint {_shown(name)} at line {tokens.items[at][1]}"
                tokens.expect("{")
                tokens.expect("OFFSET")
                end = tuple(tokens.number("an OFFSET coordinate") for _ in range(3))
                tokens.expect("}")
                joints.append(Joint(end_name, index, end, (), end_site=True))
            elif token == "}":
                tokens.take("}")
                open_joints.pop()
            else:
                raise tokens.error(f"found {_shown(token)}" if token else "unexpected end of file",
                                   f"'JOINT', 'End Site' or '}}' closing joint {_shown(name)}")
    if not joints:
        raise tokens.error(f"found {_shown(tokens.peek())}" if tokens.peek() else "unexpected end of file", "'ROOT'")
    if not any(j.channels for j in joints):
        tokens.peek()
        raise tokens.error("no channels in the hierarchy", "at least one joint with CHANNELS (a motion to read)")
    tokens.expect("MOTION")
    tokens.expect("Frames:")
    n_frames = tokens.integer("the number of frames", 10**15)
    tokens.expect("Frame")
    tokens.expect("Time:")
    at = tokens.pos
    frame_time = tokens.number("the frame time in seconds")
    if frame_time <= 0:
        raise tokens.error(f"frame time {frame_time}", "a positive number of seconds", at=at)
    if not 1.0 / MAX_FPS <= frame_time <= 1.0 / MIN_FPS:
        raise tokens.error(f"frame time {frame_time:g} s ({1.0 / frame_time:g} frames per second)",
                           f"a frame time of {1.0 / MAX_FPS:g} to {1.0 / MIN_FPS:g} seconds (frame rates from 1/60 Hz "
                           f"to {MAX_FPS / 1000:g} kHz)", at=at)
    token, line, column = tokens.items[at]
    return _Header(joints, frame_time, n_frames, line, column - 1 + len(token), tokens.line_text)


def _parse_joint_head(tokens: _Tokens, joints: list[Joint], names: dict[str, str], parent: int) -> int:
    """A joint's name, OFFSET and CHANNELS (its children come after); returns its index."""
    at = name_at = tokens.pos
    name = tokens.take("a joint name")
    if name in ("{", "}", "OFFSET", "CHANNELS"):
        raise tokens.error(f"found {_shown(name)}", "a joint name", at=at)
    if name in names:
        raise tokens.error(f"duplicate joint name {_shown(name)}" + ("" if names[name].startswith("the joint") else
                           f", the name of {names[name]}"), "unique joint names", at=at)
    tokens.expect("{")
    tokens.expect("OFFSET")
    offset = tuple(tokens.number("an OFFSET coordinate") for _ in range(3))
    tokens.expect("CHANNELS")
    count = tokens.integer("the number of channels", MAX_CHANNELS)
    channels: list[str] = []
    for _ in range(count):
        at = tokens.pos
        c = tokens.take("a channel name")
        if c not in CHANNEL_NAMES:
            raise tokens.error(f"found {_shown(c)}", "a channel name (" + ", ".join(CHANNEL_NAMES) + ")", at=at)
        if c in channels:
            raise tokens.error(f"channel {c!r} listed twice for joint {_shown(name)}", "each channel once", at=at)
        channels.append(c)
    names[name] = f"the joint at line {tokens.items[name_at][1]}"
    joints.append(Joint(name, parent, offset, tuple(channels)))
    return len(joints) - 1


def _motion_lines(header: _Header, lines: Iterator[tuple[int, str]]) -> Iterator[tuple[int, str]]:
    """The MOTION block's lines from the frame time's line on, what precedes the values blanked (columns kept)."""
    yield header.line, " " * header.column + header.first[header.column :]
    yield from lines


def _locate(header: _Header, lines: Iterator[tuple[int, str]], n_channels: int, source: str) -> ConfigError:
    """The error of a MOTION block that does not read as an array, with its line and column, in one pass.

    In order: the number of values (the first frame line whose count is wrong, else the frame lines counted), then
    the first value that is not a number, then the first that is not finite; line by line, so the memory is that
    of the longest line.
    """
    n_frames = header.n_frames
    expected = n_frames * n_channels
    total, k, last_line = 0, 0, header.line
    bad_count = beyond = bad_token = not_finite = None
    batch: list[tuple[int, str, list[str]]] = []  # lines whose values are converted together
    held = 0

    def check() -> None:
        """Look for the first value that is not a number (and the first not finite) in the lines of ``batch``."""
        nonlocal bad_token, not_finite
        if bad_token is not None:
            return
        try:
            values = np.array([w for _, _, words in batch for w in words], dtype=float)
        except ValueError:
            values = None
        if values is not None and (not_finite is not None or np.isfinite(values).all()):
            return
        for number, line, words in batch:  # line by line, only in a batch with a problem
            try:
                values = np.array(words, dtype=float)
            except ValueError:
                j = next(j for j, w in enumerate(words) if not _is_number(w))
                bad_token = (words[j], number, _column(line, j))
                return
            if not_finite is None and not np.isfinite(values).all():
                j = int(np.flatnonzero(~np.isfinite(values))[0])
                not_finite = (words[j], number, _column(line, j))

    for number, line in _motion_lines(header, lines):
        words = line.split()
        if not words:
            continue
        count = len(words)
        if bad_count is None and count != n_channels:
            bad_count = (k, number, count)
        k += 1
        if beyond is None and total + count > expected:
            beyond = (number, _column(line, expected - total))
        total += count
        last_line = number
        if bad_token is None:
            batch.append((number, line, words))
            held += count
            if held >= _PIECE:
                check()
                batch, held = [], 0
    check()
    if total != expected:
        if bad_count is not None:
            i, number, count = bad_count
            return ConfigError(f"frame {i + 1} has {count} values", file=source, line=number, column=1,
                               expected=f"{n_channels} channel values per frame line")
        number, column = (last_line + 1, 1) if k < n_frames else beyond
        return ConfigError(f"{k} frame lines after 'Frames: {n_frames}'", file=source, line=number, column=column,
                           expected=f"{n_frames} frame lines")
    if bad_token is not None:
        token, number, column = bad_token
        return ConfigError(f"found {_shown(token)}", file=source, line=number, column=column,
                           expected="a number (a channel value)")
    if not_finite is not None:
        token, number, column = not_finite
        return ConfigError(f"found {_shown(token)}", file=source, line=number, column=column,
                           expected="a finite channel value")
    return ConfigError("the MOTION block does not read as numbers", file=source, line=header.line,
                       expected="channel values")  # pragma: no cover - the block read as an array after all


def _column(line: str, j: int) -> int:
    """The column (1-based) of the ``j``-th token of a line."""
    for i, m in enumerate(_TOKEN.finditer(line)):
        if i == j:
            return m.start() + 1
    return len(line) + 1  # pragma: no cover


def _is_number(word: str) -> bool:
    try:
        np.array([word], dtype=float)
    except ValueError:
        return False
    return True


def _motion_blocks(chunks: Iterator[str], n_frames: int, n_channels: int, frames: int,
                   fail: Callable[[], ConfigError]) -> Iterator[np.ndarray]:
    """The MOTION block's values as arrays of ``frames`` frames (the last one shorter); ``fail`` gives the error.

    The text is split into tokens a chunk at a time and converted ``_PIECE`` values at a time into the block being
    filled; the line and column of a problem are found only when there is one (``fail``, a second pass).
    """
    total, frames = n_frames * n_channels, max(1, frames)
    piece = max(1, _PIECE // n_channels)  # frames converted at a time: a list of strings this long is alive
    pending: list[str] = []
    done, carry, yielded = 0, "", 0  # values converted, a token cut by the chunk's end, frames given
    block, filled = None, 0

    def room() -> int:
        """Frames still to fill in the block (a new one holds ``frames`` or the frames left)."""
        return min(frames, n_frames - yielded) if block is None else len(block) - filled

    def convert(k: int) -> None:
        nonlocal block, filled, done
        if block is None:
            block, filled = np.empty((min(frames, n_frames - yielded), n_channels)), 0
        words = pending[: k * n_channels]
        try:
            block[filled : filled + k] = np.array(words, dtype=float).reshape(k, n_channels)
        except ValueError:
            raise fail() from None
        if not np.isfinite(block[filled : filled + k]).all():
            raise fail()
        del pending[: k * n_channels]
        filled += k
        done += k * n_channels

    for chunk in chunks:
        if not chunk:
            continue
        text = carry + chunk
        words = text.split()
        carry = words.pop() if words and not text[-1].isspace() else ""
        if done + len(pending) + len(words) > total:
            raise fail()
        pending += words
        while len(pending) >= piece * n_channels:
            convert(min(piece, room()))
            if filled == len(block):
                yield block
                yielded += filled
                block = None
    if carry:
        pending.append(carry)
    if done + len(pending) != total:
        raise fail()
    while pending:
        convert(min(len(pending) // n_channels, room()))
        if filled == len(block):
            yield block
            yielded += filled
            block = None
    if block is not None and filled:  # pragma: no cover - a block is given as soon as it is full
        yield block[:filled]


class BVHStream:
    """A BVH file whose header has been read and whose MOTION block is read in blocks of frames.

    Made by :func:`open_bvh`. ``header`` is a :class:`BVH` with the joints and frame time and no frames;
    :meth:`blocks` yields the channel values (k, C) block by block, with the same errors (file, line, column) as
    reading the whole file. Use it as a context manager, or iterate :meth:`blocks` to the end, to close the file.
    """

    def __init__(self, open_chunks: Callable[[], Iterator[str]], source: str, size: int) -> None:
        self._open, self.source = open_chunks, source
        self._chunks = open_chunks()
        self._lines = _Lines(self._chunks)
        try:
            self._head = _parse_header(_Tokens(self._lines, source))
        except BaseException:
            self.close()
            raise
        self.header = BVH(self._head.joints, self._head.frame_time, np.empty((0, 0)), source)
        self._size = size  # an upper bound of the characters in the text
        self._read = False

    @property
    def n_frames(self) -> int:
        """The number of frames the header declares (the blocks are checked against it)."""
        return self._head.n_frames

    @property
    def n_channels(self) -> int:
        return self.header.n_channels

    @property
    def fps(self) -> float:
        return self.header.fps

    @property
    def joints(self) -> list[Joint]:
        return self.header.joints

    @property
    def names(self) -> list[str]:
        return self.header.names

    def _fail(self) -> ConfigError:
        """The error of the MOTION block, found by reading the text again from the start."""
        self.close()
        lines = _Lines(self._open())
        try:
            for number, _ in lines:
                if number == self._head.line:
                    break
            return _locate(self._head, iter(lines), self.n_channels, self.source)
        finally:
            close = getattr(lines._chunks, "close", None)
            if close is not None:
                close()

    def _possible(self) -> bool:
        """Whether the text can hold the declared frames (each value takes a character and a separator)."""
        return self.n_frames * (2 * self.n_channels) - 1 <= self._size

    def blocks(self, frames: int = BLOCK) -> Iterator[np.ndarray]:
        """The channel values (k, C) of ``frames`` frames at a time (the last block shorter), once."""
        if self._read:
            raise RuntimeError("the MOTION block of a BVHStream is read once")
        self._read = True
        try:
            if not self._possible():
                raise self._fail()
            head = self._head
            chunks = itertools.chain([head.first[head.column :] + "\n"], self._lines.rest())
            yield from _motion_blocks(chunks, self.n_frames, self.n_channels, frames, self._fail)
        finally:
            self.close()

    def read(self) -> BVH:
        """All the frames as one :class:`BVH` (the values in one array, filled block by block)."""
        if not self._possible():
            self.close()
            raise self._fail()
        values = np.empty((self.n_frames, self.n_channels))
        f = 0
        for block in self.blocks(max(1, _PIECE // self.n_channels)):
            values[f : f + len(block)] = block
            f += len(block)
        return BVH(self.joints, self.header.frame_time, values, self.source)

    def close(self) -> None:
        close = getattr(self._chunks, "close", None)
        if close is not None:
            close()

    def __enter__(self) -> BVHStream:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def open_bvh(path: str | Path) -> BVHStream:
    """Open a BVH file and read its header; the MOTION block follows with :meth:`BVHStream.blocks`.

    Only a regular file within the size cap is opened (:func:`toolkit.files.check_regular_file`).
    """
    path = check_regular_file(path, "BVH file", "motion")
    size = os.stat(path).st_size
    return BVHStream(lambda: _file_chunks(path), str(path), size)


def iter_bvh_blocks(path: str | Path, frames: int = BLOCK) -> Iterator[np.ndarray]:
    """The channel values of a BVH file in blocks of ``frames`` frames (k, C), as :func:`read_bvh` reads them.

    ``np.concatenate(list(iter_bvh_blocks(path, n)))`` is ``read_bvh(path).values`` bit for bit, and a file that
    :func:`read_bvh` refuses raises the same error (file, line, column) when the block holding the problem is read.
    """
    with open_bvh(path) as stream:
        yield from stream.blocks(frames)


def parse_bvh(text: str, source: str = "<bvh>") -> BVH:
    """Parse the text of a BVH file; ``source`` names it in error messages."""
    return BVHStream(lambda: _text_chunks(text), source, len(text)).read()


def read_bvh(path: str | Path) -> BVH:
    """Read a BVH file; a missing, unreadable, special (a FIFO, a device), oversized or malformed file is a
    :class:`ConfigError`."""
    return open_bvh(path).read()


def open_file(path: Path, *, names: object = None, fps: float | None = None, frames: int = BLOCK,
              need_fps: bool = True) -> Recording:
    """A BVH file as a :class:`~toolkit.recordings.recording.Recording` (:func:`toolkit.recordings.open_recording`):
    its joints and end sites in file order with their hierarchy, the rate from its Frame Time (``fps`` and ``names``
    do not apply: the file has both), the positions of every joint by forward kinematics, a block of frames at a
    time (each frame on its own: the same bits as :meth:`BVH.positions`)."""
    stream = open_bvh(path)
    header = stream.header
    blocks = (header.kinematics(values)[0] for values in stream.blocks(frames))
    return Recording(stream.names, stream.fps, stream.source, "BVH", blocks, stream.close, n_frames=stream.n_frames,
                     parents=[j.parent for j in stream.joints])
