"""View ``prediction-error``: each candidate edge's prediction error over time, and the moment of commitment.

Kopp & Graeser 2006, §4.4 and Fig. 3: when a demonstration begins, every edge
leaving the active node predicts it in parallel (its forward model); a
candidate whose prediction error passes the threshold drops out; when one is
left, Max imitates at once (response facilitation), and keeps comparing: if
the demonstration parts from the edge, he stops, returns to the last correct
node and learns the rest (true imitation). The view has the demonstrator
perform movements with rests between them, lets the character watch them with
its own segmenter and ``forward-model`` matcher (it learns as it watches, so
``movements = ["left_front", "left_side", "left_side"]`` replays the paper's
three imitation games), and plots:

- the movements really performed and the segments found, with what was
  recognised or learned and when Max committed;
- for every segment, the prediction error of every candidate command path at
  every frame (one colour per first command; a cross where it drops out), the
  threshold, the commitment as a vertical line with the share of the segment
  seen, and after it the committed edge's error against the deviation limit.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from plugins.views.demonstration import require, watch
from plugins.views.plotting import DEMONSTRATION, FREE_LABEL, PALETTE, demonstrate, figure, save_figure, timeline
from toolkit import View, hookimpl

__all__ = ["PredictionErrorView"]


class PredictionErrorView(View):
    """Prediction error of every candidate edge over a demonstration, drop-outs and commitment (K&G 2006, §4.4)."""

    name = "prediction-error"
    parameters = DEMONSTRATION
    needs = {"matcher": "forward-model"}
    """What the character must have; ``likeme show --body PROFILE FILE`` composes an observer with it."""
    recordings = "each"
    """``likeme show --body PROFILE FILE ...`` draws one picture per recording (``draw(..., recording=...)``)."""

    def draw(self, subject: Any, out: Path, recording: Any = None) -> list[Path]:
        """Draw ``subject`` watching a demonstration (the parameters') or ``recording`` (a
        :func:`~plugins.views.demonstration.recording`) to the PNG file ``out``."""
        character = subject
        matcher = require(character, "matcher", "forward-model")
        demo = demonstrate(self, character, recording)
        segments: list[dict[str, Any]] = []
        observer, found = watch(character, demo, each=lambda o: segments.append({"observation": o,
                                                                               **matcher.inspect()}))
        fps = observer.fps
        shown = matcher.inspect()  # the limits and what they measure: metres of the guiding strokes (the paper's
        # comparison) or a score relative to standing still (comparison = "motion")
        threshold, deviation, unit = shown["threshold"], shown["deviation"], shown["unit"]
        fig, (top, ax) = figure(self.params["width"], self.params["height"], (1, 4))
        timeline(top, demo, found, fps, recognised=character.matcher is not None)
        colour: dict[str, str] = {}
        highest = 2.0 * max(threshold, deviation)
        for seg in segments:
            o = seg["observation"]
            s = o.segment
            ax.axvspan(s.start_time, s.end_time, color="#f0f0f0", lw=0)
            committed = None if seg["committed_at"] is None else (s.start + seg["committed_at"] - 1) / fps
            ax.plot([s.start_time, committed or s.end_time], [threshold, threshold], color="#e6194b", lw=1.2)
            if committed is not None:
                ax.plot([committed, s.end_time], [deviation, deviation], color="#e6194b", ls="--", lw=1.2)
            series: dict[tuple[str, ...], list[tuple[float, float]]] = {}
            for frame, errors in seg["trace"]:
                for path, error in errors.items():
                    series.setdefault(path, []).append(((s.start + frame) / fps, error))
            for path, points in series.items():
                t, e = np.array(points).T
                c = colour.setdefault(path[0], PALETTE[len(colour) % len(PALETTE)])
                before = np.ones(len(t), dtype=bool)  # the committed path after the commitment: imitating
                if committed is not None and path == seg["committed_path"]:
                    before = t < committed
                ax.plot(t[before], e[before], color=c, lw=1.4)
                if not before.all():  # imitating: the committed path against the deviation limit
                    ax.plot(t[~before], e[~before], color=c, lw=3.0)
                limit = threshold if before[-1] else deviation
                if e[-1] > limit:  # dropped out (or deviated) here
                    ax.scatter([t[-1]], [e[-1]], marker="x", s=45, color=c, zorder=4)
                else:
                    ax.text(t[-1], e[-1], " " + ">".join(_short(p) for p in path), fontsize=7, color=c,
                            gid=FREE_LABEL,  # hidden where it would overlap another
                            va="center", clip_on=True)
                highest = max(highest, min(float(e.max()), 6.0 * threshold))
            if committed is not None:
                ax.axvline(committed, color="black", lw=1.5)
                share = seg["committed_at"] / s.n_frames
                ax.text(committed, 0.98, f" commits to {_short(seg['committed'])}\n at {share:.0%}", gid=FREE_LABEL,
                        zorder=4,
                        transform=ax.get_xaxis_transform(), fontsize=8, va="top")
            if seg["deviated_at"] is not None:
                ax.axvline((s.start + seg["deviated_at"] - 1) / fps, color="black", lw=1.5, ls=":")
            learned = o.match.details.get("learned") if o.match is not None else None
            if learned:
                why = "deviated: learns" if o.match.details.get("deviated") else "learns"
                ax.text((s.start_time + s.end_time) / 2, 0.8, f"{why}\n{', '.join(_short(n) for n in learned)}",
                        gid=FREE_LABEL, zorder=4,
                        transform=ax.get_xaxis_transform(), fontsize=8, ha="center", va="top", color="#404040")
        for name, c in colour.items():
            ax.plot([], [], color=c, label=f"candidate {_short(name)}")
        ax.plot([], [], color="#e6194b", label=f"threshold {threshold:.3g}{unit}")
        ax.plot([], [], color="#e6194b", ls="--", label=f"deviation limit {deviation:.3g}{unit} (while imitating, thick)")
        ax.plot([], [], color="black", label="commits (response facilitation)")
        ax.plot([], [], color="black", ls=":", label="deviates: stops imitating")
        ax.scatter([], [], marker="x", color="black", label="drops out / deviates")
        ax.set_ylim(0, highest * 1.5)
        ax.set_xlim(0, demo.motion.duration)
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"prediction error ({unit.strip()})" if unit.strip() else shown["measure"])
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, ncols=1 + len(colour) // 16)  # outside:
        # the commitments and drop-outs stay in view
        ax.set_title(f"{character.name} predicting with {shown['predicting']}: {len(found)} segment(s)",
                     fontsize=10, loc="left")
        return [save_figure(fig, out)]


def _short(name: str) -> str:
    """A command's name without its subsystem (``left_wrist:e3`` -> ``e3``)."""
    return name.split(":")[-1]


@hookimpl
def likeme_register_views():
    return [PredictionErrorView]
