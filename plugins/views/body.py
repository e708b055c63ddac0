"""View ``body``: a character's colour-coded body in its hub pose and a strip of key poses per movement.

Buchsbaum & Blumberg 2005, §4.2 and Fig. 2-3: each tracked body part is a sphere
in its own colour, the root node is marked (a black ring), bones join the
parts. Below the hub pose, every movement of the repertoire is a row of
``keys`` poses sampled evenly over the movement as the motor system performs
it, labelled with the movement's name. Everything is in the character's own
frame (it faces +z), seen from the front.

The floor is found, not assumed: a recording in a camera's frame (a Kinect's feet
1.1 m below its origin, MediaPipe's origin between the hips) stands on the floor
its feet are found on (:func:`floor_height`), so the body is drawn whole.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from plugins.lib.rendering import MAX_PIXELS, poses_png
from toolkit import ConfigError, Parameter, View, hookimpl

__all__ = ["BodyView", "Sheet", "body_frame", "floor_height", "key_pose_strip", "on_floor"]

FLOOR_PERCENTILE = 5.0
"""The floor is the height of a body's lowest part in the frames where it is lowest, less the few frames (this
percentile) where a part is tracked below it (a foot's glitch)."""


def floor_height(positions: np.ndarray, visible: np.ndarray | None = None) -> float:
    """The height (y) of the floor a body stands on in a motion (F, P, 3): the :data:`FLOOR_PERCENTILE` percentile
    over the frames of its lowest part seen; 0.0 when no part is ever seen. Found, not assumed: a camera's frame
    puts the floor wherever the camera was."""
    y = np.asarray(positions, dtype=float)[..., 1]
    seen = np.isfinite(y) if visible is None else np.asarray(visible, dtype=bool) & np.isfinite(y)
    lowest = np.where(seen, y, np.inf).min(axis=-1)
    lowest = lowest[np.isfinite(lowest)]
    return float(np.percentile(lowest, FLOOR_PERCENTILE)) if len(lowest) else 0.0


def on_floor(positions: np.ndarray, visible: np.ndarray | None = None) -> np.ndarray:
    """A motion's positions (F, P, 3) moved up or down so that its floor (:func:`floor_height`) is ``y = 0``."""
    positions = np.array(positions, dtype=float)
    positions[..., 1] -= floor_height(positions, visible)
    return positions


def key_pose_strip(motion_positions: np.ndarray, keys: int, root: int) -> np.ndarray:
    """``keys`` poses sampled evenly from a motion (F, P, 3), each moved so its root is over the origin (x, z)."""
    frames = np.linspace(0, len(motion_positions) - 1, keys).round().astype(int)
    poses = motion_positions[frames].copy()
    poses[..., [0, 2]] -= poses[:, root : root + 1, [0, 2]]
    return poses


def body_frame(motion: Any, body: Any) -> np.ndarray:
    """A recording's world positions (F, P, 3) turned, frame by frame, to face +z about its root (the facing found
    from the body's facing parts, smoothed over the recording, as perceptions find it), heights above the floor
    found in the recording (:func:`floor_height`); hidden parts NaN."""
    from plugins.lib.root_frame import RecordingFacing, root_relative

    window = max(1, int(round(motion.fps)))  # one second
    poses, visible, root, _ = root_relative(motion.positions, motion.visible, body, RecordingFacing(window))
    floor = floor_height(motion.positions, motion.visible)
    poses = poses + np.array([0.0, 1.0, 0.0]) * (root[:, None, 1:2] - floor)  # back to the root's height above it
    return np.where(visible[..., None], poses, np.nan)


@dataclass
class Sheet:
    """What :class:`BodyView` draws, as numbers: the poses (N, P, 3) placed on the sheet, the labels and the points
    they are written at, and the rectangle ``lower``..``upper`` (x, y) the picture frames."""

    poses: np.ndarray
    points: np.ndarray
    labels: list[str]
    lower: tuple[float, float]
    upper: tuple[float, float]
    height: float


class BodyView(View):
    """The body in its hub pose, parts in their colours, root marked; each movement as a strip of key poses."""

    name = "body"
    parameters = (
        Parameter("keys", int, 6, "Key poses shown per movement.", minimum=1, maximum=30),
        Parameter("movements", list, [], "Movements to show (default: all of the repertoire)."),
        Parameter("columns", int, 0, "Columns of movement strips (0: one per 12 movements).", minimum=0),
        Parameter("width", int, 1600, "Image width in pixels.", minimum=64, maximum=MAX_PIXELS),
        Parameter("height", int, 0, "Image height in pixels (0: from the number of rows).", minimum=0,
                  maximum=MAX_PIXELS),
        Parameter("fps", float, 30.0, "Frame rate the movements are performed at before sampling.", minimum=1.0),
    )

    recordings = "all"
    """``likeme show --body PROFILE FILE ...`` draws the recordings' key poses in one picture, a row each."""

    def draw(self, subject: Any, out: Path, recordings: Any = None) -> list[Path]:
        """Draw ``subject``'s hub pose and a strip of key poses per movement of its repertoire, or per recording of
        ``recordings`` (:func:`~plugins.views.demonstration.recording` each) when given, to the PNG file ``out``."""
        sheet = self.layout(subject, recordings)
        width = self.params["width"]
        (x0, y0), (x1, y1) = sheet.lower, sheet.upper
        size = (width, self.params["height"] or int(width * (y1 - y0) / (x1 - x0)))
        n_rows = max(1, len(sheet.labels) - 1)
        return [poses_png(out, subject.body, sheet.poses, sheet.points, sheet.labels, lower=sheet.lower,
                          upper=sheet.upper, size=size, radius=max(sheet.height / 28.0, 0.006),
                          font_size=max(10, min(20, int(size[1] / (n_rows + 2) / 5))), align="right")]

    def layout(self, subject: Any, recordings: Any = None) -> Sheet:
        """The sheet :meth:`draw` renders: every pose standing on the floor found for it (:func:`floor_height`: the
        hub pose's lowest part, each movement's or recording's), rows as tall as the tallest body drawn."""
        character = subject
        body, motor = character.body, character.motor
        if recordings:
            rows = [(f"{demo.who}  {demo.motion.duration:.2f} s", body_frame(demo.motion, body)) for demo in recordings]
        else:
            movements = list(self.params["movements"]) or sorted(motor.movements())
            unknown = [m for m in movements if m not in motor.movements()]
            if unknown:
                raise ConfigError(f"unknown movement {unknown[0]!r}", key=("movements",), expected="a movement of "
                                  f"{character.name}", available=sorted(motor.movements()))
            rows = []
            for movement in movements:
                motion = motor.perform(movement, fps=self.params["fps"])
                rows.append((f"{motor.label(movement)}  {motion.duration:.2f} s", on_floor(motion.positions)))
        rest = np.asarray(motor.rest_pose(), dtype=float)
        extent = np.ptp(rest[np.isfinite(rest).all(axis=1)], axis=0)
        tops = [float(np.nanmedian(np.nanmax(p[..., 1], axis=1))) for _, p in rows
                if np.isfinite(p[..., 1]).any(axis=1).any()]  # a recorded body may be taller than the rest pose
        height = max([float(extent[1]), 0.2, *tops])
        cell = max(float(extent[0]), float(extent[2]), height * 0.5) * 1.5  # one pose's width in the strip
        row = height * 1.6
        keys = self.params["keys"]
        columns = self.params["columns"] or max(1, int(np.ceil(len(rows) / 12)))
        n_rows = int(np.ceil(len(rows) / columns))
        label_width = cell * 3.2
        strip = label_width + keys * cell + cell * 0.5
        root = body.root_index
        poses, labels, points = [], [], []
        hub = rest.copy()
        hub[:, [0, 2]] -= hub[root, [0, 2]]
        hub[:, 1] -= np.nanmin(hub[:, 1]) if np.isfinite(hub[:, 1]).any() else 0.0  # one pose: its lowest part
        top = (columns * strip) / 2
        poses.append(hub * 1.4 + np.array([top, row * 0.1, 0.0]))
        labels.append(f"{character.name}: hub pose")
        points.append([top, row * 0.1 + height * 1.55, 0.0])
        for i, (label, positions) in enumerate(rows):
            c, r = divmod(i, n_rows)
            y = -(r + 1) * row - height * 0.3
            x = c * strip + label_width
            for k, pose in enumerate(key_pose_strip(positions, keys, root)):
                poses.append(pose + np.array([x + (k + 0.5) * cell, y, 0.0]))
            labels.append(label)
            points.append([x - cell * 0.1, y + height * 0.5, 0.0])
        lower = (0.0, -n_rows * row - height * 0.5)  # the feet of the last row, and a margin
        upper = (columns * strip, row * 0.1 + height * 1.8)
        return Sheet(np.stack(poses), np.array(points), labels, lower, upper, height)


@hookimpl
def likeme_register_views():
    return [BodyView]
