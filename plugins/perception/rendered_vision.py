"""Perception ``rendered-vision``: colour-coded synthetic vision by really rendering the observer's view.

Buchsbaum & Blumberg 2005, §4.2: "the world is rendered from the observer's eye
with each body part and object in its own flat colour; the image is scanned for
each colour, the centroid of each colour in screen space and the depth buffer
give its 3D position in the eye's frame". This plugin does exactly that with an
off-screen pyvista/VTK render:

1. one flat-coloured sphere per part of the watched actor (radius as in
   ``synthetic-vision``: ``part_radius`` and ``radii``, but never under about
   three pixels across, or the rasteriser may drop it) and per object, each
   with a unique colour code; no lights, no anti-aliasing, so every pixel of a
   part has exactly its code;
2. a camera at the observer's eye looking where the observer faces, with a
   ``fov`` view angle (at most 170°: a pinhole camera cannot see behind
   itself) and the perception's ``range`` as far clipping plane, at
   ``resolution`` pixels square;
3. every colour code found in at least ``min_pixels`` pixels is a seen part;
   its centroid (u, v) and the nearest depth over its pixels plus the sphere's
   radius give the centre's depth ``z``; the pinhole model turns (u, v, z) back
   into a 3D point in the eye frame and then in the world.

Occlusion comes from the depth test of the render itself, not from geometry.
Everything after this (noise, dropouts, the sensory buffer, the facing filter,
root-relative coordinates) is :class:`plugins.perception.synthetic_vision.SyntheticVision`'s,
so the two perceptions are interchangeable in a character file and can be
compared on the same scenes (``tests/test_rendered_vision.py``; the speed cost
is in ``docs/benchmarks.md``). The plotter is made once and reused for every
frame, and closed by :meth:`RenderedVision.close` and on :meth:`reset`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from plugins.lib.rendering import plotter
from plugins.perception.synthetic_vision import SyntheticVision
from toolkit import Parameter, hookimpl
from toolkit.motion import facing_vector

__all__ = ["RenderedVision", "colour_code", "unproject"]

_STEP = 40


def colour_code(i: int) -> tuple[int, int, int]:
    """A flat colour for code ``i`` (0..214), every channel a multiple of 40 from 40: codes differ by ≥ 40 per channel."""
    c = i + 1
    return _STEP * (c % 6) + 15, _STEP * (c // 6 % 6) + 15, _STEP * (c // 36 % 6) + 15


def unproject(u: np.ndarray, v: np.ndarray, z: np.ndarray, size: tuple[int, int], view_angle: float) -> np.ndarray:
    """Pixel centroids (column ``u``, row ``v`` from the top) at depth ``z`` to eye-frame points (right, up, forward)."""
    w, h = size
    tan_v = np.tan(np.radians(view_angle) / 2)
    tan_h = tan_v * w / h
    x = (2 * (u + 0.5) / w - 1) * tan_h * z
    y = (1 - 2 * (v + 0.5) / h) * tan_v * z
    return np.stack([x, y, z], axis=-1)


class RenderedVision(SyntheticVision):
    """Colour-coded rendering from the observer's eye, scanned for each part's colour, depth from the z-buffer (§4.2)."""

    name = "rendered-vision"
    parameters = SyntheticVision.parameters + (
        Parameter("resolution", int, 480, "Width and height (pixels) of the rendered view.", minimum=16, maximum=2048),
        Parameter("min_pixels", int, 1, "Pixels of a part's colour needed to see it.", minimum=1),
    )

    def attach(self, owner: Any) -> None:
        self._pl = None
        super().attach(owner)
        self.close()

    def reset(self, fps: float) -> None:
        super().reset(fps)
        self.close()

    def close(self) -> None:
        """Close the off-screen plotter (it is made again on the next frame)."""
        if getattr(self, "_pl", None) is not None:
            self._pl.close()
        self._pl = None
        self._spheres: list[Any] = []

    def __del__(self) -> None:  # pragma: no cover - best effort on interpreter exit
        try:
            self.close()
        except Exception:
            pass

    def _scene(self, n: int) -> list[Any]:
        """The plotter with ``n`` flat spheres (made or grown once, then moved and resized per frame)."""
        import pyvista as pv

        if self._pl is None:
            size = self.params["resolution"]
            self._pl = plotter((size, size), background="black", flat=True)
            self._spheres = []
        while len(self._spheres) < n:
            code = colour_code(len(self._spheres))
            actor = self._pl.add_mesh(pv.Sphere(radius=1.0, theta_resolution=24, phi_resolution=16),
                                      color=[c / 255 for c in code], lighting=False, render=False)
            self._spheres.append(actor)
        return self._spheres

    def look(self, observer: Any, target: Any, world: Any) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
        truth = target.world_pose()
        eye = observer.world_pose()[observer.body.index(self.params["eye"])]
        names = list(world.objects)
        centres = np.array([world.objects[n].position for n in names], dtype=float).reshape(-1, 3)
        # an object the observer holds is not in its view of the world (as in synthetic-vision)
        shown = np.array([world.objects[n].held_by != observer.id for n in names], dtype=bool)
        radii = np.concatenate([self._radii(target.body), [world.objects[n].radius for n in names]])
        points = np.concatenate([self._places(target.body, truth), centres])
        positions, seen = self.render_view(eye, observer.heading, points, radii,
                                           np.concatenate([np.ones(len(truth), bool), shown]))
        n = len(truth)
        objects = {name: positions[n + i].copy() for i, name in enumerate(names) if seen[n + i]}
        parts, found = self._hand_percepts(target.body, truth, positions[:n], seen[:n])
        return np.where(found[:, None], parts, np.nan), found, objects

    def render_view(self, eye: np.ndarray, heading: float, points: np.ndarray, radii: np.ndarray,
                    shown: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Render spheres at ``points`` from ``eye`` facing ``heading``; (estimated world positions, seen) of each."""
        spheres = self._scene(len(points))
        finite = np.isfinite(points).all(axis=1) & shown
        # a sphere under about two pixels across may not be rasterised at all: draw it at least that big
        pixel = 2 * np.tan(np.radians(min(self.params["fov"], 170.0)) / 2) / self.params["resolution"]  # at the centre
        radii = np.maximum(radii, 1.5 * pixel * np.linalg.norm(np.nan_to_num(points) - eye, axis=1))
        for i, actor in enumerate(spheres):
            on = i < len(points) and bool(finite[i])
            actor.SetVisibility(on)
            if on:
                actor.SetPosition(*points[i])
                actor.SetScale(float(max(radii[i], 1e-4)))
        forward = facing_vector(heading)
        up = np.array([0.0, 1.0, 0.0])
        right = np.cross(forward, up)
        view_angle = min(self.params["fov"], 170.0)
        camera = self._pl.camera
        camera.position = tuple(eye)
        camera.focal_point = tuple(eye + forward)
        camera.up = tuple(up)
        camera.view_angle = view_angle
        camera.clipping_range = (0.01, max(self.params["range"], 0.02))
        self._pl.camera_set = True  # or pyvista resets the camera to the scene's bounds on the first render
        self._pl.render()
        image = np.asarray(self._pl.screenshot(return_img=True))[..., :3].astype(np.int16)
        depth = -np.asarray(self._pl.get_image_depth(fill_value=np.nan, reset_camera_clipping_range=False))
        size = (image.shape[1], image.shape[0])
        n = len(points)
        # every pixel's code index: the nearest code within half a step on every channel
        index = np.rint((image - 15) / _STEP).astype(int)
        exact = (np.abs(image - (index * _STEP + 15)) <= _STEP // 2 - 1).all(axis=-1)
        pixel_code = index[..., 0] + 6 * index[..., 1] + 36 * index[..., 2] - 1
        rows, cols = np.nonzero(exact & (image.sum(axis=-1) > 0) & (pixel_code >= 0) & (pixel_code < n))
        code = pixel_code[rows, cols]
        # per code in one pass: pixel count, centroid, nearest finite depth
        count = np.bincount(code, minlength=n)
        with np.errstate(invalid="ignore", divide="ignore"):
            u = np.bincount(code, weights=cols, minlength=n) / count
            v = np.bincount(code, weights=rows, minlength=n) / count
        d = depth[rows, cols]
        near = np.full(n, np.inf)
        np.minimum.at(near, code[np.isfinite(d)], d[np.isfinite(d)])
        seen = finite & (count >= self.params["min_pixels"]) & np.isfinite(near)
        local = unproject(np.where(seen, u, 0.0), np.where(seen, v, 0.0), np.where(seen, near + radii, 1.0), size,
                          view_angle)  # (n, 3): right, up, forward
        positions = eye + local[:, :1] * right + local[:, 1:2] * up + local[:, 2:] * forward
        positions[~seen] = np.nan
        return positions, seen & (np.linalg.norm(np.nan_to_num(positions) - eye, axis=1) <= self.params["range"])


@hookimpl
def likeme_register_perceptions():
    return [RenderedVision]
