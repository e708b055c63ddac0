"""View ``correspondence``: a recorded demonstrator as perceived and as mapped onto the observer's own body.

Buchsbaum & Blumberg 2005, §7.1 and Kopp & Graeser 2006, §6 leave the correspondence problem open: another body has
its own size, stance and rest posture. This view shows what the observer's correspondence stage
(``[correspondence]``, docs/correspondence.md) makes of a recording: the top row is the demonstrator's root-relative
poses as perceived (§5.1), the bottom row the same frames after the mapping, which is what the segmenter and the
matcher compare with the observer's own repertoire. The first column holds, above, the demonstrator's rest posture
as the correspondence estimated it at the end of the recording and, below, the observer's own hub pose.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from plugins.lib.rendering import MAX_PIXELS, poses_png
from toolkit import ConfigError, Parameter, View, hookimpl

__all__ = ["CorrespondenceView"]


class CorrespondenceView(View):
    """A recording's poses as perceived and as mapped onto the observer's body, with both rest postures."""

    name = "correspondence"
    parameters = (
        Parameter("recording", str, doc="The recording to watch (a BVH file read through the observer's body "
                  "profile)."),
        Parameter("profile", str, "", "Body profile of the recording (default: the one the observer's repertoire "
                  "was read with)."),
        Parameter("poses", int, 6, "Frames shown, evenly over the recording.", minimum=1, maximum=30),
        Parameter("seen_from", str, "side", "Where the bodies are seen from: the side (a bow, a lean show) or the "
                  "front (a stance, the arms' spread show).", choices=("side", "front")),
        Parameter("width", int, 1600, "Image width in pixels.", minimum=64, maximum=MAX_PIXELS),
    )

    def draw(self, subject: Any, out: Path) -> list[Path]:
        from toolkit.observe import Observer
        from toolkit.recordings.profile import load_profile

        character = subject
        if character.correspondence is None:
            raise ConfigError(f"{character.name} has no correspondence", key=("correspondence",),
                              expected="an observer with a [correspondence] (likeme show ... --correspondence NAME)")
        # the profile the observer's clips were read with (given to it when it was composed, never found again from
        # a path), unless the view is told another
        profile = load_profile(self.params["profile"]) if self.params["profile"] else \
            getattr(character.repertoire, "profile", None)
        if profile is None:
            raise ConfigError("no body profile for the recording", key=("profile",),
                              expected="--set profile=PROFILE.toml, or an observer composed with --body")
        motion = profile.read(self.params["recording"])
        observer = Observer(character, profile.body, motion.fps)
        observer.watch(motion)
        loop = observer.loop
        perceived, mapped = loop.perceived.positions, loop.memory.positions
        state = character.correspondence.inspect()
        body = character.body
        hub = np.asarray(character.motor.rest_pose(), dtype=float)
        hub = hub - hub[body.root_index]
        rest = np.asarray(state.get("rest", hub), dtype=float)
        frames = np.linspace(0, len(perceived) - 1, self.params["poses"]).round().astype(int)
        height = max(float(np.ptp(hub[np.isfinite(hub).all(axis=1), 1])), 0.2)
        cell, row = height * 0.9, height * 1.5
        poses, points, labels = [], [], []
        for r, (first, sequence, title) in enumerate(((rest, perceived, "as perceived"),
                                                       (hub, mapped, f"mapped onto {character.name}"))):
            y = -r * row
            for c, pose in enumerate([first, *sequence[frames]]):  # every pose drawn with its root at its place
                pose = np.nan_to_num(pose - pose[body.root_index])
                if self.params["seen_from"] == "side":  # facing +z, seen from its left: forward is to the right
                    pose = pose[:, [2, 1, 0]] * np.array([1.0, 1.0, -1.0])
                poses.append(pose + np.array([(c + 0.5) * cell * (1.4 if c else 1.0), y, 0.0]))
            points.append([0.0, y + height * 0.75, 0.0])
            labels.append(("their rest" if r == 0 else "own hub") + f"   {title}")
        times = [f"{f / motion.fps:.1f} s" for f in frames]
        for c, text in enumerate(times, 1):
            points.append([(c + 0.5) * cell * 1.4, -row - height * 0.8, 0.0])
            labels.append(text)
        width = self.params["width"]
        lower, upper = (-cell * 0.3, -row - height), ((len(frames) + 1.2) * cell * 1.4, height * 0.9)
        size = (width, int(width * (upper[1] - lower[1]) / (upper[0] - lower[0])))
        return [poses_png(out, body, np.stack(poses), np.array(points), labels, lower=lower, upper=upper, size=size,
                          radius=height / 40.0, font_size=max(10, min(18, size[1] // 30)))]


@hookimpl
def likeme_register_views():
    return [CorrespondenceView]
