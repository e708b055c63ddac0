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
``fps``), else the step between the first two frames' times.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from toolkit.errors import ConfigError
from toolkit.recordings.csv_positions import MAX_LINE_CHARS, parse_header, parse_rows
from toolkit.recordings.recording import FPS_RANGE, MAX_FPS, MIN_FPS

__all__ = ["LiveInput", "SOURCE"]

SOURCE = "-"
"""How standard input is named, on the command line and in messages."""

_FPS_EXPECTED = "a frame rate: --fps, `fps` in the profile's [profile] table, or a time on the first two frames"


class _Header:
    """What :meth:`BodyProfile.check` needs: the joint names of the input and its name."""

    def __init__(self, names: list[str]) -> None:
        self.names, self.source = names, "standard input"


class LiveInput:
    """Frames of joint positions read from a binary stream a line at a time, through a body profile.

    The first frame (two with the rate from a time field) is read when the input is made, so :attr:`fps` and the
    joints are known and checked before any frame is given out. Iterating yields each frame's part positions,
    shape (P, 3), in metres with +y up, NaN where a value is missing, as soon as its line is read.

    Parameters
    ----------
    stream : binary file
        Standard input (``sys.stdin.buffer``) or any stream of UTF-8 lines.
    profile : BodyProfile
        Maps the input's joints to parts.
    fps : float, optional
        The frame rate; without it, from the time field of the first two frames.
    """

    def __init__(self, stream: BinaryIO, profile: Any, fps: float | None = None) -> None:
        self.stream, self.profile, self.line = stream, profile, 0
        self.path = Path(SOURCE)
        self.kind = ""
        self._layout = None
        self._times: list[float] = []
        self._pending: list[np.ndarray] = []
        self.fps = None if fps is None else _check_rate(float(fps), self.path, None)
        first = self._next_text()
        if first is None:
            raise ConfigError("no input", file=self.path, expected="a CSV header line or JSON lines, one per frame")
        if first.lstrip().startswith("{"):
            self.kind = "json"
            positions, seen_keys = self._json(first)
            names = [k for k in seen_keys if k != "time"]
            profile.check(_Header(names))  # the first frame names every mapped joint (null when not seen)
            self.profile = profile.for_names(names, self.path)  # each part's alias the input uses
            if self.profile.joints != profile.joints:  # the first frame again, by those names
                self._times.clear()
                positions = self._json(first)[0]
            self._pending.append(positions)
        else:
            self.kind = "csv"
            self._layout = parse_header(first + "\n", self.path, None)
            self.profile = profile.for_names(list(self._layout.joints), self.path)  # aliases chosen once
        if self.fps is None:
            while len(self._pending) < 2:
                frame = self._next_frame()
                if frame is None:
                    break
                self._pending.append(frame)
            if len(self._times) < 2:
                raise ConfigError("no frame rate" + (": the input ended before a second frame" if self._times else
                                  ": no time on the frames"), file=self.path, expected=_FPS_EXPECTED)
            self.fps = _check_rate(1.0 / (self._times[1] - self._times[0]), self.path, self.line)

    # -- lines ---------------------------------------------------------------------------------------

    def _next_text(self) -> str | None:
        """The next line that is not blank (without its line break), or None at the end of the input."""
        while True:
            raw = self.stream.readline(MAX_LINE_CHARS + 1)
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

    def _next_frame(self) -> np.ndarray | None:
        """The next frame's source joint positions (J, 3) in the profile's joint order, or None at the end."""
        text = self._next_text()
        if text is None:
            return None
        if self.kind == "json":
            return self._json(text)[0]
        return self._csv(text)

    def _time(self, value: float, column: int | None) -> None:
        """Keep a frame's time (the first two give the rate); times must be finite and increase."""
        if self.fps is not None and len(self._times) >= 2:
            return
        if not math.isfinite(value):
            raise ConfigError(f"time {value}", file=self.path, line=self.line, column=column,
                              expected="a finite time in seconds")
        if self._times and value <= self._times[-1]:
            raise ConfigError(f"time {value:.9g} s does not increase from {self._times[-1]:.9g} s", file=self.path,
                              line=self.line, column=column, expected="increasing times")
        self._times.append(value)

    def _csv(self, text: str) -> np.ndarray:
        layout = self._layout
        columns = layout.columns + ((layout.time,) if layout.time is not None else ())
        values = parse_rows([text], [self.line], layout, columns)[0]
        if layout.time is not None:
            self._time(float(values[-1]), None)
            values = values[:-1]
        joints = values.reshape(-1, 3)
        order = [list(layout.joints).index(j) for j in self.profile.joints]
        out = np.full((len(self.profile.joints), 3), np.nan)
        out[:] = joints[order]
        return out

    def _json(self, text: str) -> tuple[np.ndarray, list[str]]:
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
        if "time" in frame:
            t = frame["time"]
            if isinstance(t, bool) or not isinstance(t, int | float):
                raise ConfigError(f"time {t!r}", file=self.path, line=self.line, key=("time",),
                                  expected="a time in seconds")
            self._time(float(t), None)
        elif self._times and self.fps is None:
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
        return out, list(frame)

    # -- frames --------------------------------------------------------------------------------------

    def _convert(self, joints: np.ndarray) -> np.ndarray:
        joints = np.where(np.isfinite(joints), joints, np.nan)
        return self.profile.convert(joints[None], self.profile.joints)[0]

    def __iter__(self) -> Iterator[np.ndarray]:
        while self._pending:
            yield self._convert(self._pending.pop(0))
        while True:
            frame = self._next_frame()
            if frame is None:
                return
            yield self._convert(frame)


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
