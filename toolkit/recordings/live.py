"""Live input: frames of joint positions arriving one line at a time on standard input (``likeme observe -``).

Any tracker can pipe into the toolkit: each line is one frame, read as it arrives (nothing waits for the end of the
input), converted through a body profile (:class:`~toolkit.recordings.profile.BodyProfile`) to part positions in metres with
``+y`` up. Two shapes, told apart by the first line that is not blank (``docs/formats.md``, Live input):

- **CSV lines**: the first line is a header as in a CSV file (``JOINT_x``, ``JOINT_y``, ``JOINT_z`` per joint, an
  optional ``time`` column, other columns ignored; :mod:`toolkit.recordings.csv_positions`), every further line one frame.
- **JSON lines**: one object per line and per frame, ``{"time": 0.033, "Hips": [x, y, z], "Head": [x, y, z], ...}``:
  a key per source joint (keys the profile does not map are ignored), ``time`` in seconds optional.

A missing value (an empty CSV cell, ``nan``, an infinite value; in JSON ``null``, ``NaN`` or a joint left out of a
later frame) makes its part not visible in that frame; anything malformed (a cell that is not a number, a wrong
number of fields, a line that is not a JSON object, a joint that is not three numbers) is a
:class:`~toolkit.errors.ConfigError` naming the line. The frame rate: the ``fps`` given (``--fps`` or the profile's
``fps``), else the step of the first frames' times.

Dropped frames: when the frames carry times, they are placed on the frame grid as a file's time column is
(:func:`toolkit.recordings.csv_positions.frame_grid`): the frame step is measured from the first
:data:`RATE_FRAMES` frames' times, every later step must be a whole number of frames (within
:data:`~toolkit.recordings.csv_positions.TIME_TOLERANCE` of a frame), and the frames a longer step skipped are given
out with no part visible (NaN), at most :data:`MAX_GAP` seconds of them.

Frames are read as they arrive, straight from the input's file descriptor (no read-ahead that waits for a full
buffer): :meth:`LiveInput.blocks` gives out every frame that has arrived at once (one frame when the reader keeps up;
more when it fell behind, for instance while the observer was being composed), so a reader that fell behind catches
up a block at a time (``Observer.push_block``) instead of frame by frame.
"""

from __future__ import annotations

import io
import json
import math
import os
import select
from collections.abc import Iterator
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from toolkit.errors import ConfigError
from toolkit.recordings.csv_positions import (MAX_LINE_CHARS, TIME_TOLERANCE, _OffGrid, frame_grid, parse_header,
                                             parse_rows)
from toolkit.recordings.recording import FPS_RANGE, MAX_FPS, MIN_FPS

__all__ = ["LiveInput", "SOURCE", "RATE_FRAMES", "MAX_GAP", "BLOCK_FRAMES"]

RATE_FRAMES = 3
"""Frames whose times give the frame step (and the rate, without one given): a frame dropped among them is found."""

MAX_GAP = 60.0
"""The longest gap (seconds) between two frames' times that is filled with frames not seen; a longer one is an
error naming the line."""

BLOCK_FRAMES = 256
"""The most frames :meth:`LiveInput.blocks` gives out at once."""

SOURCE = "-"
"""How standard input is named, on the command line and in messages."""

_FPS_EXPECTED = "a frame rate: --fps, `fps` in the profile's [profile] table, or a time on the first two frames"


class _Lines:
    """Lines of a binary stream, read as they arrive; :meth:`ready` says whether one can be read without waiting.

    A stream with a file descriptor (a pipe, standard input) is read from the descriptor itself, whatever has arrived
    at a time (``os.read``), so nothing waits for a buffer to fill; any other stream (``io.BytesIO``) with its own
    ``readline``, every line of it ready.
    """

    def __init__(self, stream: BinaryIO) -> None:
        self.stream, self.buffer, self.eof = stream, bytearray(), False
        try:
            self.fd: int | None = stream.fileno()
        except (AttributeError, OSError, io.UnsupportedOperation):
            self.fd = None

    def readline(self) -> bytes:
        """The next line with its line break (at most ``MAX_LINE_CHARS + 1`` bytes: a longer line is cut there), or
        ``b""`` at the end of the input."""
        if self.fd is None:
            return self.stream.readline(MAX_LINE_CHARS + 1)
        while True:
            end = self.buffer.find(b"\n")
            if end >= 0 or len(self.buffer) > MAX_LINE_CHARS or self.eof:
                cut = min(end + 1 if end >= 0 else len(self.buffer), MAX_LINE_CHARS + 1)
                line = bytes(self.buffer[:cut])
                del self.buffer[:cut]
                return line
            data = os.read(self.fd, 1 << 16)  # waits for what arrives next, however little
            if data:
                self.buffer += data
            else:
                self.eof = True

    def ready(self) -> bool:
        """Whether a line (or the end of the input) can be read now without waiting for more input."""
        if self.fd is None or self.eof or b"\n" in self.buffer:
            return True
        return bool(_readable(self.fd))


def _readable(fd: int) -> bool | None:
    """Whether reading ``fd`` would not wait (``None``: cannot tell)."""
    try:
        return bool(select.select([fd], [], [], 0)[0])
    except (OSError, ValueError):
        return None


class _Header:
    """What :meth:`BodyProfile.check` needs: the joint names of the input and its name."""

    def __init__(self, names: list[str]) -> None:
        self.names, self.source = names, "standard input"


class LiveInput:
    """Frames of joint positions read from a binary stream a line at a time, through a body profile.

    The first frame (the first :data:`RATE_FRAMES` when the frames carry times) is read when the input is made, so
    :attr:`fps` and the joints are known and checked before any frame is given out. Iterating yields each frame's
    part positions, shape (P, 3), in metres with +y up, NaN where a value is missing, as soon as its line is read (and
    a frame with nothing visible for each frame the times show dropped); :meth:`blocks` yields the frames that have
    arrived, a block at a time.

    Parameters
    ----------
    stream : binary file
        Standard input (``sys.stdin.buffer``) or any stream of UTF-8 lines.
    profile : BodyProfile
        Maps the input's joints to parts.
    fps : float, optional
        The frame rate; without it, from the times of the first frames.
    """

    def __init__(self, stream: BinaryIO, profile: Any, fps: float | None = None) -> None:
        self.lines, self.profile, self.line = _Lines(stream), profile, 0
        self.path = Path(SOURCE)
        self.kind = ""
        self._layout = None
        self._timed: bool | None = None  # whether the frames carry times (the first frame says)
        self._step: float | None = None  # the frame step of the times (s)
        self._last: tuple[float, int] | None = None  # the time and line of the last frame placed
        self._pending: list[np.ndarray] = []  # converted frames ready to be given out
        self.fps = None if fps is None else _check_rate(float(fps), self.path, None)
        first = self._next_text()
        if first is None:
            raise ConfigError("no input", file=self.path, expected="a CSV header line or JSON lines, one per frame")
        early: list[tuple[np.ndarray, float | None, int]] = []
        if first.lstrip().startswith("{"):
            self.kind = "json"
            joints, time, seen_keys = self._json(first)
            names = [k for k in seen_keys if k != "time"]
            profile.check(_Header(names))  # the first frame names every mapped joint (null when not seen)
            self.profile = profile.for_names(names, self.path)  # each part's alias the input uses
            if self.profile.joints != profile.joints:  # the first frame again, by those names
                joints, time, _ = self._json(first)
            early.append((joints, time, self.line))
        else:
            self.kind = "csv"
            self._layout = parse_header(first + "\n", self.path, None)
            self.profile = profile.for_names(list(self._layout.joints), self.path)  # aliases chosen once
        self._start(early)

    # -- the frame rate and the frame grid -----------------------------------------------------------

    def _start(self, early: list[tuple[np.ndarray, float | None, int]]) -> None:
        """Read the frames the rate and the frame step need (none when the rate is given: its step is the grid's, so
        nothing waits for frames before the input is ready), measure them, and place them on the grid."""
        with_times = early[0][1] is not None if early else self._layout is not None and self._layout.time is not None
        if self.fps is not None and with_times and not early:  # the first frame with a time sets where the grid is
            self._timed, self._step = True, 1.0 / self.fps
            return
        if self.fps is None:
            while len(early) < RATE_FRAMES and (not early or early[-1][1] is not None):
                frame = self._next_frame()
                if frame is None:
                    break
                early.append(frame)
        timed = next((k for k, (_, t, _) in enumerate(early) if t is None), len(early))  # the frames with a time
        times = [t for _, t, _ in early[:timed]]
        self._timed = timed > 0
        if timed >= 2:
            grid, self._step = self._grid(np.array(times, dtype=float), [n for _, _, n in early[:timed]])
            grid = np.concatenate([grid, grid[-1] + np.arange(1, len(early) - timed + 1)])  # untimed: one frame on
            if self.fps is None:
                self.fps = _check_rate(1.0 / self._step, self.path, early[1][2])
            for k, (joints, _, _) in enumerate(early):
                if k:
                    self._pending.extend(np.full_like(joints, np.nan) for _ in range(grid[k] - grid[k - 1] - 1))
                self._pending.append(joints)
            self._last = (times[-1] + (len(early) - timed) * self._step, early[-1][2])
            self._pending = [self._convert(j) for j in self._pending]
            return
        if self.fps is None:
            raise ConfigError("no frame rate" + (": the input ended before a second frame" if self._timed else
                              ": no time on the frames"), file=self.path, expected=_FPS_EXPECTED)
        if self._timed:  # one frame with a time: the step will be the given rate's
            self._step, self._last = 1.0 / self.fps, (times[0], early[0][2])
        self._pending = [self._convert(j) for j, _, _ in early]

    def _grid(self, times: np.ndarray, lines: list[int]) -> tuple[np.ndarray, float]:
        """:func:`~toolkit.recordings.csv_positions.frame_grid` of the first frames' times, an error naming the line."""
        try:
            return frame_grid(times)
        except _OffGrid as err:
            expected = {"back": "increasing times", "off": "steps of whole frames", "sparse": "fewer dropped frames "
                        "among the first frames than frames"}[err.kind]
            raise ConfigError(err.problem, file=self.path, line=lines[err.row], expected=expected) from None

    def _placed(self, joints: np.ndarray, time: float | None, line: int) -> list[np.ndarray]:
        """A frame after the first ones: preceded by a frame with nothing visible for each frame its time shows
        dropped (a frame without a time follows the one before)."""
        if self._step is None:
            return [joints]
        if self._last is None:  # the first frame (the rate given): the grid starts at its time
            if time is not None:
                self._last = (time, line)
            return [joints]
        last, _ = self._last
        if time is None:  # no time on this frame: the next one
            self._last = (last + self._step, line)
            return [joints]
        if not time > last:
            raise ConfigError(f"time {time:.9g} s does not increase from {last:.9g} s", file=self.path, line=line,
                              expected="increasing times")
        frames = (time - last) / self._step
        count = round(frames)
        if count < 1 or abs(frames - count) > TIME_TOLERANCE:
            raise ConfigError(f"irregular timing: a step of {time - last:.6g} s from the frame before is {frames:.3g} "
                              f"frames", file=self.path, line=line,
                              expected=f"steps of whole frames of {self._step:.6g} s (one, or more where frames were "
                                       f"dropped) within {TIME_TOLERANCE:.0%} of a frame")
        if time - last > MAX_GAP + self._step:
            raise ConfigError(f"a gap of {time - last:.6g} s between frames", file=self.path, line=line,
                              expected=f"at most {MAX_GAP:g} s of dropped frames")
        self._last = (time, line)
        return [np.full_like(joints, np.nan)] * (count - 1) + [joints]

    # -- lines ---------------------------------------------------------------------------------------

    def _next_text(self) -> str | None:
        """The next line that is not blank (without its line break), or None at the end of the input."""
        while True:
            raw = self.lines.readline()
            if not raw:
                return None
            self.line += 1
            if len(raw) > MAX_LINE_CHARS and not raw.endswith(b"\n"):
                raise ConfigError(f"line longer than {MAX_LINE_CHARS} characters", file=self.path, line=self.line,
                                  column=1, expected="one frame per line")
            text = raw.decode("utf-8", errors="replace").rstrip("\r\n")
            if self.line == 1:
                text = text.removeprefix("\ufeff")
            if text.strip():
                return text

    def _next_frame(self) -> tuple[np.ndarray, float | None, int] | None:
        """The next frame's source joint positions (J, 3) in the profile's joint order, its time (None: none) and
        its line, or None at the end."""
        text = self._next_text()
        if text is None:
            return None
        if self.kind == "json":
            joints, time, _ = self._json(text)
            return joints, time, self.line
        joints, time = self._csv(text)
        return joints, time, self.line

    def _checked_time(self, value: float) -> float:
        if not math.isfinite(value):
            raise ConfigError(f"time {value}", file=self.path, line=self.line, expected="a finite time in seconds")
        return value

    def _csv(self, text: str) -> tuple[np.ndarray, float | None]:
        layout = self._layout
        columns = layout.columns + ((layout.time,) if layout.time is not None else ())
        values = parse_rows([text], [self.line], layout, columns)[0]
        time = None
        if layout.time is not None:
            time = self._checked_time(float(values[-1]))
            values = values[:-1]
        joints = values.reshape(-1, 3)
        order = [list(layout.joints).index(j) for j in self.profile.joints]
        out = np.full((len(self.profile.joints), 3), np.nan)
        out[:] = joints[order]
        return out, time

    def _json(self, text: str) -> tuple[np.ndarray, float | None, list[str]]:
        try:
            frame = json.loads(text, parse_int=_integer)
        except json.JSONDecodeError as exc:
            raise ConfigError(f"not JSON ({exc.msg})", file=self.path, line=self.line, column=exc.colno,
                              expected='one JSON object per line, {"JOINT": [x, y, z], ...}') from None
        except RecursionError:
            raise ConfigError("JSON nested too deeply", file=self.path, line=self.line,
                              expected='one JSON object per line, {"JOINT": [x, y, z], ...}') from None
        if not isinstance(frame, dict):
            raise ConfigError(f"a JSON {type(frame).__name__}, not an object", file=self.path, line=self.line,
                              expected='one JSON object per line, {"JOINT": [x, y, z], ...}')
        time = None
        if "time" in frame:
            t = frame["time"]
            if isinstance(t, bool) or not isinstance(t, int | float):
                raise ConfigError(f"time {t!r}", file=self.path, line=self.line, key=("time",),
                                  expected="a time in seconds")
            time = self._checked_time(float(t))
        elif self._timed is None and self.fps is None and self.line > 1:
            raise ConfigError("no time", file=self.path, line=self.line, key=("time",),
                              expected="a time on every frame while the rate is measured from them")
        out = np.full((len(self.profile.joints), 3), np.nan)
        for k, joint in enumerate(self.profile.joints):
            value = frame.get(joint)
            if value is None:
                continue
            if not (isinstance(value, list) and len(value) == 3 and
                    all(v is None or (isinstance(v, int | float) and not isinstance(v, bool)) for v in value)):
                raise ConfigError(f"joint {joint!r} is {value!r}", file=self.path, line=self.line, key=(joint,),
                                  expected="[x, y, z] numbers (null for a missing value), or null")
            out[k] = [np.nan if v is None else float(v) for v in value]
        return out, time, list(frame)

    # -- frames --------------------------------------------------------------------------------------

    def _convert(self, joints: np.ndarray) -> np.ndarray:
        joints = np.where(np.isfinite(joints), joints, np.nan)
        return self.profile.convert(joints[None], self.profile.joints)[0]

    def _more(self) -> list[np.ndarray] | None:
        """The frames the next line gives (with the frames its time shows dropped), or None at the end."""
        frame = self._next_frame()
        if frame is None:
            return None
        joints, time, line = frame
        return [self._convert(j) for j in self._placed(joints, time, line)]

    def __iter__(self) -> Iterator[np.ndarray]:
        for block in self.blocks(1):
            yield from block

    def blocks(self, most: int = BLOCK_FRAMES) -> Iterator[np.ndarray]:
        """The frames as they arrive, (n, P, 3) at a time: the next frame (waiting for it), with every frame that
        has arrived behind it, up to ``most`` (a frame's dropped frames always with it)."""
        while True:
            frames, self._pending = self._pending, []
            if not frames:
                more = self._more()
                if more is None:
                    return
                frames = more
            while len(frames) < most and self.lines.ready():
                more = self._more()
                if more is None:
                    break
                frames.extend(more)
            yield np.stack(frames)


def _integer(text: str) -> int | float:
    """A JSON integer, bounded: one of more than 18 digits is read as a float (a coordinate of 400 or 5,000 digits
    is then infinite: not seen on that frame; such a time an error naming the line), never Python's ``ValueError``
    for 4,300 digits or an ``OverflowError`` later."""
    return int(text) if len(text) <= 18 else float(text)


def _check_rate(rate: float, path: Path, line: int | None) -> float:
    if not MIN_FPS <= rate <= MAX_FPS:
        raise ConfigError(f"a frame rate of {rate:g} frames per second", file=path, line=line,
                          expected=f"a frame rate in {FPS_RANGE} Hz")
    return rate
