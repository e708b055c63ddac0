"""A stick figure small enough to work path search out by hand: five parts whose hand either rises (``raise``) or
goes forward (``reach``) and back, 0.5 s out and 0.5 s back, sampled at 10 pose nodes a second: each movement is a
path of nine nodes out of the hub and back."""

from __future__ import annotations

import numpy as np

from toolkit import Motion

STICK = """
[character]
name = "Stick"

[body]
parts = ["root", "head", "lk", "rk", "hand"]
root = "root"
facing = { left = "lk", right = "rk", forward = "head" }

[motor]
plugin = "posegraph"
node_rate = 10.0

[motor.poses.stand]
root = [0.0, 1.0, 0.0]
head = [0.0, 1.6, 0.1]
lk = [0.1, 0.5, 0.0]
rk = [-0.1, 0.5, 0.0]
hand = [0.3, 1.0, 0.0]

[motor.poses.up]
base = "stand"
hand = [0.3, 1.6, 0.0]

[motor.poses.front]
base = "stand"
hand = [0.3, 1.0, 0.6]

[motor.movements.raise]
keys = [{ pose = "stand", at = 0.0 }, { pose = "up", at = 0.5 }, { pose = "stand", at = 1.0 }]

[motor.movements.reach]
keys = [{ pose = "stand", at = 0.0 }, { pose = "front", at = 0.5 }, { pose = "stand", at = 1.0 }]

[matcher]
plugin = "path-search"
"""

FPS = 30.0


def observed(stick, movement: str, *, speed: float = 1.0, offset=(0.0, 0.0, 0.0), hidden: str | None = None) -> Motion:
    """The stick's own movement, root-relative as an observer perceives it, the hand moved by ``offset``."""
    motion = stick.motor.perform(movement, fps=FPS, speed=speed).root_relative(stick.body.root)
    positions = motion.positions.copy()
    positions[:, stick.body.index("hand")] += offset
    visible = np.ones(positions.shape[:2], dtype=bool)
    if hidden is not None:
        visible[:, stick.body.index(hidden)] = False
    return Motion(positions, FPS, motion.parts, visible)
