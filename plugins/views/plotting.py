"""Matplotlib scaffolding shared by the signal views: figures, the demonstration's timeline, atomic PNG files.

Not a component. Figures are :class:`matplotlib.figure.Figure` objects drawn on
the Agg canvas, never through ``pyplot``: no global figure registry, nothing
to close, no display. :func:`timeline` draws the strip every signal plot starts
with: the movements the demonstrator really performed, and the segments the
watcher found with what it recognised and when it decided.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from toolkit import Parameter
from plugins.lib.rendering import MAX_PIXELS

__all__ = ["DEMONSTRATION", "FREE_LABEL", "PALETTE", "blank", "colours", "figure", "fit_labels", "save_figure",
           "span_label", "timeline", "demonstrate"]

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
    Parameter("width", int, 1400, "Image width in pixels.", minimum=200, maximum=MAX_PIXELS),
    Parameter("height", int, 800, "Image height in pixels.", minimum=200, maximum=MAX_PIXELS),
)
"""The parameters every signal view shares: what is demonstrated, and the picture's size."""


def demonstrate(view: Any, character: Any, recording: Any = None) -> Any:
    """The :class:`~plugins.views.demonstration.Demonstration` a signal view's parameters ask for, or ``recording``
    (one made by :func:`~plugins.views.demonstration.recording`) when there is one."""
    from plugins.views.demonstration import perform_sequence

    if recording is not None:
        return recording
    p = view.params
    return perform_sequence(character, p["demonstrator"], p["movements"], "movements", speed=p["speed"],
                            rest=p["rest"], noise=p["noise"], seed=p["seed"])


def blank(width: int, height: int) -> Any:
    """An empty figure of ``width`` x ``height`` pixels (constrained layout, Agg canvas)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    dpi = 100
    fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)  # a canvas that can measure text before the picture is written
    return fig


def figure(width: int, height: int, rows: Sequence[float]) -> tuple[Any, list[Any]]:
    """A figure of ``width`` x ``height`` pixels with one axis per row (``rows``: relative heights), sharing x."""
    fig = blank(width, height)
    axes = fig.subplots(len(rows), 1, sharex=True, gridspec_kw={"height_ratios": list(rows)}, squeeze=False)[:, 0]
    return fig, list(axes)


SPAN_LABEL = "likeme-span-label"
"""The ``gid`` of a label that belongs inside a span of the x axis (:func:`span_label`): fitted before saving."""

FREE_LABEL = "likeme-free-label"
"""The ``gid`` of a label placed where its data is (the end of a line, a moment): before saving, one that would
overlap a label of higher ``zorder`` or drawn before it, or run past its axes, is hidden (:func:`fit_labels`)."""

ELLIPSIS = "\u2026"


def span_label(ax: Any, x0: float, x1: float, y: float, text: str, **kwargs: Any) -> Any:
    """A label centred in the span ``x0``..``x1`` (data) at height ``y`` (axes fraction), fitted to the span when the
    figure is saved (:func:`fit_labels`): shortened with an ellipsis where it is wider, hidden where not one letter
    fits, so labels of neighbouring spans never overlap and none runs past the axes."""
    kwargs.setdefault("fontsize", 8)
    label = ax.text((x0 + x1) / 2, y, text, ha="center", va="center", transform=ax.get_xaxis_transform(),
                    gid=SPAN_LABEL, clip_on=False, **kwargs)
    label.set_in_layout(False)  # fitted after the layout, not a reason to shrink the axes
    label.likeme_span = (float(x0), float(x1))
    label.likeme_text = text
    return label


def _shorten(label: Any, text: str, width: float, renderer: Any, smallest: float | None = None) -> bool:
    """Set the longest prefix of ``text`` (with an ellipsis when cut) whose width is within ``width`` pixels, after
    trying the font down to ``smallest`` points; whether anything of it is left."""
    label.set_text(text)
    size = label.get_fontsize()
    while label.get_window_extent(renderer).width > width and smallest is not None and size > smallest:
        size = max(smallest, size - 0.5)
        label.set_fontsize(size)
    if label.get_window_extent(renderer).width <= width:
        return True
    lo, hi = 0, len(text) - 1  # the longest prefix that fits, by bisection
    while lo < hi:
        mid = (lo + hi + 1) // 2
        label.set_text(text[:mid].rstrip() + ELLIPSIS)
        if label.get_window_extent(renderer).width <= width:
            lo = mid
        else:
            hi = mid - 1
    label.set_text(text[:lo].rstrip() + ELLIPSIS)
    return lo > 0


def fit_labels(fig: Any, pad: float = 3.0) -> int:
    """Fit every axes title to the figure's width and every :func:`span_label` of ``fig`` to the visible part of its
    span, after the layout is done (twice: the titles first, as they take part in the layout, then the labels); the
    layout is then kept as it is. Returns how many labels and titles were shortened or hidden."""
    changed = 0
    left, right = fig.bbox.x0 + pad, fig.bbox.x1 - pad
    for _ in range(3):  # a shorter title changes the layout, which may move another title
        fig.canvas.draw()  # the layout, and a renderer that measures text
        renderer = fig.canvas.get_renderer()
        shortened = 0
        for ax in fig.axes:
            for title in (ax.title, ax._left_title, ax._right_title):
                box = title.get_window_extent(renderer)
                if title.get_text() and (box.x1 > right + 0.5 or box.x0 < left - 0.5):
                    room = {"left": right - max(box.x0, left), "right": min(box.x1, right) - left,
                            "center": 2 * min((box.x0 + box.x1) / 2 - left, right - (box.x0 + box.x1) / 2)}
                    _shorten(title, title.get_text(), room[title.get_horizontalalignment()], renderer)
                    shortened += 1
        changed += shortened
        if not shortened:
            break
    fig.set_layout_engine("none")  # what is measured now is where things stay
    for ax in fig.axes:
        lo, hi = sorted(ax.get_xlim())
        for label in ax.texts:
            if label.get_gid() != SPAN_LABEL:
                continue
            x0, x1 = max(label.likeme_span[0], lo), min(label.likeme_span[1], hi)
            if x1 <= x0:
                label.set_visible(False)
                changed += 1
                continue
            label.set_x((x0 + x1) / 2)
            (px0, _), (px1, _) = ax.transData.transform([(x0, 0.0), (x1, 0.0)])
            fits = _shorten(label, label.likeme_text, abs(px1 - px0) - 2 * pad, renderer,
                            smallest=min(6.5, label.get_fontsize()))
            label.set_visible(fits)
            changed += label.get_text() != label.likeme_text or not fits
        kept: list[Any] = []
        free = [t for t in ax.texts if t.get_gid() == FREE_LABEL and t.get_visible()]
        for label in sorted(free, key=lambda t: -t.get_zorder()):  # the higher first, then in the order drawn
            box = label.get_window_extent(renderer)
            if box.x1 > ax.bbox.x1 and label.get_horizontalalignment() == "left":  # past the right edge: to the left
                label.set_horizontalalignment("right")
                label.set_text(label.get_text().strip() + " ")
                box = label.get_window_extent(renderer)
            shift = max(0.0, ax.bbox.y0 - box.y0) - max(0.0, box.y1 - ax.bbox.y1)  # a line's end at the floor: up
            if shift and abs(shift) < box.height:  # moved inside when its anchor is (the rest would be clipped)
                transform = label.get_transform()
                anchor = transform.transform(label.get_position())
                label.set_position(transform.inverted().transform(anchor + [0.0, shift]))
                box = label.get_window_extent(renderer)
            inside = ax.bbox.x0 <= box.x0 and box.x1 <= ax.bbox.x1 and ax.bbox.y0 <= box.y0 and box.y1 <= ax.bbox.y1
            if inside and not any(box.overlaps(other) for other in kept):
                kept.append(box)
            else:
                label.set_visible(False)
                changed += 1
    return changed


def save_figure(fig: Any, out: str | Path) -> Path:
    """Fit the labels (:func:`fit_labels`), then write ``fig`` to ``out`` as PNG atomically (a temporary file in the
    same folder, then a rename)."""
    from toolkit.files import writing

    out = Path(out)
    fit_labels(fig)
    with writing(out, "picture") as tmp:
        fig.savefig(tmp, format="png")
    return out


UNKNOWN_COLOUR = "#a0a0a0"
"""The colour of a segment recognised as no movement."""


def colours(names: Sequence[str]) -> dict[str, str]:
    """A colour per movement name (sorted, so the same names get the same colours in every picture): the palette,
    or for more names than it has, hues a golden angle apart in two strengths (strong, distinct neighbours)."""
    names = sorted(set(names))
    if len(names) <= len(PALETTE):
        return {m: PALETTE[i] for i, m in enumerate(names)}
    from matplotlib.colors import hsv_to_rgb, to_hex

    return {m: to_hex(hsv_to_rgb((0.61803398875 * i % 1.0, 0.75, 0.9 if i % 2 else 0.65)))
            for i, m in enumerate(names)}


def timeline(ax: Any, demo: Any, observations: Sequence[Any], fps: float, *, recognised: bool = True) -> None:
    """The strip above a signal: true movements (top row, when they are known) and found segments (bottom row).

    A found segment is coloured and labelled by what was recognised (grey: unknown; ``recognised=False``, with no
    matcher: alternating greys, unlabelled); a black tick up from the foot of the lane marks the moment the matcher
    committed when it did so before the segment ended. Labels are fitted to their spans when the figure is saved.
    """
    found = [o.movement or "unknown" for o in observations] if recognised else []
    colour = colours([m for _, _, m in demo.truth] + [m for m in found if m != "unknown"])
    colour["unknown"] = UNKNOWN_COLOUR
    rows = {"found": (0.05, 0.45), "performed": (0.55, 0.95)} if demo.truth else {"found": (0.25, 0.75)}
    lo, hi = rows["found"]
    for start, end, movement in demo.truth:
        a, b = rows["performed"]
        ax.axvspan(start / fps, end / fps, ymin=a, ymax=b, facecolor=colour[movement], alpha=0.35, lw=1,
                   edgecolor="white")
        span_label(ax, start / fps, end / fps, (a + b) / 2, movement)
    for k, o in enumerate(observations):
        s = o.segment
        fill = colour[found[k]] if recognised else ("#606060" if k % 2 else "#909090")
        ax.axvspan(s.start_time, s.end_time, ymin=lo, ymax=hi, facecolor=fill, alpha=0.5, lw=1, edgecolor="white")
        if recognised:
            span_label(ax, s.start_time, s.end_time, (lo + hi) / 2, found[k])
        if o.decided_at is not None:  # a black tick up from the lane's foot, below its label
            t = (s.start + o.decided_at) / fps
            ax.plot([t, t], [lo, lo + 0.3 * (hi - lo)], color="black", lw=2.5, transform=ax.get_xaxis_transform())
    ax.set_ylim(0, 1)
    ax.set_yticks([(a + b) / 2 for a, b in rows.values()], list(rows))
    ax.tick_params(axis="y", length=0)
    what = ", ".join(m for _, _, m in demo.truth)
    ax.set_title(f"{demo.who}: {what}" if what else demo.who, fontsize=10, loc="left")
