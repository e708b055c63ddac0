"""Off-screen pyvista scaffolding shared by the views and ``rendered-vision``: plotters, bodies, frames, movies.

Everything renders off screen (no display needed): :func:`plotter` picks VTK's
EGL or OSMesa window when there is no X display. A :class:`BodyFigure` draws a
body as one sphere per tracked part in the part's colour (the paper's
colour-coded body, Buchsbaum & Blumberg 2005, Fig. 2-3), bones as lines between
them and the root as a ring; :meth:`BodyFigure.update` moves it to a new pose
in place, so an animation reuses one plotter and one set of actors. A
:class:`Movie` writes the frames of one plotter as numbered PNG files, a GIF
and an MP4 at the motion's own frame rate (imageio, imageio-ffmpeg).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from toolkit.body import Body

__all__ = ["MAX_PIXELS", "plotter", "BodyFigure", "Movie", "SphereSet", "TubeSet", "part_colours", "hex_to_rgb", "GREY",
           "save_png", "draw_bodies", "frame_2d", "add_labels", "poses_png"]

GREY = "#b0b0b0"
MAX_PIXELS = 8192
"""The largest width or height of a picture a view draws, in pixels (a bound on the memory a setting can ask for)."""
"""The colour of a part the observer does not see."""

_PALETTE = ("#e6194b", "#3cb44b", "#4363d8", "#f58231", "#911eb4", "#42d4f4", "#f032e6", "#bfef45", "#fabed4",
            "#469990", "#dcbeff", "#9a6324", "#800000", "#aaffc3", "#808000", "#000075", "#ffe119", "#a9a9a9")


def hex_to_rgb(colour: str) -> tuple[int, int, int]:
    """``"#rrggbb"`` to (r, g, b) in 0..255."""
    c = colour.lstrip("#")
    return int(c[0:2], 16), int(c[2:4], 16), int(c[4:6], 16)


def part_colours(body: Body) -> list[str]:
    """Each part's colour: the body's own (``[body.colours]``), else a distinct colour of its own: part ``i`` the
    palette's ``i``-th, and a body of more parts than the palette has colours hues spread by the golden angle (never
    repeated: colour-coded vision tells parts apart by colour alone)."""
    palette = _palette()
    extra = [next(palette) for _ in range(len(body.parts))]
    return [body.colours.get(p, extra[i]) for i, p in enumerate(body.parts)]


def _palette():
    """Distinct colours, endlessly: :data:`_PALETTE`, then generated ones never black and never repeated."""
    import colorsys

    yield from _PALETTE
    seen = set(_PALETTE)
    k = 0
    while True:
        k += 1
        hue = (k * 0.381966) % 1.0
        light = (0.45, 0.65, 0.30)[k % 3]
        r, g, b = (round(255 * c) for c in colorsys.hls_to_rgb(hue, light, 0.9))
        colour = f"#{r:02x}{g:02x}{b:02x}"
        if colour not in seen and colour != "#000000":
            seen.add(colour)
            yield colour


def _headless() -> None:
    """Without an X display, ask VTK for an EGL window (falling back to OSMesa) before it opens one."""
    if not os.environ.get("DISPLAY") and "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ:
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"


def plotter(size: tuple[int, int] = (800, 600), *, background: str = "white", flat: bool = False) -> Any:
    """An off-screen :class:`pyvista.Plotter` of ``size`` (width, height) pixels.

    ``flat``: no anti-aliasing and no lights, so every pixel of a mesh has exactly its colour (for colour scanning).
    Close it (``plotter.close()``) when done; :class:`Movie` and the views do.
    """
    _headless()
    import pyvista as pv

    pl = pv.Plotter(off_screen=True, window_size=list(size), lighting="none" if flat else "light kit")
    pl.set_background(background)
    pl.renderer.GetCullers().RemoveAllItems()  # VTK culls props covering < 1e-4 of the view: far small parts vanish
    if flat:
        pl.disable_anti_aliasing()
    return pl


def save_png(pl: Any, path: str | Path) -> Path:
    """Render ``pl`` and write it to ``path`` as PNG (creating the folder)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    pl.screenshot(str(path))
    return path


def draw_bodies(pl: Any, body: Body, poses: np.ndarray, *, radius: float = 0.03, colours: Sequence[str] | None = None,
                bone_colour: str = "#404040", root_ring: bool = True, opacity: float = 1.0) -> None:
    """Draw many still poses (N, P, 3) of one body at once: one sphere mesh, one bone mesh, one ring mesh.

    For pictures (strips of key poses, graph nodes); animations move a :class:`BodyFigure` instead.
    """
    import pyvista as pv

    poses = np.where(body.angle_mask[:, None], np.nan, np.asarray(poses, dtype=float).reshape(-1, body.n_parts, 3))
    finite = np.isfinite(poses).all(axis=2)  # fingers (joint angles, not places) are not drawn as points
    rgb = np.array([hex_to_rgb(c) for c in (colours if colours is not None else part_colours(body))], dtype=np.uint8)
    points = pv.PolyData(poses[finite])
    points["rgb"] = np.broadcast_to(rgb, (*poses.shape[:2], 3))[finite]
    sphere = pv.Sphere(radius=radius, theta_resolution=12, phi_resolution=8)
    if points.n_points:
        pl.add_mesh(points.glyph(geom=sphere, scale=False, orient=False), scalars="rgb", rgb=True, smooth_shading=True,
                    opacity=opacity)
    pairs = body.bone_indices()
    if len(pairs):
        ok = finite[:, pairs[:, 0]] & finite[:, pairs[:, 1]]  # (N, B)
        base = (np.arange(len(poses)) * body.n_parts)[:, None]
        segments = np.stack([base + pairs[:, 0], base + pairs[:, 1]], axis=-1)[ok]
        if len(segments):
            lines = pv.PolyData(np.nan_to_num(poses.reshape(-1, 3)), lines=np.column_stack(
                [np.full(len(segments), 2), segments]).ravel())
            pl.add_mesh(lines, color=bone_colour, line_width=2, opacity=opacity)
    if root_ring:
        roots = poses[:, body.root_index][finite[:, body.root_index]]
        if len(roots):
            ring = pv.Disc(inner=radius * 1.6, outer=radius * 2.2, normal=(0, 1, 0), c_res=24)
            pl.add_mesh(pv.PolyData(roots).glyph(geom=ring, scale=False, orient=False), color="black", opacity=opacity)


def add_labels(pl: Any, points: np.ndarray, texts: Sequence[str], *, font_size: int = 14, align: str = "left",
               colour: str = "black") -> Any:
    """Text at 3D points (an array, or a PolyData whose points can move later), every one drawn; ``align`` left,
    centre or right."""
    if hasattr(points, "points"):  # a PolyData is kept (texts as its array): moving its points moves the labels
        points["labels"] = np.array(list(texts))
        texts = "labels"
    else:
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        texts = list(texts)
    actor = pl.add_point_labels(points, texts, font_size=font_size,
                                shape=None, show_points=False, always_visible=True, text_color=colour,
                                justification_horizontal={"centre": "center"}.get(align, align))
    actor.GetMapper().SetPlaceAllLabels(True)
    return actor


def poses_png(out: str | Path, body: Body, poses: np.ndarray, points: np.ndarray, labels: Sequence[str], *,
              lower: Sequence[float], upper: Sequence[float], size: tuple[int, int], radius: float, font_size: int,
              align: str = "left") -> Path:
    """A sheet of still poses (N, P, 3) with labels at ``points``, framed on ``lower``..``upper`` (x, y), as PNG."""
    pl = plotter(size)
    try:
        draw_bodies(pl, body, np.asarray(poses), radius=radius)
        add_labels(pl, np.asarray(points), labels, font_size=font_size, align=align)
        frame_2d(pl, lower, upper)
        return save_png(pl, out)
    finally:
        pl.close()


def frame_2d(pl: Any, lower: Sequence[float], upper: Sequence[float], *, margin: float = 0.04) -> None:
    """Look along -z with a parallel projection at the rectangle ``lower``..``upper`` (x, y), filling the window."""
    (x0, y0), (x1, y1) = lower, upper
    w, h = pl.window_size
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    half_h = max((y1 - y0) / 2, (x1 - x0) / 2 * h / w) * (1 + margin)
    pl.enable_parallel_projection()
    pl.camera.focal_point = (cx, cy, 0.0)
    pl.camera.position = (cx, cy, 100.0)
    pl.camera.up = (0.0, 1.0, 0.0)
    pl.camera.parallel_scale = half_h
    pl.camera.clipping_range = (1.0, 1000.0)


class BodyFigure:
    """A body drawn in a plotter: a sphere per part, bones, the root marked; moved in place by :meth:`update`.

    Parameters
    ----------
    pl : pyvista.Plotter
    body : Body
    pose : array (P, 3)
        World positions of the parts (NaN: not drawn).
    radius : float
        Sphere radius in metres.
    colours : sequence of str, optional
        One colour per part; default :func:`part_colours`.
    bones : bool
        Draw the bones (``body.bones``) as lines.
    flat : bool
        Unlit flat colours (for colour-coded rendering).
    label : str, optional
        Text shown above the head.
    """

    def __init__(self, pl: Any, body: Body, pose: np.ndarray, *, radius: float = 0.03,
                 colours: Sequence[str] | None = None, bones: bool = True, flat: bool = False,
                 label: str | None = None, opacity: float = 1.0) -> None:
        import pyvista as pv

        self.pl, self.body = pl, body
        self.colours = list(colours) if colours is not None else part_colours(body)
        self.spheres = []
        for i in range(body.n_parts):
            mesh = pv.Sphere(radius=radius, theta_resolution=16, phi_resolution=12)
            self.spheres.append(pl.add_mesh(mesh, color=self.colours[i], lighting=not flat, smooth_shading=not flat,
                                            opacity=opacity))
        self.ring = None
        if not flat:
            ring = pv.Disc(inner=radius * 1.6, outer=radius * 2.2, normal=(0, 1, 0), c_res=32)
            self.ring = pl.add_mesh(ring, color="black", opacity=opacity)
        self.bones = None
        pairs = body.bone_indices()
        if bones and len(pairs):
            self._lines = pv.PolyData(np.zeros((body.n_parts, 3)), lines=np.column_stack(
                [np.full(len(pairs), 2), pairs]).ravel())
            self.bones = pl.add_mesh(self._lines, color="#404040", line_width=3, opacity=opacity)
        self._label_point = None
        if label is not None:
            self._label_point = pv.PolyData(np.zeros((1, 3)))
            add_labels(pl, self._label_point, [label], align="centre")
        self.update(pose)

    def update(self, pose: np.ndarray, visible: np.ndarray | None = None) -> None:
        """Move to ``pose`` (P, 3); parts not ``visible`` are greyed, NaN parts and fingers (joint angles) hidden."""
        pose = np.where(self.body.angle_mask[:, None], np.nan, np.asarray(pose, dtype=float))
        finite = np.isfinite(pose).all(axis=1)
        for i, actor in enumerate(self.spheres):
            actor.SetVisibility(bool(finite[i]))
            if finite[i]:
                actor.SetPosition(*pose[i])
            actor.prop.color = self.colours[i] if visible is None or visible[i] else GREY
        root = pose[self.body.root_index]
        if self.ring is not None:
            self.ring.SetVisibility(bool(finite[self.body.root_index]))
            if finite[self.body.root_index]:
                self.ring.SetPosition(*root)
        if self.bones is not None:
            self._lines.points = np.where(finite[:, None], pose, np.nanmean(pose[finite], axis=0) if finite.any() else 0.0)
        if self._label_point is not None and finite.any():
            self._label_point.points = pose[finite][np.argmax(pose[finite, 1])][None] + np.array([[0.0, 0.12, 0.0]])


class Movie:
    """Frames of one plotter written as PNG files, a GIF and an MP4 at ``fps``.

    Call :meth:`frame` after each update of the scene, then :meth:`close`.
    ``formats`` is any of ``png`` (numbered frames ``frame_00000.png``...),
    ``gif`` and ``mp4``.
    """

    def __init__(self, pl: Any, folder: str | Path, fps: float, *, formats: Iterable[str] = ("png", "gif", "mp4"),
                 name: str = "scenario") -> None:
        self.pl, self.folder, self.fps = pl, Path(folder), float(fps)
        self.formats = tuple(formats)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.files: list[Path] = []
        self.n = 0
        self._gif = self._mp4 = None
        if "gif" in self.formats:
            import imageio.v2 as imageio

            path = self.folder / f"{name}.gif"
            self._gif = imageio.get_writer(path, mode="I", duration=1.0 / self.fps, loop=0)
            self.files.append(path)
        if "mp4" in self.formats:
            import imageio.v2 as imageio

            path = self.folder / f"{name}.mp4"
            self._mp4 = imageio.get_writer(path, fps=self.fps, codec="libx264", quality=7, macro_block_size=8,
                                           ffmpeg_log_level="quiet")  # its failures are raised, not printed
            self.files.append(path)

    def frame(self) -> np.ndarray:
        """Render the plotter's current scene and write it to every format; returns the image (H, W, 3)."""
        self.pl.render()
        image = np.asarray(self.pl.screenshot(return_img=True))
        if "png" in self.formats:
            import imageio.v2 as imageio

            path = self.folder / f"frame_{self.n:05d}.png"
            imageio.imwrite(path, image)
            self.files.append(path)
        if self._gif is not None:
            self._gif.append_data(image)
        if self._mp4 is not None:
            self._mp4.append_data(image)
        self.n += 1
        return image

    def close(self) -> list[Path]:
        """Finish the GIF and MP4 and close the plotter; returns every file written."""
        for writer in (self._gif, self._mp4):
            if writer is not None:
                writer.close()
        self.pl.close()
        return self.files


class SphereSet:
    """Many flat-coloured spheres drawn as one mesh: moved, resized and recoloured together from arrays each frame.

    For colour-coded rendering (``rendered-vision``): one actor and one vertex array however many spheres, each
    sphere's vertices all of its colour (unlit: every pixel of it has exactly that colour). A sphere of radius 0 is
    a point and draws nothing.

    Parameters
    ----------
    pl : pyvista.Plotter
    n : int
        How many spheres.
    resolution : (int, int)
        The template sphere's theta and phi resolution.
    """

    def __init__(self, pl: Any, n: int, resolution: tuple[int, int] = (12, 8)) -> None:
        import pyvista as pv

        template = pv.Sphere(radius=1.0, theta_resolution=resolution[0], phi_resolution=resolution[1])
        self.n, self.template = n, np.asarray(template.points, dtype=float)
        v = len(self.template)
        faces = template.faces.reshape(-1, 4)  # triangles: [3, a, b, c]
        offsets = (np.arange(n) * v)[:, None, None]
        all_faces = np.concatenate([faces[None, :, :1].repeat(n, 0), faces[None, :, 1:] + offsets], axis=2)
        self.mesh = pv.PolyData(np.zeros((n * v, 3)), faces=all_faces.reshape(-1))
        self.mesh["rgb"] = np.zeros((n * v, 3), dtype=np.uint8)
        self.actor = pl.add_mesh(self.mesh, scalars="rgb", rgb=True, lighting=False, render=False)
        self._points = self.mesh.points.reshape(n, v, 3)  # a view of VTK's own array: written in place each frame
        self._colours: np.ndarray | None = None

    def update(self, centres: np.ndarray, radii: np.ndarray, colours: np.ndarray | None = None) -> None:
        """Spheres at ``centres`` (n, 3) of ``radii`` (n,) (0 or non-finite: not drawn), coloured ``colours``
        (n, 3) uint8 when given."""
        centres = np.nan_to_num(np.asarray(centres, dtype=float), nan=0.0, posinf=0.0, neginf=0.0)
        radii = np.where(np.isfinite(radii), radii, 0.0)
        np.multiply(self.template[None], radii[:, None, None], out=self._points)
        self._points += centres[:, None, :]
        self.mesh.GetPoints().Modified()
        if colours is not None:
            colours = np.asarray(colours, dtype=np.uint8)
            if self._colours is None or not np.array_equal(colours, self._colours):
                self.mesh.point_data["rgb"][:] = np.repeat(colours, len(self.template), axis=0)
                self.mesh.point_data.GetArray("rgb").Modified()
                self._colours = colours.copy()


class TubeSet:
    """Many flat cylinders (open tubes) between pairs of points, drawn as one mesh of one colour (limbs).

    Parameters
    ----------
    pl : pyvista.Plotter
    n : int
        How many tubes.
    colour : str
    sides : int
        Sides of each tube.
    """

    def __init__(self, pl: Any, n: int, colour: str, sides: int = 8) -> None:
        import pyvista as pv

        angle = np.linspace(0.0, 2 * np.pi, sides, endpoint=False)
        self.ring = np.stack([np.cos(angle), np.sin(angle)], axis=1)  # (sides, 2)
        self.n, self.sides = n, sides
        a = np.arange(sides)
        quad = np.stack([np.full(sides, 4), a, (a + 1) % sides, (a + 1) % sides + sides, a + sides], axis=1)
        self.mesh = self.actor = None
        if n:  # nothing to draw without tubes
            faces = np.concatenate([quad + np.r_[0, [2 * sides * k] * 4] for k in range(n)])
            self.mesh = pv.PolyData(np.zeros((n * 2 * sides, 3)), faces=faces.reshape(-1))
            self.actor = pl.add_mesh(self.mesh, color=colour, lighting=False, render=False)
            self._points = self.mesh.points.reshape(n, 2, sides, 3)  # VTK's own array, written in place

    def update(self, starts: np.ndarray, ends: np.ndarray, radius: float) -> None:
        """Tubes of ``radius`` from ``starts`` (n, 3) to ``ends`` (n, 3); a tube with a non-finite or equal end is
        not drawn."""
        if not self.n:
            return
        starts, ends = np.asarray(starts, dtype=float), np.asarray(ends, dtype=float)
        along = ends - starts
        length = np.linalg.norm(along, axis=1)
        ok = np.isfinite(length) & (length > 1e-9)
        d = np.where(ok[:, None], along, [0.0, 1.0, 0.0]) / np.where(ok, length, 1.0)[:, None]
        helper = np.where((np.abs(d[:, 0]) < 0.9)[:, None], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
        x = np.cross(d, helper)
        x /= np.linalg.norm(x, axis=1, keepdims=True)
        z = np.cross(x, d)
        r = np.where(ok, radius, 0.0)[:, None, None]
        circle = (self.ring[None, :, :1] * x[:, None, :] + self.ring[None, :, 1:] * z[:, None, :]) * r  # (n, sides, 3)
        base = np.where(ok[:, None], starts, 0.0)[:, None, :]
        top = np.where(ok[:, None], ends, 0.0)[:, None, :]
        np.add(base, circle, out=self._points[:, 0])
        np.add(top, circle, out=self._points[:, 1])
        self.mesh.GetPoints().Modified()
