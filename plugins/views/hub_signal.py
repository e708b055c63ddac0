"""View ``hub-signal``: the distance-to-hub signal with its thresholds and the segments found (B&B 2005, Fig. 4).

Buchsbaum & Blumberg 2005, §5.1 and Fig. 4: the observer compares every
incoming frame with its own hub pose; a movement begins where the (low-pass
filtered) distance rises above a threshold and ends where it falls back. The
view has the demonstrator perform movements with rests between them, lets the
character watch them (``motion-capture`` perception, the character's own
``hub-threshold`` segmenter and its matcher), and plots, over time:

- the movements really performed and the segments found, each with what the
  matcher recognised and, for a matcher that commits early, when;
- the raw distance (thin), the level the thresholds apply to (the filtered
  distance minus its running minimum, thick), the start and end thresholds,
  and the segments found shaded.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from plugins.views.demonstration import require, watch
from plugins.views.plotting import DEMONSTRATION, demonstrate, figure, save_figure, timeline
from toolkit import Motion, View, hookimpl

__all__ = ["HubSignalView"]


class HubSignalView(View):
    """Distance to the hub over a demonstration, the thresholds and the segments found (B&B 2005, §5.1, Fig. 4)."""

    name = "hub-signal"
    parameters = DEMONSTRATION
    needs = {"segmenter": "hub-threshold"}
    """What the character must have; ``likeme show --body PROFILE FILE`` composes an observer with it."""
    recordings = "each"
    """``likeme show --body PROFILE FILE ...`` draws one picture per recording (``draw(..., recording=...)``)."""

    def draw(self, subject: Any, out: Path, recording: Any = None) -> list[Path]:
        """Draw ``subject`` watching a demonstration (the parameters') or ``recording`` (a
        :func:`~plugins.views.demonstration.recording`) to the PNG file ``out``."""
        character = subject
        segmenter = require(character, "segmenter", "hub-threshold")
        demo = demonstrate(self, character, recording)
        observer, found = watch(character, demo)
        fps = observer.fps
        seen = Motion(np.array(observer.poses), fps, character.body.parts, np.array(observer.visible))
        raw, filtered, level = segmenter.signal(seen)
        start, end = segmenter.thresholds
        t = seen.times
        fig, (top, ax) = figure(self.params["width"], self.params["height"], (1, 4))
        timeline(top, demo, found, fps, recognised=character.matcher is not None)
        for o in found:
            ax.axvspan(o.segment.start_time, o.segment.end_time, color="#d8d8d8", lw=0)
        ax.plot(t, raw, color="#9a9a9a", lw=0.8, label="distance to the nearest hub (eq. 1)")
        ax.plot(t, filtered, color="#4363d8", lw=1.0, ls=":", label="low-pass filtered")
        ax.plot(t, level, color="#4363d8", lw=2.0, label="level compared (filtered minus its floor)")
        ax.axhline(start, color="#e6194b", lw=1.2, label=f"start threshold {start:g}")
        ax.axhline(end, color="#e6194b", lw=1.2, ls="--", label=f"end threshold {end:g}")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("distance (m)")
        ax.set_xlim(0, t[-1] if len(t) else 1)
        ax.set_ylim(bottom=0)
        ax.legend(loc="upper right", fontsize=8)
        ax.set_title(f"{character.name} watching: distance to its hub pose, {len(found)} segment(s) found (grey)",
                     fontsize=10, loc="left")
        return [save_figure(fig, out)]


@hookimpl
def likeme_register_views():
    return [HubSignalView]
