"""A tracker's jitter on the recordings a benchmark reads (``likeme bench recognition|segmentation|stream --jitter
M``).

A marker-based capture places a joint within a millimetre or so; a depth camera's skeleton tracker (a Kinect's 20
joints at 30 frames a second, say) within a centimetre or more, from frame to frame. The benchmarks read every
recording whole (:meth:`BodyProfile.read <toolkit.recordings.profile.BodyProfile.read>`): the repertoire's clips
the observer is composed from, the demos and the streams. :class:`Jittered` reads them through the same profile
and adds independent Gaussian noise of ``jitter`` metres to every coordinate of every joint seen in every frame,
the simplest model of a tracker's frame-to-frame noise, so that any recording can be watched as a tracker would
have given it: what each segmenter and matcher loses to it is then measured on the same takes.

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

__all__ = ["Jittered", "jittered"]


@dataclasses.dataclass(frozen=True)
class Jittered(BodyProfile):
    """A body profile whose :meth:`read` adds a tracker's jitter: ``jitter`` metres (the standard deviation of
    each coordinate's independent Gaussian noise), drawn from ``seed`` and the file's and its folder's names."""

    jitter: float = 0.0
    seed: int = 0

    def read(self, path: str | Path, fps: float | None = None) -> Motion:
        motion = super().read(path, fps)
        path = Path(path)
        name = f"{path.parent.name}/{path.name}"  # a repertoire's clips share names across movements' folders
        rng = np.random.default_rng([self.seed, zlib.crc32(name.encode("utf-8"))])
        noise = rng.normal(0.0, self.jitter, motion.positions.shape)
        return Motion(motion.positions + noise, motion.fps, motion.parts)  # a part not seen stays NaN


def jittered(profile: BodyProfile, jitter: float, seed: int = 0) -> BodyProfile:
    """``profile`` reading with ``jitter`` metres of a tracker's noise (``profile`` itself for 0)."""
    if not jitter:
        return profile
    fields = {f.name: getattr(profile, f.name) for f in dataclasses.fields(BodyProfile)}
    return Jittered(**fields, jitter=float(jitter), seed=int(seed))
