"""View ``imitation``: a demonstration and the observer's imitation of it, side by side, as PNG frames, a GIF and an
MP4 at the recording's frame rate.

Buchsbaum & Blumberg 2005, §5.3 and Kopp & Graeser 2006, §4.4: the observer performs what it recognised with its own
movements. ``likeme show --body PROFILE --repertoire DIR FILE --view imitation`` lets the observer ``likeme observe``
composes imitate the recording (:func:`plugins.action.imitation.imitate_motion`, what ``likeme imitate`` does) and
draws both bodies beside each other, frame for frame, with the movement the demonstrator is performing as the
observer recognised it; ``--set imitation=FILE`` draws an imitation written before (``likeme imitate --out FILE``,
read through the same profile) instead. Each body is drawn on its own floor (its lowest part over the recording),
the imitation beside the demonstrator across the way they travel, both seen from one camera.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from plugins.lib.rendering import MAX_PIXELS, BodyFigure, Movie, plotter
from toolkit import ConfigError, Parameter, View, hookimpl

__all__ = ["ImitationView", "side_by_side"]

FORMATS = ("png", "gif", "mp4")


def _floor(motion: Any) -> float:
    seen = np.where(np.isfinite(motion.positions).all(axis=-1) & motion.visible, motion.positions[..., 1], np.nan)
    return float(np.nanmin(seen)) if np.isfinite(seen).any() else 0.0


def side_by_side(demonstration: np.ndarray, imitation: np.ndarray, floors: tuple[float, float],
                 facing: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Both motions (F, P, 3) set on the floor ``y = 0`` and the imitation moved beside the demonstration, across
    the way the camera looks, by both bodies' extent across it and a body height. The camera looks along the
    demonstrator's main direction of travel when they travel more than their height, else at their front (their
    median ``facing``, radians about +y). Returns the two motions and the camera's horizontal viewing direction."""
    demo = demonstration - np.array([0.0, floors[0], 0.0])
    imit = imitation - np.array([0.0, floors[1], 0.0])
    height = float(np.nanmax(demo[..., 1])) if np.isfinite(demo[..., 1]).any() else 1.0
    root = np.nan_to_num(np.nanmean(demo, axis=1)[:, [0, 2]])
    flat = root - root.mean(axis=0)
    _, _, vt = np.linalg.svd(flat, full_matrices=False) if len(flat) > 1 else (None, None, np.eye(2))
    if np.ptp(flat @ vt[0]) > height:
        along = vt[0]
    else:  # they stay where they are: seen from the front
        along = -np.array([np.sin(facing), np.cos(facing)])
    across = np.array([along[1], 0.0, -along[0]])
    reach = lambda m: np.nan_to_num(m @ across)  # noqa: E731 - the extent of a motion across the travel
    gap = float(reach(demo).max() - reach(imit).min()) + 0.6 * max(height, 0.1)
    imit = imit + across * gap
    return demo, imit, np.array([along[0], 0.0, along[1]])


class ImitationView(View):
    """A recording and the observer's imitation of it, side by side over time (B&B §5.3, K&G §4.4)."""

    name = "imitation"
    recordings = "each"
    parameters = (
        Parameter("imitation", str, "", "An imitation written before (likeme imitate --out FILE), read through the "
                  "recording's profile; empty: the observer imitates the recording here."),
        Parameter("formats", list, list(FORMATS), "What to write: png (numbered frames), gif, mp4."),
        Parameter("every", int, 1, "Keep one frame in this many (the movie plays at the frame rate divided by it).",
                  minimum=1),
        Parameter("width", int, 960, "Frame width in pixels.", minimum=64, maximum=MAX_PIXELS),
        Parameter("height", int, 544, "Frame height in pixels.", minimum=64, maximum=MAX_PIXELS),
    )

    def draw(self, subject: Any, out: Path, recording: Any = None) -> list[Path]:
        """Write the frames, GIF and MP4 into the folder named by ``out`` without its suffix (``stream-imitation``
        for ``stream-imitation.png``); returns the files written."""
        unknown = sorted(set(self.params["formats"]) - set(FORMATS))
        if unknown:
            raise ConfigError(f"unknown format {unknown[0]!r}", key=("formats",), expected="image formats",
                              available=list(FORMATS))
        if recording is None:
            raise ConfigError("no recording to imitate", key=("--view",),
                              expected="likeme show --body PROFILE --repertoire DIR FILE --view imitation")
        character, demo = subject, recording.motion
        imitation, labels = self._imitation(character, demo)
        return self.render(character.body, demo, imitation, labels, Path(out).with_suffix(""),
                           who=(recording.who, character.name))

    def _imitation(self, character: Any, demo: Any) -> tuple[Any, list[str]]:
        """The imitation (world positions of the observer's parts, as long as the demonstration) and, per frame, the
        movement performed (empty between movements)."""
        labels = [""] * demo.n_frames
        if self.params["imitation"]:
            profile = getattr(character.repertoire, "profile", None)
            if profile is None:
                raise ConfigError("no body profile to read the imitation", key=("imitation",),
                                  expected="an observer composed with --body")
            path = Path(self.params["imitation"])
            motion = profile.read(path)
            if motion.n_frames != demo.n_frames:
                raise ConfigError(f"{motion.n_frames} frames, the recording {demo.n_frames}", file=path,
                                  key=("imitation",), expected="the imitation of this recording (as many frames)")
            return motion, labels
        from plugins.action.imitation import imitate_motion
        from toolkit.observe import Observer

        done = imitate_motion(Observer(character, character.body, demo.fps), demo)
        for seg in done.segments:
            text = f"{seg.movement} (learned)" if seg.learned else seg.movement
            labels[seg.start : seg.end] = [text] * (seg.end - seg.start)
        return done.motion, labels

    def render(self, body: Any, demo: Any, imitation: Any, labels: list[str], folder: Path,
               who: tuple[str, str] = ("demonstrator", "imitation")) -> list[Path]:
        """Draw both motions frame by frame with one plotter, moved in place, into ``folder``."""
        import pyvista as pv

        from plugins.lib.root_frame import facing_heading

        heading = facing_heading(np.nan_to_num(demo.positions), demo.visible, body)
        facing = float(np.angle(np.nanmean(np.exp(1j * heading)))) if np.isfinite(heading).any() else 0.0
        a, b, view = side_by_side(demo.positions, imitation.positions, (_floor(demo), _floor(imitation)), facing)
        both = np.concatenate([a.reshape(-1, 3), b.reshape(-1, 3)])
        both = both[np.isfinite(both).all(axis=1)]
        lo, hi = (both.min(axis=0), both.max(axis=0)) if len(both) else (np.zeros(3), np.ones(3))
        centre, span = (lo + hi) / 2, max(float(np.max(hi - lo)), 0.5)
        pl = plotter((self.params["width"], self.params["height"]))
        movie = Movie(pl, folder, demo.fps / self.params["every"], formats=self.params["formats"], name="imitation")
        try:
            pl.add_mesh(pv.Plane(center=(centre[0], 0.0, centre[2]), direction=(0, 1, 0), i_size=span * 1.5,
                                 j_size=span * 1.5), color="#e9e4d8")
            radius = 0.03 * max(float(hi[1] - lo[1]), 0.2) / 1.7
            shown = demo.visible & np.isfinite(demo.positions).all(axis=-1)
            figures = (BodyFigure(pl, body, a[0], radius=radius, label=who[0]),
                       BodyFigure(pl, body, b[0], radius=radius, label=f"{who[1]} imitates"))
            text = pl.add_text("", position=(10, 10), font_size=11, color="black")
            pl.camera.focal_point = centre
            across = np.array([view[2], 0.0, -view[0]])
            depth, width = np.ptp(both @ view), max(float(np.ptp(both @ across)), float(hi[1] - lo[1]))
            distance = depth / 2 + 1.4 * width  # the nearest body in view, both side by side across the picture
            pl.camera.position = centre - view * distance + np.array([0.0, width * 0.35, 0.0])
            pl.camera.up = (0.0, 1.0, 0.0)
            for f in range(0, demo.n_frames, self.params["every"]):
                figures[0].update(np.where(shown[f, :, None], a[f], np.nan))
                figures[1].update(b[f])
                text.SetInput(f"t = {f / demo.fps:5.2f} s  frame {f}" + (f"\n{labels[f]}" if labels[f] else ""))
                movie.frame()
        finally:
            files = movie.close()
        return files


@hookimpl
def likeme_register_views():
    return [ImitationView]
