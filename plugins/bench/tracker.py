"""A tracker's jitter and drop-outs on the recordings a benchmark reads (``likeme bench recognition|segmentation|stream
--jitter M --dropout S``).

A marker-based capture places a joint within a millimetre or so; a depth camera's skeleton tracker (a Kinect's 20
joints at 30 frames a second, say) within a centimetre or more, from frame to frame. The benchmarks read every
recording whole (:meth:`BodyProfile.read <toolkit.recordings.profile.BodyProfile.read>`): the repertoire's clips
the observer is composed from, the demos and the streams. :class:`Jittered` reads them through the same profile
and adds independent Gaussian noise of ``jitter`` metres to every coordinate of every joint seen in every frame,
the simplest model of a tracker's frame-to-frame noise; and it loses joints for a while (``dropout``: that share
of each joint's frames, in gaps of :data:`GAP` seconds, each joint on its own; a lost joint is not seen, NaN). Any
recording can so be watched as a tracker would have given it: what each segmenter and matcher loses to it is
measured on the same takes.

The noise of a file depends on its name, its folder's name and the seed only (not on where the data lies, which
process reads it, nor in what order), so a run with ``--jobs N`` gives the figures one process gives.
"""

from __future__ import annotations

import dataclasses
import zlib
from pathlib import Path

import numpy as np

from toolkit import Motion
from toolkit.recordings.profile import BodyProfile

__all__ = ["GAP", "Jittered", "jittered"]

GAP = (0.1, 0.33)
"""Seconds a lost joint stays lost (drawn evenly between the two): a few frames to a third of a second."""


@dataclasses.dataclass(frozen=True)
class Jittered(BodyProfile):
    """A body profile whose :meth:`read` adds a tracker's jitter, ``jitter`` metres (the standard deviation of
    each coordinate's independent Gaussian noise), and loses joints for ``dropout`` of their frames (in gaps of
    :data:`GAP` seconds), drawn from ``seed`` and the file's and its folder's names."""

    jitter: float = 0.0
    seed: int = 0
    dropout: float = 0.0

    def read(self, path: str | Path, fps: float | None = None) -> Motion:
        motion = super().read(path, fps)
        path = Path(path)
        name = f"{path.parent.name}/{path.name}"  # a repertoire's clips share names across movements' folders
        rng = np.random.default_rng([self.seed, zlib.crc32(name.encode("utf-8"))])
        positions = motion.positions + rng.normal(0.0, self.jitter, motion.positions.shape)  # NaN stays NaN
        n, parts = positions.shape[:2]
        if self.dropout > 0 and n:
            low, high = (max(1, int(round(g * motion.fps))) for g in GAP)
            target = int(round(self.dropout * n))
            for part in range(parts):
                lost, goal = 0, min(target, int(np.isfinite(positions[:, part, 0]).sum()))
                while lost < goal:  # gaps at random until the part's share of frames is lost (the last cut short)
                    start = int(rng.integers(n))
                    length = min(int(rng.integers(low, high + 1)), goal - lost)
                    lost += np.isfinite(positions[start : start + length, part, 0]).sum()
                    positions[start : start + length, part] = np.nan
        return Motion(positions, motion.fps, motion.parts)


def jittered(profile: BodyProfile, jitter: float, seed: int = 0, dropout: float = 0.0) -> BodyProfile:
    """``profile`` reading with ``jitter`` metres of a tracker's noise and ``dropout`` of each joint's frames lost
    (``profile`` itself for neither)."""
    if not jitter and not dropout:
        return profile
    fields = {f.name: getattr(profile, f.name) for f in dataclasses.fields(BodyProfile)}
    return Jittered(**fields, jitter=float(jitter), seed=int(seed), dropout=float(dropout))
