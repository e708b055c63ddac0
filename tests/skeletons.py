"""Generated recordings of a person in the joint names of other skeletons (Bandai-Namco, Kinect), for tests.

Nothing here comes from a dataset: a body 1.7 m tall is posed by hand (metres, +y up, facing +z, its left at +x)
and moved by a few lines of trigonometry (a bow, a wave, a slow turn), then written with another skeleton's joint
names, hierarchy, units and axes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from toolkit.bvh import BVH, Joint, from_joint_positions, write_bvh

REST = {  # metres, +y up, facing +z, left at +x
    "hips": (0.0, 0.95, 0.0), "spine": (0.0, 1.1, 0.0), "chest": (0.0, 1.3, 0.0), "neck": (0.0, 1.5, 0.0),
    "head": (0.0, 1.6, 0.03), "l_clavicle": (0.05, 1.42, 0.0), "l_shoulder": (0.18, 1.42, 0.0),
    "l_elbow": (0.21, 1.15, -0.02), "l_wrist": (0.23, 0.9, 0.02), "l_hip": (0.09, 0.9, 0.0),
    "l_knee": (0.1, 0.5, 0.03), "l_ankle": (0.1, 0.08, 0.0), "l_toes": (0.1, 0.02, 0.13),
}
REST.update({k.replace("l_", "r_"): (-x, y, z) for k, (x, y, z) in REST.items() if k.startswith("l_")})
NAMES = tuple(REST)


def _rot_x(points: np.ndarray, centre: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotate points (F, k, 3) about the x axis through ``centre`` by ``angle`` (F,) radians."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    p = points - centre
    y, z = p[..., 1], p[..., 2]
    return centre + np.stack([p[..., 0], c * y - s * z, s * y + c * z], axis=-1)


def human(movement: str, frames: int = 60, *, turn: float = 0.3, swing: bool = False) -> np.ndarray:
    """A person's joints (F, len(NAMES), 3), metres, +y up: ``rest``, ``bow`` (the trunk leans forward and back up),
    ``wave`` (the right hand rises and waves); the whole body turns by ``turn`` radians about +y over the clip.
    ``swing``: the left arm swings forward and back (its hand crosses the line across the hips again and again)."""
    rest = np.array([REST[n] for n in NAMES], dtype=float)
    pose = np.repeat(rest[None], frames, axis=0)
    t = np.linspace(0.0, 1.0, frames)
    upper = [NAMES.index(n) for n in NAMES if n in ("spine", "chest", "neck", "head") or n[2:] in
             ("clavicle", "shoulder", "elbow", "wrist")]
    if movement == "bow":
        pose[:, upper] = _rot_x(pose[:, upper], pose[:, [0]], 0.9 * np.sin(np.pi * t))
    elif movement == "wave":
        lift = np.sin(np.pi * t)[:, None]
        elbow, wrist = NAMES.index("r_elbow"), NAMES.index("r_wrist")
        pose[:, elbow] += lift * np.array([-0.15, 0.35, 0.1])
        pose[:, wrist] += lift * np.array([-0.2, 0.85, 0.15]) + \
            (lift * np.sin(6 * np.pi * t)[:, None]) * np.array([0.15, 0.0, 0.0])
    if swing:
        for name, reach in (("l_elbow", 0.15), ("l_wrist", 0.35)):
            pose[:, NAMES.index(name), 2] += reach * np.sin(2 * np.pi * 4 * t)
    heading = turn * t
    c, s = np.cos(heading)[:, None], np.sin(heading)[:, None]
    x, z = pose[..., 0].copy(), pose[..., 2].copy()
    pose[..., 0], pose[..., 2] = c * x + s * z, -s * x + c * z
    return pose


def performance(movements, *, still: int = 20, frames: int = 60) -> np.ndarray:
    """Movements one after another with ``still`` frames of rest before each and after the last."""
    pieces = []
    for m in movements:
        pieces += [human("rest", still, turn=0.0), human(m, frames, turn=0.0)]
    return np.concatenate(pieces + [human("rest", still, turn=0.0)])


BANDAI = [  # joint, parent, our point (None: an end site at its parent, as in the Bandai-Namco files)
    ("joint_Root", None, "ground"), ("Hips", "joint_Root", "hips"), ("Spine", "Hips", "spine"),
    ("Chest", "Spine", "chest"), ("Neck", "Chest", "neck"), ("Head", "Neck", "head"), ("Head_end", "Head", None),
]
for _s, _side in (("L", "l"), ("R", "r")):
    BANDAI += [(f"Shoulder_{_s}", "Chest", f"{_side}_clavicle"),
               (f"UpperArm_{_s}", f"Shoulder_{_s}", f"{_side}_shoulder"),
               (f"LowerArm_{_s}", f"UpperArm_{_s}", f"{_side}_elbow"),
               (f"Hand_{_s}", f"LowerArm_{_s}", f"{_side}_wrist"),
               (f"Hand_{_s}_end", f"Hand_{_s}", None)]
for _s, _side in (("L", "l"), ("R", "r")):
    BANDAI += [(f"UpperLeg_{_s}", "Hips", f"{_side}_hip"), (f"LowerLeg_{_s}", f"UpperLeg_{_s}", f"{_side}_knee"),
               (f"Foot_{_s}", f"LowerLeg_{_s}", f"{_side}_ankle"), (f"Toes_{_s}", f"Foot_{_s}", f"{_side}_toes"),
               (f"Toes_{_s}_end", f"Toes_{_s}", None)]

KINECT = [("SpineBase", None, "hips"), ("SpineMid", "SpineBase", "spine"), ("SpineShoulder", "SpineMid", "chest"),
          ("Neck", "SpineShoulder", "neck"), ("Head", "Neck", "head")]
for _s, _side in (("Left", "l"), ("Right", "r")):
    KINECT += [(f"Shoulder{_s}", "SpineShoulder", f"{_side}_shoulder"),
               (f"Elbow{_s}", f"Shoulder{_s}", f"{_side}_elbow"),
               (f"Wrist{_s}", f"Elbow{_s}", f"{_side}_wrist"), (f"Hip{_s}", "SpineBase", f"{_side}_hip"),
               (f"Knee{_s}", f"Hip{_s}", f"{_side}_knee"), (f"Ankle{_s}", f"Knee{_s}", f"{_side}_ankle"),
               (f"Foot{_s}", f"Ankle{_s}", f"{_side}_toes")]


def _skeleton_positions(skeleton, pose: np.ndarray) -> tuple[list[str], list[int], np.ndarray]:
    names = [j for j, _, _ in skeleton]
    parents = [-1 if p is None else names.index(p) for _, p, _ in skeleton]
    cols = []
    for joint, parent, point in skeleton:
        if point == "ground":
            hips = pose[:, NAMES.index("hips")]
            cols.append(hips * np.array([1.0, 0.0, 1.0]))
        elif point is None:
            cols.append(cols[names.index(parent)])
        else:
            cols.append(pose[:, NAMES.index(point)])
    return names, parents, np.stack(cols, axis=1)


def source_axes(points: np.ndarray, up: str) -> np.ndarray:
    """likeme's (x, y, z) with +y up written in a source whose up axis is ``up`` (``+y``, ``+z`` or ``-y``)."""
    x, y, z = points[..., 0], points[..., 1], points[..., 2]
    return {"+y": np.stack([x, y, z], -1), "+z": np.stack([x, -z, y], -1), "-y": np.stack([x, -y, -z], -1)}[up]


def write_skeleton_bvh(path: Path, skeleton, pose: np.ndarray, *, scale: float = 1.0, up: str = "+y",
                       fps: float = 30.0) -> Path:
    """A BVH with the joints of ``skeleton`` (``BANDAI`` or ``KINECT``) moving as ``pose`` (metres, +y up) in the
    given units (``scale`` units per metre) and up axis; end sites (no point) at their parent, as BVH End Sites."""
    names, parents, positions = _skeleton_positions(skeleton, pose)
    positions = source_axes(positions * scale, up)
    real = [i for i, (_, _, point) in enumerate(skeleton) if point is not None]
    index = {i: k for k, i in enumerate(real)}
    bvh = from_joint_positions([names[i] for i in real], [index[parents[i]] if parents[i] >= 0 else -1 for i in real],
                               positions[:, real], fps)
    joints = list(bvh.joints)
    order, out_joints, columns = [], [], []
    # end sites go right after their parent joint's subtree is opened: append them as leaves of their parent
    for i, (joint, parent, point) in enumerate(skeleton):
        if point is None:
            continue
        order.append(i)
    new_index = {}
    for i in order:
        j = joints[index[i]]
        new_index[i] = len(out_joints)
        out_joints.append(Joint(j.name, -1 if j.parent < 0 else new_index[real[j.parent]], j.offset, j.channels))
        columns.append(bvh.values[:, 3 * index[i]:3 * index[i] + 3])
        for k, (_, parent, point) in enumerate(skeleton):
            if point is None and parent == names[i]:
                out_joints.append(Joint(f"{names[i]}_end", new_index[i], (0.0, 0.0, 0.0), (), end_site=True))
    write_bvh(BVH(out_joints, 1.0 / fps, np.concatenate(columns, axis=1)), path)
    return path


def write_skeleton_csv(path: Path, skeleton, pose: np.ndarray, *, scale: float = 1.0, up: str = "+y",
                       fps: float = 30.0) -> Path:
    """A CSV of joint positions (``JOINT_x,JOINT_y,JOINT_z`` columns and a ``time`` column in seconds)."""
    names, _, positions = _skeleton_positions(skeleton, pose)
    positions = source_axes(positions * scale, up)
    header = ["time"] + [f"{n}_{a}" for n in names for a in "xyz"]
    rows = [",".join([f"{f / fps:.6f}"] + [f"{v:.6f}" for v in positions[f].ravel()]) for f in range(len(positions))]
    path.write_text(",".join(header) + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return path
