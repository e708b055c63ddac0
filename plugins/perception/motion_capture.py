"""Perception ``motion-capture``: every part of the target, exactly, as a tracking suit reports it.

The perfect-input baseline for the perception stage: no field of view, no
occlusion, no noise. Objects are tracked too, exactly, and known by their look (colour and size,
:mod:`plugins.perception.object_looks`) under the observer's own names, as the vision perceptions know them. The world positions are converted to root-relative
coordinates with the facing found from the body's facing parts (Buchsbaum &
Blumberg 2005, §5.1, see :mod:`plugins.lib.root_frame`), so the result is what the
``synthetic-vision`` perception gives when nothing is hidden.
"""

from __future__ import annotations

import numpy as np

from plugins.lib.root_frame import HeadingFilter, root_relative
from plugins.perception.object_looks import rgb_of
from plugins.perception.object_tracking import OBJECT_PARAMETERS, Detections, tracker_for
from toolkit import Parameter, Percept, Perception, hookimpl


class MotionCapture(Perception):
    """Sees every part of the target exactly (no occlusion or noise); root-relative by §5.1."""

    name = "motion-capture"
    watches_recordings = True
    parameters = (
        Parameter("facing_window", float, 3.0, "Seconds over which the target's facing is a running median "
                  "(steady through kicks and head turns; a real turn is followed after half of it), the forward "
                  "marker's side the vote of its frames (0: every frame on its own).", minimum=0.0, maximum=60.0),
        *OBJECT_PARAMETERS,
    )

    def attach(self, owner) -> None:
        super().attach(owner)
        self._objects = tracker_for(self.params)  # checks the looks now, at the character's load

    def reset(self, fps: float) -> None:
        self._facing = HeadingFilter(round(self.params["facing_window"] * fps))
        self._objects = tracker_for(self.params, fps)

    @property
    def _window(self) -> HeadingFilter:
        """The facing's running median (and the forward marker's vote) over the frames so far (made by
        :meth:`reset`); a frame on its own (a world's step) takes :meth:`HeadingFilter.update`'s path."""
        facing = getattr(self, "_facing", None)
        if facing is None:
            raise RuntimeError("perceive before reset(fps): an observer resets its perception when it begins watching")
        return facing

    def perceive(self, observer, target, world) -> Percept:
        percept = self.perceive_pose(target.world_pose(), None, target.body, world.time)
        shown = list(world.objects.values())  # every object's marker: where, how big, what colour (not its name or kind)
        objects, kinds, sizes = self._objects.update(Detections(
            np.array([o.position for o in shown], dtype=float).reshape(-1, 3), np.array([o.radius for o in shown], dtype=float),
            np.array([rgb_of(o.colour) for o in shown], dtype=float).reshape(-1, 3)))
        return Percept(percept.time, percept.pose, percept.visible, percept.world, percept.root, percept.heading, objects,
                       kinds, sizes)

    def in_view(self, observer, target, world, points) -> np.ndarray:
        """Every object is tracked: one not reported where it was is gone."""
        return np.ones(len(np.asarray(points).reshape(-1, 3)), dtype=bool)

    def perceive_pose(self, positions, visible, body, time) -> Percept:
        """Root-relative percept of recorded world positions (P, 3); non-finite or masked parts are not seen."""
        positions = np.asarray(positions, dtype=float)
        pose, mask, root, heading = root_relative(positions[None], None if visible is None else np.asarray(visible)[None],
                                                  body, self._window)
        world = np.where(mask[0, :, None], positions, np.nan)
        return Percept(time, pose[0], mask[0], world, root[0], float(heading[0]))

    def perceive_poses(self, positions, visible, body, times) -> tuple[np.ndarray, np.ndarray]:
        """A block of recorded frames (n, P, 3) at once: the same poses and masks as one perceive_pose per frame."""
        pose, mask, _, _ = root_relative(positions, visible, body, self._window)
        return pose, mask


@hookimpl
def likeme_register_perceptions():
    return [MotionCapture]
