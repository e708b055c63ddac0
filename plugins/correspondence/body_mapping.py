"""Correspondence ``body-mapping``: the demonstrator's size and rest posture replaced by the observer's own.

Buchsbaum & Blumberg 2005, §7.1 and Kopp & Graeser 2006, §6 leave the correspondence problem open: their observers
compare another body's poses directly with their own, which works when the other is built and stands like
oneself (Max and Morris) and fails for real people, who differ in size, proportions, stance and rest posture. This
plugin makes the other's movement comparable with one's own in two steps, each a parameter, both estimated from
the frames seen so far (causal: a live observer can do it, and the result does not depend on packet sizes):

1. ``size = "bones"``: the observer's rigid links (pairs of parts whose distance stays the same through its own
   movements, :func:`plugins.lib.body_size.rigid_pairs`; a skeleton's bones among them) are measured on the
   demonstrator as they are seen (a running mean); the body is scaled by the ratio of their summed lengths and
   every bone that is a rigid link is set to its own ratio, along the demonstrator's bone direction
   (:func:`plugins.lib.body_size.retarget`). A body with no rigid link (a character animated part by part from
   key poses) has no measurable size and is not rescaled;
2. ``rest = "dwell"``: the demonstrator's rest posture is estimated from where they dwell
   (:class:`plugins.lib.rest_posture.RestPosture`) and the movement is taken relative to it and mapped onto the
   observer's own hub: ``pose - their rest + own hub``. A stooped, wide-legged or proud stance then reads as
   rest, and a bow as a bow.

``size = "none"`` and ``rest = "none"`` switch a step off; with no ``[correspondence]`` table at all a character
watches as the papers' observers do. The observer's own body is its motor system's rest pose (the hub):
its bone lengths, its size (:func:`plugins.lib.body_size.body_scale`) and the posture movement is mapped onto.
Fingers (joint angles) pass through unchanged.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import Any

import numpy as np

from plugins.lib.body_size import RunningLengths, body_scale, bone_lengths, bone_tree, retarget, rigid_pairs
from plugins.lib.rest_posture import RestPosture
from toolkit import ConfigError, Correspondence, Parameter, hookimpl

__all__ = ["BodyMapping"]


class BodyMapping(Correspondence):
    """The demonstrator's size and rest posture, estimated as they are seen, replaced by one's own (§7.1)."""

    name = "body-mapping"
    parameters = (
        Parameter("size", str, "bones", "How the demonstrator's size is mapped: 'bones' (every bone at the "
                  "observer's length, along the demonstrator's direction) or 'none'.", choices=("bones", "none")),
        Parameter("rest", str, "dwell", "How the demonstrator's rest posture is found: 'dwell' (where they are "
                  "slow for a while, mapped onto the observer's hub; [correspondence.dwell] says how) or 'none' "
                  "(their rest is taken as one's own).", choices=("dwell", "none")),
        Parameter("dwell", doc="With rest = 'dwell': what counts as dwelling, and how long it is remembered "
                  "(plugins.lib.rest_posture.RestPosture).", parameters=(
                      Parameter("speed", float, 0.05, "Speed in body sizes per second (the observer's size, about "
                                "0.45 m for an adult) at which a pose counts a quarter as much towards the rest "
                                "posture as a still one.", minimum=1e-6),
                      Parameter("window", float, 0.5, "Seconds over which the speed is smoothed: slow for an "
                                "instant (a turning point) is not dwelling.", minimum=0.0),
                      Parameter("memory", float, 30.0, "Time constant (s) with which the rest estimate forgets: a "
                                "demonstrator who changes stance is followed after about this long.", minimum=0.1),
                  )),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        body = owner.body
        rest = np.asarray(owner.motor.rest_pose(), dtype=float)
        if rest.shape != (body.n_parts, 3):
            raise ConfigError("the motor system's rest pose does not fit the body", key=("plugin",),
                              expected=f"a rest pose of shape ({body.n_parts}, 3)", available=[str(rest.shape)])
        self.root = body.root_index
        self.positions = ~body.angle_mask  # fingers are joint angles: never mapped
        self.hub = rest - rest[self.root]
        self.tree = bone_tree(body.parts, body.bones, body.parts[self.root], skip=body.angle_parts)
        own = [(m.positions, m.visible) for _, m in owner.motor.examples()]
        self.pairs, self.own_lengths = rigid_pairs(own, self.positions)
        where = {(int(i), int(j)): k for k, (i, j) in enumerate(self.pairs)}
        self.bone_pair = np.array([where.get((min(i, j), max(i, j)), -1) for i, j in self.tree], dtype=np.intp)
        self.size = body_scale(self.hub, self.positions)
        if self.size <= 0:
            raise ConfigError("the motor system's rest pose has no size", key=("plugin",),
                              expected="a rest pose with at least two distinct parts")
        self.reset(body.parts, 30.0)

    def reset(self, parts: Sequence[str], fps: float) -> None:
        self._fps = float(fps)
        self._lengths = RunningLengths(len(self.pairs))
        dwell = self.params["dwell"]
        self._rest = RestPosture(len(self.hub), self._fps, dwell_speed=dwell["speed"], window=dwell["window"],
                                 memory=dwell["memory"], prior=self.hub)

    def map_block(self, poses: np.ndarray, visible: np.ndarray) -> np.ndarray:
        poses = np.asarray(poses, dtype=float)
        visible = np.asarray(visible, dtype=bool)
        if not len(poses):
            return poses.copy()
        root = poses[:, self.root : self.root + 1]
        rel = poses - root
        out = self._resize(rel, visible) if self.params["size"] == "bones" else rel
        if self.params["rest"] == "dwell":
            out = out - self._rest.update(out, visible, self.size) + self.hub
        out = out + root
        out[:, ~self.positions] = poses[:, ~self.positions]
        return out

    def _resize(self, rel: np.ndarray, visible: np.ndarray) -> np.ndarray:
        """The demonstrator's rigid links measured so far against one's own: the whole body scaled by the ratio of
        their summed lengths, then each bone that is a rigid link set to its own ratio (see the module)."""
        if not len(self.pairs):  # nothing rigid in one's own body: size cannot be measured
            return rel
        theirs = self._lengths.update(bone_lengths(rel, visible, self.pairs))
        known = np.isfinite(theirs) & (theirs > 1e-9)
        with np.errstate(invalid="ignore", divide="ignore"):
            whole = (np.where(known, self.own_lengths, 0.0).sum(axis=1) / np.where(known, theirs, 0.0).sum(axis=1))
        whole = np.where(np.isfinite(whole) & (whole > 0), whole, 1.0)
        out = rel * whole[:, None, None]
        if not len(self.tree):
            return out
        rigid = self.bone_pair >= 0
        cols = np.where(rigid, self.bone_pair, 0)
        with np.errstate(invalid="ignore", divide="ignore"):
            own = self.own_lengths[cols] / np.where(known[:, cols], theirs[:, cols], 1.0)
        ratio = np.where(rigid & known[:, cols], own / whole[:, None], 1.0)
        return retarget(out, self.tree, ratio, self.root)

    def inspect(self) -> Mapping[str, Any]:
        """The current estimates: the demonstrator's rest posture (root-relative, after resizing; one's own hub
        until they have been seen still) and the lengths of the rigid links on them, and the observer's own."""
        return MappingProxyType({
            "rest": self._rest.current if self.params["rest"] == "dwell" else None,
            "hub": self.hub.copy(),
            "their_lengths": self._lengths.mean,
            "own_lengths": self.own_lengths.copy(),
            "rigid_pairs": [(self.owner.body.parts[i], self.owner.body.parts[j]) for i, j in self.pairs],
            "size": self.size,
        })


@hookimpl
def likeme_register_correspondences():
    return [BodyMapping]
