"""Writing BVH files: the text of a :class:`~toolkit.recordings.bvh.BVH`, and a BVH made from joint positions.

likeme writes its own characters' motions (``likeme bench make-data``) as BVH files whose every joint has position
channels only, relative to its parent: forward kinematics of what is written gives back the positions it was made
from, to the precision written.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from toolkit.recordings.bvh import BVH, Joint

__all__ = ["format_bvh", "write_bvh", "from_joint_positions"]


def _number(x: float) -> str:
    return format(float(x), ".9g")


def format_bvh(bvh: BVH, *, precision: int = 6) -> str:
    """The text of a BVH file for ``bvh`` (values to ``precision`` significant digits)."""
    children: dict[int, list[int]] = {}
    for i, j in enumerate(bvh.joints):
        children.setdefault(j.parent, []).append(i)
    out = ["HIERARCHY"]
    starts = np.concatenate([[0], np.cumsum([len(j.channels) for j in bvh.joints])]).astype(int)
    columns: list[int] = []  # the value columns in the order the hierarchy names their joints (depth first)

    stack: list[tuple[int, int, bool]] = [(root, 0, False) for root in reversed(children.get(-1, []))]
    while stack:  # depth first, without recursion (a hierarchy may be deep)
        i, depth, closing = stack.pop()
        joint, pad = bvh.joints[i], "  " * depth
        if closing:
            out.append(f"{pad}}}")
            continue
        off = " ".join(_number(v) for v in joint.offset)
        if joint.end_site:
            out.extend([f"{pad}End Site", f"{pad}{{", f"{pad}  OFFSET {off}", f"{pad}}}"])
            continue
        out.append(f"{pad}{'ROOT' if joint.parent < 0 else 'JOINT'} {joint.name}")
        out.append(f"{pad}{{")
        out.append(f"{pad}  OFFSET {off}")
        out.append(f"{pad}  CHANNELS {len(joint.channels)} {' '.join(joint.channels)}".rstrip())
        columns.extend(range(starts[i], starts[i + 1]))
        stack.append((i, depth, True))
        stack.extend((c, depth + 1, False) for c in reversed(children.get(i, [])))
    out += ["MOTION", f"Frames: {bvh.n_frames}", f"Frame Time: {bvh.frame_time:.9g}"]
    fmt = f"%.{precision}g"
    values = np.asarray(bvh.values)
    if len(columns) == values.shape[1] and columns != list(range(len(columns))):
        values = values[:, columns]
    out.extend(" ".join(fmt % v for v in row) for row in values)
    return "\n".join(out) + "\n"


def write_bvh(bvh: BVH, path: str | Path, *, precision: int = 6) -> Path:
    """Write ``bvh`` to ``path`` atomically (temporary file, flush, rename); returns the path."""
    from toolkit.state import write_atomic

    path = Path(path)
    write_atomic(path, format_bvh(bvh, precision=precision))
    return path


def from_joint_positions(names: Sequence[str], parents: Sequence[int], positions: np.ndarray, fps: float,
                         source: str = "<generated>") -> BVH:
    """A BVH that reproduces given joint positions (F, J, 3) with position channels only.

    Every joint gets ``Xposition Yposition Zposition`` channels relative to its
    parent (world-aligned, no rotations), which is how likeme writes its own
    characters' motions: forward kinematics of the result gives back ``positions``.
    """
    positions = np.asarray(positions, dtype=float)
    joints, columns = [], []
    for j, (name, parent) in enumerate(zip(names, parents)):
        local = positions[:, j] - (positions[:, parent] if parent >= 0 else 0.0)
        joints.append(Joint(name, parent, tuple(float(v) for v in local[0]), ("Xposition", "Yposition", "Zposition")))
        columns.append(local)
    return BVH(joints, 1.0 / fps, np.concatenate(columns, axis=1), source)
