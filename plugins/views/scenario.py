"""View ``scenario``: a scenario rendered over time as PNG frames, a GIF and an MP4 at its own frame rate.

What it shows, frame by frame: the ground, the objects, every actor's
colour-coded body (Buchsbaum & Blumberg 2005, Fig. 2-3) with its id; for every
actor that watches another, its field of view on the ground (the perception's
``fov`` and ``range``) and what it sees: the watched actor's parts it did not
see in that frame are greyed (§4.2: occlusion, field of view); and, as text,
the segments found, the movements recognised and the imitations started, as
they happen. An imitation is the imitator's own body moving beside the
demonstration.

The view records the run through the run-event hooks (``likeme_world_stepped``,
``likeme_segment_found``, ``likeme_movement_recognised``,
``likeme_imitation_started``), then draws every recorded frame with one plotter
whose actors are moved in place, and closes it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from plugins.lib.rendering import BodyFigure, MAX_PIXELS, Movie, plotter
from toolkit import Parameter, View, hookimpl
from toolkit.motion import facing_vector

__all__ = ["ScenarioView", "Recorder"]


def _check_colours(world: Any) -> None:
    """Every object's colour is one the renderer draws: checked before the run, not found after it."""
    import pyvista as pv

    from toolkit import ConfigError

    for name, obj in world.objects.items():
        if obj.colour:
            try:
                pv.Color(obj.colour)
            except ValueError:
                raise ConfigError(f"unknown colour {obj.colour!r} of object {name!r}", key=("objects", name, "colour"),
                                  expected='a colour "#rrggbb" (or a colour name the renderer knows)') from None


@dataclass
class Recorder:
    """What a run showed, frame by frame; registered as a plugin while the world runs."""

    world: Any = field(repr=False)
    every: int = 1
    poses: dict[str, list[np.ndarray]] = field(default_factory=dict)
    headings: dict[str, list[float]] = field(default_factory=dict)
    seen: dict[str, list[np.ndarray | None]] = field(default_factory=dict)  # observer -> its target's visible parts
    objects: list[dict[str, tuple[np.ndarray, float, str]]] = field(default_factory=list)
    frames: list[int] = field(default_factory=list)
    notes: list[tuple[int, str]] = field(default_factory=list)
    fps: float = 30.0

    @hookimpl
    def likeme_world_stepped(self, world: Any) -> None:
        if world.frame % self.every:
            return
        self.frames.append(world.frame)
        for id, actor in world.actors.items():
            self.poses.setdefault(id, []).append(actor.world_pose().copy())
            self.headings.setdefault(id, []).append(float(actor.heading))
            memory = actor.memory
            seen = memory.visible[-1].copy() if memory is not None and len(memory.visible) else None
            self.seen.setdefault(id, []).append(seen)
        self.objects.append({n: (o.position.copy(), float(o.radius), o.colour) for n, o in world.objects.items()})

    @hookimpl
    def likeme_segment_found(self, world: Any, observer: Any, target: Any, segment: Any) -> None:
        self.notes.append((world.frame, f"{observer.id}: segment of {target.id}, "
                                        f"{segment.start_time:.2f}-{segment.end_time:.2f} s"))

    @hookimpl
    def likeme_movement_recognised(self, world: Any, observer: Any, target: Any, segment: Any, match: Any) -> None:
        what = f"recognised {match.movement} ({match.confidence:.2f})" if match.movement else "unknown movement"
        self.notes.append((world.frame, f"{observer.id}: {what}"))

    @hookimpl
    def likeme_imitation_started(self, world: Any, actor: Any, target: Any, request: Any) -> None:
        self.notes.append((world.frame, f"{actor.id}: imitates {request.movement}"))


def field_of_view(eye: np.ndarray, heading: float, fov_degrees: float, reach: float, n: int = 24) -> np.ndarray:
    """A fan on the ground (y = 0.005): the eye's ground point and an arc ``reach`` away across the field of view."""
    half = np.radians(min(fov_degrees, 359.0)) / 2
    arc = np.array([facing_vector(heading + a) for a in np.linspace(-half, half, n)]) * reach
    centre = np.array([eye[0], 0.0, eye[2]])
    points = np.vstack([centre, centre + arc])
    points[:, 1] = 0.005
    return points


class ScenarioView(View):
    """A scenario over time: bodies, objects, fields of view, what the observer sees, segments and labels as text."""

    name = "scenario"
    subject = "scenario"
    parameters = (
        Parameter("formats", list, ["png", "gif", "mp4"], "What to write: png (numbered frames), gif, mp4."),
        Parameter("every", int, 1, "Keep one frame in this many (the movie plays at the frame rate divided by it).",
                  minimum=1),
        Parameter("width", int, 800, "Frame width in pixels.", minimum=64, maximum=MAX_PIXELS),
        Parameter("height", int, 600, "Frame height in pixels.", minimum=64, maximum=MAX_PIXELS),
        Parameter("reach", float, 2.5, "Length (m) of the field of view drawn on the ground.", minimum=0.1),
        Parameter("notes", float, 3.0, "Seconds a segment or label stays on screen.", minimum=0.0),
    )

    def start(self, world: Any) -> Recorder:
        """Begin recording ``world``'s run (call before it runs; :meth:`finish` after)."""
        unknown = sorted(set(self.params["formats"]) - {"png", "gif", "mp4"})
        if unknown:
            from toolkit import ConfigError

            raise ConfigError(f"unknown format {unknown[0]!r}", key=("formats",), expected="image formats",
                              available=["png", "gif", "mp4"])
        _check_colours(world)
        recorder = Recorder(world, every=self.params["every"], fps=world.fps)
        world.pm.register(recorder, name="scenario-view-recorder")
        return recorder

    @staticmethod
    def stop(recorder: Recorder) -> None:
        """Stop recording (whether the run ended or failed); calling it again does nothing."""
        if recorder.world.pm.is_registered(recorder):
            recorder.world.pm.unregister(recorder)

    def finish(self, recorder: Recorder, out: Path) -> list[Path]:
        """Stop recording and draw every recorded frame into the folder ``out``."""
        self.stop(recorder)
        return self.render(recorder, Path(out))

    def draw(self, subject: Any, out: Path) -> list[Path]:
        recorder = self.start(subject.world)
        try:
            subject.run()
        finally:
            self.stop(recorder)
        return self.render(recorder, Path(out))

    def render(self, recorder: Recorder, out: Path) -> list[Path]:
        """Draw every recorded frame into the folder ``out``; returns the files written."""
        import pyvista as pv

        world = recorder.world

        if not recorder.frames:
            return []
        pl = plotter((self.params["width"], self.params["height"]))
        movie = Movie(pl, out, recorder.fps / recorder.every, formats=self.params["formats"])
        everything = np.concatenate([np.concatenate(p)[np.isfinite(np.concatenate(p)).all(axis=1)]
                                     for p in recorder.poses.values()])
        lo, hi = everything.min(axis=0), everything.max(axis=0)
        centre = (lo + hi) / 2
        span = max(float(np.max(hi - lo)), 2.0)
        ground = pv.Plane(center=(centre[0], 0.0, centre[2]), direction=(0, 1, 0), i_size=span * 1.6, j_size=span * 1.6)
        pl.add_mesh(ground, color="#e9e4d8")
        figures = {id: BodyFigure(pl, world.actors[id].body, poses[0], radius=0.035, label=id)
                   for id, poses in recorder.poses.items()}
        fans = {}
        for id, actor in world.actors.items():
            perception = actor.character.perception
            if actor.target is None and not any(s is not None for s in recorder.seen[id]):
                continue
            params = getattr(perception, "params", {})
            fov, reach = float(params.get("fov", 360.0)), min(float(params.get("range", 99.0)), self.params["reach"])
            eye_part = actor.body.index(params["eye"]) if "eye" in params else actor.body.root_index
            points = field_of_view(recorder.poses[id][0][eye_part], recorder.headings[id][0], fov, reach)
            fan = pv.PolyData(points, faces=np.hstack([[3, 0, i, i + 1] for i in range(1, len(points) - 1)]))
            pl.add_mesh(fan, color="#ffd24d", opacity=0.35)
            fans[id] = (fan, eye_part, fov, reach)
        balls: dict[str, Any] = {}
        text = pl.add_text("", position=(10, 10), font_size=11, color="black")
        pl.camera.focal_point = centre
        pl.camera.position = centre + np.array([span * 2.4, span * 1.1, span * 0.9])
        pl.camera.up = (0.0, 1.0, 0.0)
        ids = list(recorder.poses)
        try:
            watcher = {id: next((o for o in ids if world.actors[o].target is not None
                                 and world.actors[o].target.id == id), None) for id in ids}
            for k, frame in enumerate(recorder.frames):
                for id in ids:  # a watched actor shows what its watcher saw of it; the others are drawn whole
                    seen = recorder.seen[watcher[id]][k] if watcher[id] is not None else None
                    figures[id].update(recorder.poses[id][k], seen)
                    if id in fans:
                        fan, eye, fov, reach = fans[id]
                        fan.points = field_of_view(recorder.poses[id][k][eye], recorder.headings[id][k], fov, reach)
                for name, (position, radius, colour) in recorder.objects[k].items():
                    if name not in balls:
                        balls[name] = pl.add_mesh(pv.Sphere(radius=radius), color=colour or "#999999")
                    balls[name].SetPosition(*position)
                for name in set(balls) - set(recorder.objects[k]):
                    balls[name].SetVisibility(False)
                window = int(self.params["notes"] * recorder.fps)
                recent = [note for f, note in recorder.notes if frame - window < f <= frame][-4:]
                text.SetInput(f"t = {frame / recorder.fps:5.2f} s\n" + "\n".join(recent))
                movie.frame()
        finally:
            files = movie.close()
        return files


@hookimpl
def likeme_register_views():
    return [ScenarioView]
