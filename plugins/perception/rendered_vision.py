"""Perception ``rendered-vision``: colour-coded synthetic vision by really rendering the observer's view (B&B §4.2).

Buchsbaum & Blumberg 2005, §4.2: "the synthetic vision system takes as input a graphical rendering of the world from
the position and orientation of the creature's eye ... each object is assigned a unique color, which can be used as
an identifying tag. By scanning the visual image for pixels of a particular color, the creature can 'see' an object
... the screen-space coordinates of an object's centroid ... combined with information from the rendering's
depth-buffer" give its 3D position in the eye's frame. This plugin does exactly that, off screen (VTK through
pyvista, :func:`plugins.lib.rendering.plotter`):

1. the world as it looks: one flat, unlit sphere per body part of the watched actor in the colour it wears
   (``[body.colours]``; Max's nose is yellow, Fig. 2-3), its bones as flat cylinders of ``limb_radius`` in
   ``limb_colour`` (an arm hides the hand behind it), and every object in its own colour and size; no lights, no
   anti-aliasing, so every pixel of a thing has exactly its colour;
2. a pinhole camera at the observer's eye looking where it faces, ``fov`` degrees wide (at most 170), at
   ``resolution`` pixels square, the perception's ``range`` its far plane;
3. the image scanned (:mod:`plugins.perception.colour_scan`): the pixels of each body part's colour, as the observer
   knows it (Max starts out knowing which colour is which part, §5: his own ``[body.colours]``), give the part's
   centroid, and the nearest depth over them plus the part's radius its distance; every other colour is an
   object's, each connected blob of it one object, whose size is its apparent radius (a part's colour seen in two
   places is the part where it was last found, and an object elsewhere). The centroid (u, v) and depth
   z turn back into a point in the world through the pinhole model.

A camera is not exact: a part is found to within a fraction of a pixel (at 1.6 m a pixel of a 480 px, 140 degree
view is about 1.8 cm), its depth to within ``depth_noise`` of it, and each centroid jitters by ``pixel_noise``
pixels from frame to frame. :meth:`RenderedVision.position_uncertainty` says how far off a seen point may be, which
is what an observer reading another's gaze must allow for (:mod:`plugins.action.line_of_sight`).

Occlusion comes from the depth test of the render itself. Everything after the scan (noise, dropouts, the sensory
buffer, the facing filter, root-relative coordinates, naming the objects seen) is
:class:`plugins.perception.synthetic_vision.SyntheticVision`'s, so the two are interchangeable in a character file
and compared on the same scenes by ``likeme bench vision``. The plotter is made once, reused for every frame, and
closed by :meth:`RenderedVision.close` and on :meth:`reset`; the colour and depth buffers are read straight from the
render window (one render per frame).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from plugins.lib.rendering import SphereSet, TubeSet, part_colours, plotter
from plugins.perception.colour_scan import Scan, pack, scan, unproject
from plugins.perception.object_looks import rgb_of
from plugins.perception.object_tracking import Detections
from plugins.perception.synthetic_vision import SyntheticVision
from toolkit import ConfigError, Parameter, hookimpl
from toolkit.motion import facing_vector

__all__ = ["RenderedVision", "QUANTISATION"]

QUANTISATION = 0.3
"""Standard deviation, in pixels, of a rendered centroid from the true centre's projection: a blob of a few pixels is
cut by the pixel grid, and a part half hidden is found at the middle of what shows (measured by ``likeme bench
vision``: the median error is about this share of a pixel's footprint)."""

_NEAR = 0.05  # metres: the near clipping plane (the z-buffer's precision is best close to it)


class RenderedVision(SyntheticVision):
    """Colour-coded rendering from the observer's eye, scanned for each part's colour, depth from the z-buffer (§4.2)."""

    name = "rendered-vision"
    parameters = SyntheticVision.parameters + (
        Parameter("resolution", int, 480, "Width and height (pixels) of the rendered view.", minimum=16, maximum=2048),
        Parameter("min_pixels", int, 1, "Pixels of a part's colour needed to see it.", minimum=1),
        Parameter("min_share", float, 0.0, "Share of the disc a part's sphere would fill in the picture, unhidden, "
                  "that must show for the part to be seen: a part mostly covered is taken as hidden (the centroid "
                  "of the sliver that shows is not where the part is). 0: any pixel of its colour, as the paper "
                  "scans.", minimum=0.0, maximum=1.0),
        Parameter("pixel_noise", float, 0.25, "Standard deviation (pixels) of each centroid's jitter from frame to "
                  "frame: the camera's noise across the line of sight.", minimum=0.0, maximum=100.0),
        Parameter("depth_noise", float, 0.002, "Standard deviation of each depth reading, as a share of the depth: "
                  "the camera's noise along the line of sight.", minimum=0.0, maximum=1.0),
        Parameter("limb_radius", float, 0.0, "Radius (m) of the cylinder drawn along each bone of the watched body "
                  "(0: none, only the parts' spheres): limbs hide what is behind them.", minimum=0.0),
        Parameter("limb_colour", str, "#505050", "The colour limbs are drawn in (not a part's or an object's: the "
                  "observer knows it as body, which hides but is not tracked)."),
    )

    def attach(self, owner: Any) -> None:
        self._pl = None
        super().attach(owner)
        if rgb_of(self.params["limb_colour"]) is None:
            raise ConfigError(f"invalid colour {self.params['limb_colour']!r}", key=("limb_colour",),
                              expected='a colour "#rrggbb"')
        self._camera_rng = np.random.default_rng(self.params["seed"] + 1)
        self.close()
        self._known_colours(owner, owner.body)  # the colours it knows its own parts by (and another's): distinct

    def reset(self, fps: float) -> None:
        super().reset(fps)
        self._camera_rng = np.random.default_rng(self.params["seed"] + 1)
        self.close()

    def close(self) -> None:
        """Close the off-screen plotter (it is made again on the next frame)."""
        if getattr(self, "_pl", None) is not None:
            self._pl.close()
        self._pl = None
        self._body: Any = None
        self._part_uv: np.ndarray | None = None
        self._last: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None  # eye, axes (3, 3), depth image

    def __del__(self) -> None:  # pragma: no cover - best effort on interpreter exit
        try:
            self.close()
        except Exception:
            pass

    # -- the scene -------------------------------------------------------------------------------------------------

    def _scene(self, observer: Any, body: Any, n_objects: int) -> None:
        """The plotter with the watched body's parts and limbs and room for ``n_objects`` objects (made once per
        body; the spheres made again when more objects are in the world); the colours the observer knows each part
        by."""
        from vtkmodules.vtkCommonCore import vtkFloatArray, vtkUnsignedCharArray

        if self._pl is None or self._body is not body:
            self.close()
            size = self.params["resolution"]
            self._pl = plotter((size, size), background="black", flat=True)
            self._pixels, self._depths = vtkUnsignedCharArray(), vtkFloatArray()
            self._body = body
            self._parts = np.flatnonzero(~body.angle_mask)  # fingers are angles carried by a wrist: not drawn
            self._worn = np.array([rgb_of(c) for c in part_colours(body)], dtype=np.uint8)[self._parts]
            bones = [(a, b) for a, b in body.bone_indices() if not body.angle_mask[a] and not body.angle_mask[b]]
            self._bones = np.array(bones, dtype=int).reshape(-1, 2) if self.params["limb_radius"] > 0 else \
                np.zeros((0, 2), int)
            self._limbs = TubeSet(self._pl, len(self._bones), self.params["limb_colour"])
            self._spheres: SphereSet | None = None
            self._codes = self._known_colours(observer, body)
        if self._spheres is None or self._spheres.n < len(self._parts) + n_objects:
            room = 0 if self._spheres is None else self._spheres.n - len(self._parts)
            if self._spheres is not None:
                self._pl.remove_actor(self._spheres.actor, render=False)
            self._spheres = SphereSet(self._pl, len(self._parts) + max(n_objects, 2 * room, 4))

    def _known_colours(self, observer: Any, body: Any) -> dict[int, int]:
        """Packed colour (``r << 16 | g << 8 | b``) to the watched body's part index, as the observer knows the
        colours: its own part of that name wears it. -1 is the limbs' colour (body, not tracked)."""
        own = dict(zip(observer.body.parts, part_colours(observer.body)))
        codes: dict[int, int] = {int(pack(rgb_of(self.params["limb_colour"]))): -1}
        for i in np.flatnonzero(~body.angle_mask):
            name = body.parts[i]
            if name not in own:
                continue  # a part the observer has not got: it does not know what to look for
            code = int(pack(rgb_of(own[name])))
            whose = f"{getattr(observer, 'character', observer).name}'s [body.colours]"
            if code == 0:
                raise ConfigError(f"{whose}: part {name!r} is black, the colour of the empty background",
                                  expected="another colour for it")
            if code in codes:
                other = "the limbs (limb_colour)" if codes[code] < 0 else repr(body.parts[codes[code]])
                raise ConfigError(f"{whose}: part {name!r} and {other} look alike ({own[name]}), and colour-coded "
                                  "vision tells parts apart by colour alone", expected="a colour of its own for each part")
            codes[code] = int(i)
        return codes

    # -- looking ---------------------------------------------------------------------------------------------------

    def look(self, observer: Any, target: Any, world: Any) -> tuple[np.ndarray, np.ndarray, Detections]:
        truth = target.world_pose()
        shown = [o for o in world.objects.values() if o.held_by != observer.id]  # not what the observer holds itself
        self._scene(observer, target.body, len(shown))
        self._target_id = target.id
        radii = self._radii(target.body)
        places = self._places(target.body, truth)
        keys, rows, cols, depth, eye, axes = self._render(observer, places, radii, shown)
        n = target.body.n_parts
        if getattr(self, "_part_uv", None) is None or len(self._part_uv) != n:
            self._part_uv = np.full((n, 2), np.nan)  # where each part was last found in the picture
        found = scan(keys, rows, cols, depth, self._codes, n, self.params["min_pixels"], self._part_uv)
        at = found.part_pixels > 0
        self._part_uv[at] = np.column_stack([found.part_u, found.part_v])[at]
        positions, seen = self._parts_seen(found, radii, eye, axes)
        parts, sees = self._hand_percepts(target.body, truth, positions, seen)
        return np.where(sees[:, None], parts, np.nan), sees, self._objects_seen(found, eye, axes)

    def _render(self, observer: Any, places: np.ndarray, radii: np.ndarray, shown: list[Any]
                ) -> tuple[np.ndarray, ...]:
        """Place everything, render once, and read back the drawn pixels: their packed colours, rows (from the top),
        columns and depths (metres along the view axis); and the eye and its axes (right, up, forward) (3, 3)."""
        from vtkmodules.util.numpy_support import vtk_to_numpy

        eye = self.eye(observer)
        view_angle = min(self.params["fov"], 170.0)
        size = self.params["resolution"]
        pixel = 2 * np.tan(np.radians(view_angle) / 2) / size  # a pixel's footprint per metre of depth, centre
        distance = np.linalg.norm(np.nan_to_num(places) - eye, axis=1)
        drawn = np.maximum(radii, 1.5 * pixel * distance)  # under about two pixels across a sphere may vanish
        self._drawn = drawn
        slots = self._spheres.n
        centres, sizes = np.zeros((slots, 3)), np.zeros(slots)
        colours = np.zeros((slots, 3), dtype=np.uint8)
        k = len(self._parts)
        finite = np.isfinite(places[self._parts]).all(axis=1)
        centres[:k], sizes[:k], colours[:k] = places[self._parts], np.where(finite, drawn[self._parts], 0.0), self._worn
        for j, obj in enumerate(shown):
            if np.isfinite(obj.position).all():
                centres[k + j], sizes[k + j] = self._where_drawn(obj, places, drawn), float(obj.radius)
                colours[k + j] = rgb_of(obj.colour)
        self._spheres.update(centres, sizes, colours)
        self._limbs.update(places[self._bones[:, 0]], places[self._bones[:, 1]], self.params["limb_radius"])
        forward = facing_vector(observer.heading)
        up = np.array([0.0, 1.0, 0.0])
        right = np.cross(forward, up)
        far = max(self.params["range"], 2 * _NEAR)
        camera = self._pl.renderer.GetActiveCamera()  # VTK's own: pyvista's setters reset the clipping range
        camera.SetPosition(*eye)
        camera.SetFocalPoint(*(eye + forward))
        camera.SetViewUp(*up)
        camera.SetViewAngle(view_angle)
        camera.SetClippingRange(_NEAR, far)
        axes = np.stack([right, up, forward])
        window = self._pl.ren_win
        window.Render()
        top, left, bottom, right_col = _window(centres, sizes, eye, axes, size, view_angle)
        height, width = bottom - top + 1, right_col - left + 1
        # read back only the rectangle everything drawn falls in (OpenGL counts rows from the bottom)
        window.GetRGBACharPixelData(left, size - 1 - bottom, right_col, size - 1 - top, 0, self._pixels, 0)
        window.GetZbufferData(left, size - 1 - bottom, right_col, size - 1 - top, self._depths)
        z = vtk_to_numpy(self._depths).reshape(height, width)[::-1]  # top row first
        at_row, at_col = np.nonzero(z < 1.0)
        keys = vtk_to_numpy(self._pixels).reshape(height, width, 4)[::-1][at_row, at_col].copy().view(np.uint32)[:, 0]
        depth = _metres(z[at_row, at_col], far)
        self._last = (eye, axes, z.copy(), (top, left), far)
        return keys & 0xFFFFFF, at_row + top, at_col + left, depth, eye, axes

    def _where_drawn(self, obj: Any, places: np.ndarray, drawn: np.ndarray) -> np.ndarray:
        """Where an object is drawn: where it is, but one held in the watched body's hand (the world keeps it at the
        hand's centre) sits in the grip, at the hand's surface beyond the forearm, not inside the hand's sphere."""
        part = obj.properties.get("held_in") if obj.held_by is not None else None
        body = self._body
        if part is None or part not in body.parts or obj.held_by != self._target_id:
            return obj.position
        i = body.index(part)
        parents = [a for a, b in body.bone_indices() if b == i and not body.angle_mask[a]]
        if not parents or not np.isfinite(places[[parents[0], i]]).all():
            return obj.position
        along = places[i] - places[parents[0]]
        length = float(np.linalg.norm(along))
        return obj.position if length < 1e-9 else obj.position + along / length * drawn[i]

    def _noisy(self, u: np.ndarray, v: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The camera's noise on centroids (pixels) and depths (relative)."""
        if self.params["pixel_noise"] > 0:
            u = u + self._camera_rng.normal(0.0, self.params["pixel_noise"], u.shape)
            v = v + self._camera_rng.normal(0.0, self.params["pixel_noise"], v.shape)
        if self.params["depth_noise"] > 0:
            z = z * (1.0 + self._camera_rng.normal(0.0, self.params["depth_noise"], z.shape))
        return u, v, z

    def _to_world(self, u: np.ndarray, v: np.ndarray, z: np.ndarray, eye: np.ndarray, axes: np.ndarray) -> np.ndarray:
        size = self.params["resolution"]
        local = unproject(u, v, z, (size, size), min(self.params["fov"], 170.0))  # (n, 3): right, up, forward
        return eye + local @ axes

    def _parts_seen(self, found: Scan, radii: np.ndarray, eye: np.ndarray, axes: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
        seen = found.part_pixels >= self.params["min_pixels"]
        if self.params["min_share"] > 0:
            pixel = 2 * np.tan(np.radians(min(self.params["fov"], 170.0)) / 2) / self.params["resolution"]
            with np.errstate(invalid="ignore", divide="ignore"):  # the disc it fills unhidden, at its depth
                disc = np.pi * (self._drawn / (pixel * (found.part_near + self._drawn))) ** 2
            seen &= found.part_pixels >= self.params["min_share"] * np.where(np.isfinite(disc), disc, np.inf)
        positions = np.full((len(seen), 3), np.nan)
        if seen.any():
            u, v, z = self._noisy(found.part_u[seen], found.part_v[seen], found.part_near[seen] + self._drawn[seen])
            positions[seen] = self._to_world(u, v, z, eye, axes)
        seen &= np.linalg.norm(np.nan_to_num(positions - eye, nan=np.inf), axis=1) <= self.params["range"]
        return np.where(seen[:, None], positions, np.nan), seen

    def _objects_seen(self, found: Scan, eye: np.ndarray, axes: np.ndarray) -> Detections:
        keep = found.blob_pixels >= self.params["min_pixels"]
        if not keep.any():
            return Detections.none()
        size = self.params["resolution"]
        pixel = 2 * np.tan(np.radians(min(self.params["fov"], 170.0)) / 2) / size
        # the blob's apparent radius in pixels; a sphere of radius R whose nearest point is z away looks
        # R / (z + R) wide (per metre of depth), so R = a z / (1 - a) for an angular size a
        a = np.minimum(np.sqrt(found.blob_pixels[keep] / np.pi) * pixel, 0.9)
        near = found.blob_near[keep]
        radius = a * near / (1.0 - a)
        u, v, z = self._noisy(found.blob_u[keep], found.blob_v[keep], near + radius)
        positions = self._to_world(u, v, z, eye, axes)
        inside = np.linalg.norm(positions - eye, axis=1) <= self.params["range"]
        return Detections(positions[inside], radius[inside], found.blob_colours[keep][inside])

    def picture(self) -> np.ndarray:
        """What the eye saw in the last frame it rendered, as the observer scans it: (H, W, 3) RGB, top row first
        (black where nothing is). Empty (0, 0, 3) before the first frame."""
        from vtkmodules.util.numpy_support import vtk_to_numpy

        if self._pl is None or self._last is None:
            return np.zeros((0, 0, 3), dtype=np.uint8)
        from vtkmodules.vtkCommonCore import vtkUnsignedCharArray

        size = self.params["resolution"]
        pixels = vtkUnsignedCharArray()
        self._pl.ren_win.GetRGBACharPixelData(0, 0, size - 1, size - 1, 0, pixels, 0)  # the last frame, whole
        return vtk_to_numpy(pixels).reshape(size, size, 4)[::-1, :, :3].copy()

    # -- what the camera can tell ----------------------------------------------------------------------------------

    def position_uncertainty(self, distance: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """The standard deviation (m) of a seen position at ``distance`` (m) from the eye, across the line of sight
        and along it: a centroid is off by :data:`QUANTISATION` and ``pixel_noise`` pixels, each pixel ``distance``
        times its angular size wide; the depth by ``depth_noise`` of it and as much as a centroid across; both with
        the geometric ``noise`` added."""
        d = np.asarray(distance, dtype=float)
        pixel = 2 * np.tan(np.radians(min(self.params["fov"], 170.0)) / 2) / self.params["resolution"]
        noise = self.params["noise"]
        across = np.hypot(pixel * d * np.hypot(QUANTISATION, self.params["pixel_noise"]), noise)
        along = np.sqrt((self.params["depth_noise"] * d) ** 2 + (pixel * d * QUANTISATION) ** 2 + noise ** 2)
        return across, along

    def in_view(self, observer: Any, target: Any, world: Any, points: np.ndarray) -> np.ndarray:
        """Whether an object at each of ``points`` (n, 3) would have been seen in the last rendered frame: inside the
        picture, and the eye saw past where it was (the depth there is farther, or nothing is there). Where something
        nearer covers the place, or something about as far is there (another thing of its colour it may have merged
        with), the eye cannot tell it is gone."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        if self._last is None:
            return np.zeros(len(points), dtype=bool)
        eye, axes, z_buffer, (top, left), far = self._last
        local = (points - eye) @ axes.T  # right, up, forward
        size = self.params["resolution"]
        tan = np.tan(np.radians(min(self.params["fov"], 170.0)) / 2)
        depth = local[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = ((local[:, 0] / (depth * tan)) + 1) / 2 * size - 0.5
            v = (1 - local[:, 1] / (depth * tan)) / 2 * size - 0.5
        inside = np.isfinite(points).all(axis=1) & (depth > _NEAR) & (np.abs(u + 0.5 - size / 2) < size / 2) & \
            (np.abs(v + 0.5 - size / 2) < size / 2) & (np.linalg.norm(points - eye, axis=1) <= self.params["range"])
        out = np.zeros(len(points), dtype=bool)
        if inside.any():
            iu = np.clip(np.rint(u[inside]).astype(int), 0, size - 1) - left
            iv = np.clip(np.rint(v[inside]).astype(int), 0, size - 1) - top
            read = (iu >= 0) & (iu < z_buffer.shape[1]) & (iv >= 0) & (iv < z_buffer.shape[0])
            z = np.ones(len(iu))  # outside the rectangle read back nothing was drawn
            z[read] = z_buffer[iv[read], iu[read]]
            out[inside] = _metres(z, far) > depth[inside] + self.params["gate"]
        return out


def _window(centres: np.ndarray, radii: np.ndarray, eye: np.ndarray, axes: np.ndarray, size: int,
            view_angle: float) -> tuple[int, int, int, int]:
    """The rows and columns (top, left, bottom, right; rows from the top) of the rectangle of a ``size`` square
    picture that every drawn sphere (``radii`` > 0) falls in, with two pixels to spare; the whole picture when one
    reaches behind the eye. Limbs join spheres, so they fall in it too."""
    on = radii > 0
    if not on.any():
        return 0, 0, 0, 0
    local = (centres[on] - eye) @ axes.T  # right, up, forward
    z = local[:, 2]
    if (z - radii[on] <= _NEAR).any():
        return 0, 0, size - 1, size - 1
    tan = np.tan(np.radians(view_angle) / 2)
    scale = size / (2 * tan)  # pixels per unit of x / z
    reach = radii[on] / np.sqrt(np.maximum(z**2 - radii[on] ** 2, 1e-12))  # a sphere's angular half-width (tan)
    u, v = local[:, 0] / z, local[:, 1] / z
    grow = reach * (1 + u**2 + v**2)  # off the axis a sphere's image is wider
    left = int(np.floor(((u - grow).min() + tan) * scale - 2))
    right = int(np.ceil(((u + grow).max() + tan) * scale + 2))
    top = int(np.floor((tan - (v + grow).max()) * scale - 2))
    bottom = int(np.ceil((tan - (v - grow).min()) * scale + 2))
    clip = lambda x: min(max(x, 0), size - 1)  # noqa: E731
    return clip(top), clip(left), max(clip(bottom), clip(top)), max(clip(right), clip(left))


def _metres(z: np.ndarray, far: float) -> np.ndarray:
    """Depth-buffer values (0..1, non-linear) to metres along the view axis (inf where nothing was drawn)."""
    z = np.asarray(z, dtype=float)
    with np.errstate(divide="ignore"):
        depth = 2 * _NEAR * far / ((far + _NEAR) - (2 * z - 1) * (far - _NEAR))
    return np.where(z >= 1.0, np.inf, depth)


@hookimpl
def likeme_register_perceptions():
    return [RenderedVision]
