"""View ``speed-profile``: the wrist speed with break points and direction clusters (Kopp & Graeser 2006, §4.3).

Kopp & Graeser 2006, §4.1 and §4.3: the sensory memory finds each movement's
onset and end; the working memory of the movement is cut at speed minima that
fall well below their neighbouring maxima, and where successive movement
vectors fall into different direction clusters (divisive clustering) at a
sharp turn. The view has the demonstrator perform movements with rests between
them, lets the character watch them with its own ``velocity-direction``
segmenter (and its matcher), and plots:

- the movements really performed and the segments found (with what the
  matcher recognised and when it committed);
- the speed of the fastest chosen part between frames (grey, the whole
  stream), the rest speed of the sensory memory, and inside each movement the
  smoothed speed the working memory is cut on, its points coloured by direction
  cluster; speed break points as solid lines, direction break points dashed,
  the breaks kept marked with a triangle;
- the chosen parts' trajectories in the frontal plane, coloured by direction
  cluster, with the breaks kept as black dots.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from plugins.views.demonstration import require, watch
from plugins.views.plotting import DEMONSTRATION, PALETTE, blank, demonstrate, save_figure, timeline
from toolkit import View, hookimpl

__all__ = ["SpeedProfileView"]


TRAJECTORIES = 3
"""At most this many parts get a trajectory panel: those that travel most."""


class SpeedProfileView(View):
    """Speed of the chosen parts, break points and direction clusters over a demonstration (K&G 2006, §4.3)."""

    name = "speed-profile"
    parameters = DEMONSTRATION
    needs = {"segmenter": "velocity-direction"}
    """What the character must have; ``likeme show --body PROFILE FILE`` composes an observer with it."""
    recordings = "each"
    """``likeme show --body PROFILE FILE ...`` draws one picture per recording (``draw(..., recording=...)``)."""

    def draw(self, subject: Any, out: Path, recording: Any = None) -> list[Path]:
        """Draw ``subject`` watching a demonstration (the parameters') or ``recording`` (a
        :func:`~plugins.views.demonstration.recording`) to the PNG file ``out``."""
        from matplotlib.ticker import MaxNLocator

        character = subject
        segmenter = require(character, "segmenter", "velocity-direction")
        demo = demonstrate(self, character, recording)
        analysed: dict[tuple[int, int], object] = {}  # each movement the working memory closed, once

        def keep(_observation: object) -> None:
            signals = segmenter.inspect()
            if signals:
                analysed.setdefault(signals["movement"], signals["analysis"])

        observer, found = watch(character, demo, each=keep)
        movements = [(start, end, analysis) for (start, end), analysis in analysed.items()]
        fps = observer.fps
        chosen = segmenter.params["parts"] or list(character.body.parts)
        idx = [character.body.parts.index(p) for p in chosen]
        scale = np.where(character.body.angle_mask[idx], segmenter.params["angle_scale"], 1.0)  # fingers: rad -> m
        poses = np.where(np.array(observer.visible)[:, idx, None], np.array(observer.poses)[:, idx], np.nan)
        poses = poses * scale[:, None]
        speed = np.nanmax(np.linalg.norm(np.diff(poses, axis=0), axis=2), axis=1) * fps if len(poses) > 1 else np.zeros(0)
        placed = [j for j, i in enumerate(idx) if not character.body.angle_mask[i]]  # parts with a trajectory in space
        if len(placed) > TRAJECTORIES:  # the parts that travel most (all of a recording's joints would not fit)
            travel = np.nansum(np.linalg.norm(np.diff(poses[:, placed], axis=0), axis=2), axis=0)
            placed = sorted(placed[j] for j in np.argsort(-travel, kind="stable")[:TRAJECTORIES])

        fig = blank(self.params["width"], self.params["height"])
        k = len(placed)  # the left three quarters: the timeline and the speed; the right quarter: one trajectory per part
        left, right = fig.subfigures(1, 2, width_ratios=[3, 1]) if k else (fig, None)
        top, ax = left.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [1, 4]})
        trajectory_axes = list(np.atleast_1d(right.subplots(k, 1))) if k else []
        timeline(top, demo, found, fps, recognised=character.matcher is not None)
        top.tick_params(axis="x", labelbottom=False)
        t = (np.arange(len(speed)) + 0.5) / fps
        ax.plot(t, speed, color="#b0b0b0", lw=0.8, label="speed of the fastest part (frame to frame)")
        ax.axhline(segmenter.params["rest_speed"], color="#909090", ls=":", lw=1.2,
                   label=f"rest speed {segmenter.params['rest_speed']:g} m/s (sensory memory)")
        n_speed = n_direction = n_kept = 0
        for start, end, analysis in movements:
            ts = (start + np.arange(len(analysis.speed)) + 0.5) / fps
            ax.plot(ts, analysis.speed, color="black", lw=1.0)
            ok = analysis.clusters >= 0
            ax.scatter(ts[ok], analysis.speed[ok], s=9, zorder=3,
                       c=[PALETTE[c % len(PALETTE)] for c in analysis.clusters[ok]])
            for b in analysis.speed_breaks:
                ax.axvline((start + b) / fps, color="#e6194b", lw=1.0)
            for b in analysis.direction_breaks:
                ax.axvline((start + b) / fps, color="#4363d8", lw=1.0, ls="--")
            kept = np.array(analysis.breaks, dtype=int)
            ax.scatter((start + kept) / fps, analysis.speed[np.clip(kept - 1, 0, len(analysis.speed) - 1)],
                       marker="v", s=70, color="black", zorder=4)
            n_speed, n_direction, n_kept = n_speed + len(analysis.speed_breaks), n_direction + len(
                analysis.direction_breaks), n_kept + len(kept)
            window = analysis.window.reshape(len(analysis.window), -1, 3)
            for j, tax in zip(placed, trajectory_axes):
                xy = window[:, j, :2]
                for c in np.unique(analysis.clusters):
                    sel = np.flatnonzero(analysis.clusters == c)
                    tax.scatter(xy[sel + 1, 0], xy[sel + 1, 1], s=5,
                                color=PALETTE[c % len(PALETTE)] if c >= 0 else "#b0b0b0")
                tax.scatter(xy[kept, 0], xy[kept, 1], s=30, color="black", zorder=3)
        for j, tax in zip(placed, trajectory_axes):
            tax.ticklabel_format(useOffset=False)
            x0, x1 = tax.get_xlim()
            y0, y1 = tax.get_ylim()
            if max(x1 - x0, y1 - y0) < 0.05:  # a part that hardly moved: show 10 cm around it
                tax.set_xlim((x0 + x1) / 2 - 0.05, (x0 + x1) / 2 + 0.05)
                tax.set_ylim((y0 + y1) / 2 - 0.05, (y0 + y1) / 2 + 0.05)
            tax.set_aspect("equal", adjustable="box")
            tax.set_title(f"{chosen[j]}: x, y (m)", fontsize=8)
            tax.tick_params(labelsize=7)
            tax.xaxis.set_major_locator(MaxNLocator(nbins=2))  # a narrow panel: few ticks, none overlapping
        ax.plot([], [], color="#e6194b", label=f"speed break points ({n_speed})")
        ax.plot([], [], color="#4363d8", ls="--", label=f"direction break points ({n_direction})")
        ax.scatter([], [], marker="v", color="black", label=f"breaks kept ({n_kept})")
        ax.set_xlabel("time (s)")
        fingers = int(character.body.angle_mask[idx].sum())
        ax.set_ylabel("speed (m/s; fingers: rad/s x angle_scale)" if fingers else "speed (m/s)")
        ax.set_xlim(0, demo.motion.duration)
        ax.set_ylim(bottom=0)
        ax.legend(loc="upper right", fontsize=8)
        watched = (", ".join(chosen[j] for j in placed) if len(chosen) - fingers <= TRAJECTORIES else
                   f"{len(chosen) - fingers} parts") + (f" and {fingers} fingers" if fingers else "")
        ax.set_title(f"{character.name} watching {watched}: {len(movements)} movement(s) in working memory, "
                     f"points coloured by direction cluster", fontsize=10, loc="left")
        return [save_figure(fig, out)]


@hookimpl
def likeme_register_views():
    return [SpeedProfileView]
