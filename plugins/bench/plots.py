"""The pictures of ``likeme bench recognition|segmentation|stream --plot PNG``.

- recognition: a confusion matrix per matcher, the count in every cell, the labels on both axes and a colour bar;
- segmentation and stream: the scores per plugin as bars, then a timeline per stream: its true segments (top lane)
  and, one lane per plugin, the segments each found, coloured by the true movement it counts for (the benchmark's
  rule, :func:`plugins.bench.metrics.match_segments`) or, in the stream benchmark, by the movement recognised
  (crossed out in red where it is not the true one); a found segment that counts for none is hatched.

Labels are fitted to their spans (:func:`plugins.views.plotting.fit_labels`): shortened, never overlapping, never
past the axes. Matplotlib is imported when a picture is drawn, not before.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["plot_result", "confusion_figure", "timeline_figure", "MAX_STREAMS"]

MAX_STREAMS = 12
"""At most this many streams get a timeline (the first, by name); the title says how many there were."""

FALSE = "#e6194b"
"""Segments that count for no true movement, and recognitions that are wrong."""


def plot_result(result: dict[str, Any], path: str | Path) -> Path:
    """Draw a benchmark result (what :func:`plugins.bench.mocap.recognition`, ``segmentation`` or ``stream``
    returns) to the PNG file ``path``, atomically."""
    from plugins.views.plotting import save_figure

    kind = result["benchmark"]
    fig = confusion_figure(result) if kind == "recognition" else timeline_figure(result)
    return save_figure(fig, path)


def confusion_figure(result: dict[str, Any]) -> Any:
    """One confusion matrix per plugin of a recognition result: rows true, columns recognised, counts written in
    the cells, a colour bar of the counts."""
    from matplotlib.ticker import MaxNLocator

    from plugins.views.plotting import blank

    rows = result["plugins"]
    n = max((len(r["labels"]) for r in rows), default=1)
    cell = 0.3 if n > 12 else 0.45  # inches per cell
    side = max(3.0, n * cell + 2.2)  # the matrix and its labels
    fig = blank(int(100 * (side + 1.0) * len(rows)), int(100 * (side + 0.6)))
    axes = fig.subplots(1, max(len(rows), 1), squeeze=False)[0]
    for ax, row in zip(axes, rows):
        m = np.asarray(row["confusion"], dtype=int)
        labels = row["labels"]
        image = ax.imshow(m, cmap="Blues", vmin=0, vmax=max(int(m.max()), 1))
        dark = m > 0.6 * max(int(m.max()), 1)
        size = 8 if n <= 40 else 6
        for (i, j), count in np.ndenumerate(m):
            if count:
                ax.text(j, i, str(count), ha="center", va="center", fontsize=size,
                        color="white" if dark[i, j] else "black")
        ax.set_xticks(range(len(labels)), labels, rotation=90, fontsize=size)
        ax.set_yticks(range(len(labels)), labels, fontsize=size)
        ax.set_xlabel("recognised")
        ax.set_ylabel("true")
        ax.set_title(f"{row['plugin']}: accuracy {row['accuracy']:.2f}, macro F1 {row['macro_f1']:.2f}, "
                     f"{row['items']} clips", fontsize=9, loc="left")
        bar = fig.colorbar(image, ax=ax, shrink=0.8, label="clips")
        bar.locator = MaxNLocator(integer=True)  # counts
        bar.update_ticks()
    return fig


def _lanes(n: int) -> list[tuple[float, float]]:
    """``n`` lanes from the top of an axis down, as (bottom, top) axes fractions with a gap between them."""
    step = 1.0 / n
    return [(1.0 - (k + 1) * step + 0.1 * step, 1.0 - k * step - 0.1 * step) for k in range(n)]


def timeline_figure(result: dict[str, Any]) -> Any:
    """The scores per plugin as bars, then, per stream, its true segments and the segments each plugin found."""
    from plugins.bench.metrics import match_segments
    from plugins.views.plotting import UNKNOWN_COLOUR, blank, colours, span_label

    kind = result["benchmark"]
    plugins = [r["plugin"] for r in result["plugins"]]
    scores = ("precision", "recall", "f1") if kind == "segmentation" else ("error_rate",)
    streams = sorted(result.get("timelines", []), key=lambda t: t["item"])
    shown = streams[:MAX_STREAMS]
    lanes = 1 + len(plugins)
    bar_height = 1.2 + 0.22 * len(plugins)
    stream_height = 0.3 + 0.26 * lanes
    fig = blank(1400, int(100 * (bar_height + stream_height * len(shown) + 0.6)))
    axes = fig.subplots(1 + len(shown), 1, squeeze=False,
                        gridspec_kw={"height_ratios": [bar_height] + [stream_height] * len(shown)})[:, 0]
    bars = axes[0]
    y = np.arange(len(plugins))
    height = 0.8 / len(scores)
    for k, score in enumerate(scores):
        values = [r[score] for r in result["plugins"]]
        bars.barh(y + (k - (len(scores) - 1) / 2) * height, values, height=height, label=score.replace("_", " "),
                  color=("#4363d8", "#3cb44b", "#000075", "#f58231")[k])
        for yy, v in zip(y + (k - (len(scores) - 1) / 2) * height, values):
            bars.text(v, yy, f" {v:.2f}", va="center", fontsize=7)
    bars.set_yticks(y, plugins, fontsize=8)
    bars.invert_yaxis()
    bars.set_xlim(0, max([1.0] + [r[s] * 1.15 for r in result["plugins"] for s in scores]))
    bars.legend(loc="lower right", fontsize=7, ncols=len(scores))
    what = "true and found segments" if kind == "segmentation" else "true and recognised movements"
    more = f" (the first {len(shown)} of {len(streams)} streams)" if len(shown) < len(streams) else ""
    bars.set_title(f"{kind}: {', '.join(s.replace('_', ' ') for s in scores)} per plugin; below, {what} per "
                   f"stream{more} (hatched: a found segment that counts for no true movement; red label: "
                   f"recognised wrong)" if kind == "stream" else f"{kind}: {', '.join(s for s in scores)} per plugin; "
                   f"below, {what} per stream{more} (hatched: a found segment that counts for no true movement)",
                   fontsize=10, loc="left")
    names = [m for t in shown for _, _, m in t["truth"]]
    names += [f[2] for t in shown for found in t["found"].values() for f in found if len(f) > 2]
    colour = colours([m for m in names if m != "unknown"])
    colour["unknown"] = UNKNOWN_COLOUR
    for ax, stream in zip(axes[1:], shown):
        fps = stream["fps"]
        where = _lanes(lanes)
        truth = stream["truth"]
        for a, b, m in truth:
            ax.axvspan(a / fps, b / fps, ymin=where[0][0], ymax=where[0][1], facecolor=colour[m], alpha=0.45,
                       edgecolor="white", lw=1)
            span_label(ax, a / fps, b / fps, sum(where[0]) / 2, m, fontsize=7)
        ticks = ["true"]
        for lane, plugin in zip(where[1:], plugins):
            found = stream["found"].get(plugin, [])
            pairs = dict(match_segments([(f[0], f[1]) for f in found], [(a, b) for a, b, _ in truth]))
            for i, f in enumerate(found):
                start, end = f[0] / fps, f[1] / fps
                counted = truth[pairs[i]][2] if i in pairs else None
                label = f[2] if len(f) > 2 else counted
                fill = colour[label] if label is not None else "white"
                ax.axvspan(start, end, ymin=lane[0], ymax=lane[1], facecolor=fill, alpha=0.6 if label else 1.0,
                           edgecolor="white" if counted or label else FALSE, hatch=None if counted or label else "////",
                           lw=1)
                if len(f) > 2:
                    right = counted == label
                    span_label(ax, start, end, sum(lane) / 2, label, fontsize=7,
                               color="black" if right else FALSE)
            ticks.append(plugin)
        ax.set_ylim(0, 1)
        ax.set_xlim(0, stream["frames"] / fps)
        ax.set_yticks([sum(w) / 2 for w in where], ticks, fontsize=7)
        ax.tick_params(axis="y", length=0)
        ax.tick_params(axis="x", labelsize=7)
        ax.set_title(f"{stream['item']}: {len(truth)} true segments", fontsize=8, loc="left")
    if len(axes) > 1:
        axes[-1].set_xlabel("time (s)")
    return fig
