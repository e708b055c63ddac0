"""Matplotlib scaffolding shared by the signal views: figures, the demonstration's timeline, atomic PNG files.

Not a component. Figures are :class:`matplotlib.figure.Figure` objects drawn on
the Agg canvas, never through ``pyplot``: no global figure registry, nothing
to close, no display. :func:`timeline` draws the strip every signal plot starts
with: the movements the demonstrator really performed, and the segments the
watcher found with what it recognised and when it decided.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from toolkit import Parameter

__all__ = ["DEMONSTRATION", "PALETTE", "blank", "figure", "save_figure", "timeline", "demonstrate"]

PALETTE = ("#4363d8", "#e6194b", "#3cb44b", "#f58231", "#911eb4", "#42d4f4", "#f032e6", "#9a6324", "#469990",
           "#800000", "#808000", "#000075")
"""Distinct colours for candidates, clusters and movements."""

DEMONSTRATION = (
    Parameter("movements", list, [], "Movements the demonstrator performs one after another (empty: every movement "
              "of its repertoire).", items=str),
    Parameter("demonstrator", str, "", "Character (file or name) who performs them (empty: the character itself)."),
    Parameter("speed", float, 1.0, "Speed of the performed movements.", minimum=0.05),
    Parameter("rest", float, 0.6, "Seconds of stillness before, between and after the movements.", minimum=0.0),
    Parameter("noise", float, 0.0, "Standard deviation (m) of Gaussian observation noise.", minimum=0.0),
    Parameter("seed", int, 0, "Seed of the noise."),
    Parameter("width", int, 1400, "Image width in pixels.", minimum=200),
    Parameter("height", int, 800, "Image height in pixels.", minimum=200),
)
"""The parameters every signal view shares: what is demonstrated, and the picture's size."""


def demonstrate(view: Any, character: Any) -> Any:
    """The :class:`~plugins.views.demonstration.Demonstration` a signal view's parameters ask for."""
    from plugins.views.demonstration import perform_sequence

    p = view.params
    return perform_sequence(character, p["demonstrator"], p["movements"], "movements", speed=p["speed"],
                            rest=p["rest"], noise=p["noise"], seed=p["seed"])


def blank(width: int, height: int) -> Any:
    """An empty figure of ``width`` x ``height`` pixels (constrained layout, Agg canvas)."""
    from matplotlib.figure import Figure

    dpi = 100
    return Figure(figsize=(width / dpi, height / dpi), dpi=dpi, layout="constrained")


def figure(width: int, height: int, rows: Sequence[float]) -> tuple[Any, list[Any]]:
    """A figure of ``width`` x ``height`` pixels with one axis per row (``rows``: relative heights), sharing x."""
    fig = blank(width, height)
    axes = fig.subplots(len(rows), 1, sharex=True, gridspec_kw={"height_ratios": list(rows)}, squeeze=False)[:, 0]
    return fig, list(axes)


def save_figure(fig: Any, out: str | Path) -> Path:
    """Write ``fig`` to ``out`` as PNG atomically (a temporary file in the same folder, then a rename)."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".png", dir=out.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, format="png")
        os.replace(tmp, out)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return out


def timeline(ax: Any, demo: Any, observations: Sequence[Any], fps: float) -> None:
    """The strip above a signal: true movements (top row) and found segments (bottom row) over time.

    Each found segment is labelled with what was recognised; a black tick marks the moment the matcher committed
    when it did so before the segment ended.
    """
    names = sorted({m for _, _, m in demo.truth})
    colour = {m: PALETTE[i % len(PALETTE)] for i, m in enumerate(names)}
    for start, end, movement in demo.truth:
        ax.axvspan(start / fps, end / fps, ymin=0.55, ymax=0.95, color=colour[movement], alpha=0.35, lw=0)
        ax.text((start + end) / 2 / fps, 0.75, movement, ha="center", va="center", fontsize=8, clip_on=True)
    for k, o in enumerate(observations):
        s = o.segment
        ax.axvspan(s.start_time, s.end_time, ymin=0.05, ymax=0.45, color="#606060" if k % 2 else "#909090",
                   alpha=0.5, lw=0)
        label = o.movement or "unknown"
        ax.text((s.start_time + s.end_time) / 2, 0.25, label, ha="center", va="center", fontsize=8, clip_on=True,
                color="black")
        if o.decided_at is not None:
            t = (s.start + o.decided_at) / fps
            ax.plot([t, t], [0.05, 0.45], color="black", lw=2)
    ax.set_ylim(0, 1)
    ax.set_yticks([0.25, 0.75], ["found", "performed"])
    ax.tick_params(axis="y", length=0)
    ax.set_title(f"{demo.who}: {', '.join(m for _, _, m in demo.truth)}", fontsize=10, loc="left")
