"""Body profiles that check themselves: warnings where a profile is probably wrong, and a profile proposed for a file.

Two uses of the same body knowledge (which joints are a head, hips or feet; how tall a body of some kind is; how
the facing is found, :mod:`plugins.lib.root_frame`):

- :func:`profile_warnings` and :class:`RecordingCheck` (``likeme validate --body``): the profile's units give a body
  far smaller or larger than a body of its kind, its up axis puts the root below the feet or the head under the hips,
  its facing flips more than once in 1000 frames, or two parts map one joint;
- :func:`propose_profile` (``likeme profile FILE``): a profile for a recording, with its units and up axis from the
  data, its parts from the common joint-naming schemes (:data:`SCHEMES`), facing markers, bones from the BVH
  hierarchy or the scheme, and ``# TODO`` comments where it could not decide.

It lives on the top floor, beside the commands that use it, not in the core: it is an algorithm (heuristics about
bodies, and the facing estimate of §5.1, Buchsbaum & Blumberg 2005, :mod:`plugins.lib.root_frame`).

The kind of a body is read from its own proportions, not from one dataset: a body whose vertical extent is at least
half its span (twice the largest distance of a part from the parts' centroid) stands upright, like a person, a
child, a giant or Max the mouse, and is :data:`UPRIGHT_HEIGHT` tall; any other body (four-legged, lying, a hand)
spans :data:`OTHER_SPAN`. A wrong unit is a factor of 10 to 1000 (or 25.4, 30.48): far outside either range.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from likeme.schemes import SCHEMES, Candidate, Scheme
from toolkit.body import Body, Facing
from toolkit.recordings.profile import Joint, gather_joints, joint_columns, joint_names

__all__ = ["UPRIGHT_HEIGHT", "OTHER_SPAN", "FLIP_RATE", "SCHEMES", "profile_warnings", "RecordingCheck",
           "recording_warnings", "facing_warnings", "facing_flips", "body_groups", "Proposal", "propose_profile"]

UPRIGHT_HEIGHT = (0.3, 3.0)
"""Heights (m) of a body standing upright: a toddler (or an upper body alone) to a giant."""
OTHER_SPAN = (0.03, 6.0)
"""Spans (m) of any other body: a mouse to a horse."""
UPRIGHT_RATIO = 0.5
"""A body stands upright when its vertical extent is at least this fraction of its span (the median frame)."""
FLIP_RATE = 1e-3
"""The facing may flip (turn by more than :data:`FLIP_ANGLE` from one frame to the next) in at most this fraction of
the frames (``tests/toolkit/recordings/test_profile.py`` holds the Bandai-Namco profile to it)."""
FLIP_ANGLE = 2.0
"""A turn (radians) between two consecutive frames that no body makes: a flip of the estimate."""
UP_COSINE = 0.7
"""The head-above-feet direction must be within about 45 degrees of the profile's up (cosine)."""
_MAX_LISTED = 10
_UNIT_NAMES = {"metre": 1.0, "centimetre": 0.01, "millimetre": 0.001}
"""The units a proposal chooses between (inches and feet are 2.5 and 3 times a centimetre and a decimetre: a
proposal cannot tell them from the data, the comment beside ``units`` gives the height to check)."""
_UP = np.array([0.0, 1.0, 0.0])

# -- which parts are a head, hips, feet: by the part's name or its joint's, in any naming scheme -----------------

_HEAD_WORDS = ("head", "nose", "neck", "skull")
_HIP_WORDS = ("hip", "pelvis", "spinebase", "upleg", "upperleg", "thigh", "femur")
_FOOT_WORDS = ("foot", "feet", "toe", "ankle", "heel")


def _norm(name: str) -> str:
    """A joint name compared across schemes: lower case, without a ``prefix:`` (``mixamorig:``) or separators."""
    return re.sub(r"[^a-z0-9]", "", name.rsplit(":", 1)[-1].lower())


def _named(names: Sequence[str], words: Iterable[str]) -> list[int]:
    words = tuple(words)
    return [i for i, n in enumerate(names) if any(w in _norm(n) for w in words)]


def body_groups(parts: Sequence[str], joints: Sequence[Joint]) -> dict[str, list[int]]:
    """The indices of the parts that are a head (or neck, nose), hips and feet (toes, ankles, heels), by the part's
    name or its source joint's (``head``, ``Head``, ``mixamorig:LeftUpLeg``, ``AnkleLeft``...; a mean's joints)."""
    both = [" ".join(_norm(n) for n in (p, *joint_names([j]))) for p, j in zip(parts, joints)]
    return {"head": _named(both, _HEAD_WORDS), "hips": _named(both, _HIP_WORDS), "feet": _named(both, _FOOT_WORDS)}


# -- checks -------------------------------------------------------------------------------------------------------


def profile_warnings(profile) -> list[str]:
    """What is probably wrong in a profile alone: two parts that map one joint (they would be one point)."""
    seen: dict[str, str] = {}
    out = []
    for part, joint in zip(profile.body.parts, profile.joints):
        if joint in seen:
            out.append(f"parts {seen[joint]!r} and {part!r} both map joint {joint!r}: they are one point")
        else:
            seen[joint] = part
    return out


def _mean_of(positions: np.ndarray, visible: np.ndarray, idx: list[int]) -> np.ndarray:
    """The mean position (F, 3) of the visible parts ``idx``; NaN where none is visible."""
    if not idx:
        return np.full((len(positions), 3), np.nan)
    seen = visible[:, idx]
    total = np.where(seen[..., None], positions[:, idx], 0.0).sum(axis=1)
    count = seen.sum(axis=1)
    return np.where(count[:, None] > 0, total / np.maximum(count, 1)[:, None], np.nan)


def _extents(positions: np.ndarray, visible: np.ndarray, up: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per frame: the extent along ``up`` and the span (twice the largest distance of a part from the centroid)."""
    ok = visible & np.isfinite(positions).all(axis=-1)
    count = ok.sum(axis=1)
    safe = np.where(ok[..., None], positions, 0.0)
    centre = safe.sum(axis=1) / np.maximum(count, 1)[:, None]
    far = np.where(ok, np.linalg.norm(safe - centre[:, None], axis=-1), 0.0).max(axis=1, initial=0.0)
    height = safe @ up
    vertical = np.where(ok, height, -np.inf).max(axis=1, initial=-np.inf) - \
        np.where(ok, height, np.inf).min(axis=1, initial=np.inf)
    good = count >= 2
    return np.where(good, vertical, np.nan), np.where(good, 2.0 * far, np.nan)


def _frames_text(frames: Sequence[int]) -> str:
    shown = ", ".join(str(f) for f in frames[:_MAX_LISTED])
    return shown + (f" and {len(frames) - _MAX_LISTED} more" if len(frames) > _MAX_LISTED else "")


def facing_flips(heading: np.ndarray) -> np.ndarray:
    """The frames (indices) where the facing estimate turns by more than :data:`FLIP_ANGLE` since the frame before."""
    turn = np.abs(np.angle(np.exp(1j * np.diff(np.asarray(heading, dtype=float)))))
    return np.flatnonzero(np.nan_to_num(turn, nan=0.0) > FLIP_ANGLE) + 1


def _size_kind(vertical: np.ndarray, span: np.ndarray) -> tuple[bool, float, float]:
    """(upright, the median vertical extent, the median span) of a body's frames, in the data's own units."""
    v, s = np.nanmedian(vertical), np.nanmedian(span)
    return bool(v >= UPRIGHT_RATIO * s), float(v), float(s)


def _unit_name(scale: float) -> str:
    for name, value in _UNIT_NAMES.items():
        if np.isclose(scale, value):
            return name
    return f"{scale:g} m per unit"


def _best_unit(size: float, upright: bool) -> tuple[str, float]:
    """The unit (of :data:`_UNIT_NAMES`) that makes ``size`` nearest the middle of its kind's range, in log."""
    low, high = UPRIGHT_HEIGHT if upright else OTHER_SPAN
    middle = np.sqrt(low * high)
    name = min(_UNIT_NAMES, key=lambda n: abs(np.log(size * _UNIT_NAMES[n] / middle)))
    return name, _UNIT_NAMES[name]


@dataclass
class RecordingCheck:
    """The checks of one recording read through a profile, fed a block of frames at a time (metres, +y up).

    ``update(positions, visible)`` with blocks (k, P, 3), (k, P) as :meth:`BodyProfile.stream` gives them; then
    ``warnings()``. Keeps a few numbers per frame, never the positions.
    """

    profile: object
    _vertical: list[np.ndarray] = field(default_factory=list)
    _span: list[np.ndarray] = field(default_factory=list)
    _heading: list[np.ndarray] = field(default_factory=list)
    _direction: list[np.ndarray] = field(default_factory=list)
    _root_below: list[np.ndarray] = field(default_factory=list)
    _head_under: list[np.ndarray] = field(default_factory=list)

    def __post_init__(self) -> None:
        profile = self.profile
        self.body: Body = profile.body
        self.groups = body_groups(profile.body.parts, profile.joints)
        self.position_parts = ~profile.body.angle_mask

    def update(self, positions: np.ndarray, visible: np.ndarray) -> None:
        from plugins.lib.root_frame import facing_heading

        positions = np.asarray(positions, dtype=float)
        visible = np.asarray(visible, dtype=bool) & np.isfinite(positions).all(axis=-1) & self.position_parts
        vertical, span = _extents(positions, visible, _UP)
        self._vertical.append(vertical)
        self._span.append(span)
        self._heading.append(facing_heading(np.where(visible[..., None], positions, 0.0), visible, self.body))
        head, hips, feet = (_mean_of(positions, visible, self.groups[k]) for k in ("head", "hips", "feet"))
        root = _mean_of(positions, visible, [self.body.root_index])
        g = self.groups
        upper = head if g["head"] else root
        lower = feet if g["feet"] else hips if g["hips"] else root if g["head"] else np.full_like(root, np.nan)
        direction = upper - lower
        norm = np.linalg.norm(direction, axis=-1, keepdims=True)
        self._direction.append(np.where(norm > 0, direction / np.where(norm > 0, norm, 1.0), np.nan))
        self._root_below.append(np.where(np.isfinite(root[:, 1] + feet[:, 1]), root[:, 1] < feet[:, 1], np.nan))
        self._head_under.append(np.where(np.isfinite(head[:, 1] + hips[:, 1]), head[:, 1] < hips[:, 1], np.nan))

    def warnings(self, facing: bool = True) -> list[str]:
        """What is probably wrong with the profile for this recording, one sentence each (none: it looks right).

        ``facing=False`` leaves the facing out: over several recordings, :func:`facing_warnings` counts its flips
        over them all (:meth:`flips`), as one short clip with two flips says little about a profile.
        """
        if not self._vertical:
            return []
        vertical, span = np.concatenate(self._vertical), np.concatenate(self._span)
        out = []
        if np.isfinite(span).any():
            scale, unit = self.profile.scale, _unit_name(self.profile.scale)
            upright, height, size = _size_kind(vertical, span)
            measure, value, (low, high) = ("tall", height, UPRIGHT_HEIGHT) if upright else ("across", size, OTHER_SPAN)
            if not low <= value <= high:
                kind = "a body standing upright" if upright else "a body that does not stand upright"
                best, best_scale = _best_unit(value / scale, upright)
                hint = (f" (units = \"{best}\" would make it {value / scale * best_scale:.3g} m)"
                        if best_scale != scale else "")
                out.append(f"the body is {value:.3g} m {measure} with units {unit}, and {kind} is {low:g} to {high:g} "
                           f"m {measure}: the units are probably wrong{hint}")
            out += self._up_warnings()
        if facing:
            out += [text for _, text in facing_warnings([("", *self.flips())])]
        return out

    def flips(self) -> tuple[np.ndarray, int]:
        """The frames where the facing flips (:func:`facing_flips`), and the number of frames."""
        heading = np.concatenate(self._heading) if self._heading else np.zeros(0)
        return facing_flips(heading), len(heading)

    def _up_warnings(self) -> list[str]:
        from toolkit.recordings.profile import UP_AXES

        why = []
        for name, values, text in (("root", self._root_below, "the root is below the feet"),
                                   ("head", self._head_under, "the head is under the hips")):
            v = np.concatenate(values)
            if np.isfinite(v).any() and np.nanmean(v) > 0.5:
                why.append(f"{text} in {np.nanmean(v):.0%} of the frames")
        d = np.concatenate(self._direction)
        if not (self.groups["head"] or self.groups["feet"] or self.groups["hips"]) or not np.isfinite(d).any():
            return []
        mean = np.nanmean(d, axis=0)
        norm = float(np.linalg.norm(mean))
        if norm == 0.0:
            return []
        cosine = mean[1] / norm
        if cosine < UP_COSINE and not why:
            why.append(f"the head-above-feet direction is {np.degrees(np.arccos(np.clip(cosine, -1, 1))):.0f} "
                       "degrees from up")
        if not why:
            return []
        source = UP_AXES[self.profile.up].T @ mean  # back to the file's axes
        axis = int(np.argmax(np.abs(source)))
        guess = f"{'+' if source[axis] > 0 else '-'}{'xyz'[axis]}"
        return [f"up = \"{self.profile.up}\" is probably wrong: {' and '.join(why)}; the file's up axis looks like "
                f"\"{guess}\""]


def facing_warnings(records: Sequence[tuple[object, np.ndarray, int]]) -> list[tuple[object, str]]:
    """``(source, warning)`` for each recording whose facing flips, when the facing flips in more than
    :data:`FLIP_RATE` of the frames of all ``records`` (``(source, flip frames, number of frames)`` each)."""
    flips = sum(len(f) for _, f, _ in records)
    frames = sum(n for _, _, n in records)
    if flips <= FLIP_RATE * frames:
        return []
    over = f" ({flips} of {frames} frames over all the recordings)" if len(records) > 1 else ""
    return [(source, f"the facing flips (turns by more than {np.degrees(FLIP_ANGLE):.0f} degrees in a frame) in "
                     f"{len(f)} of {n} frames, more than 1 in {1 / FLIP_RATE:.0f}{over}: frames "
                     f"{_frames_text(f.tolist())}; check [facing] (left is the body's own left; forward a part always "
                     "in front of the body, seen from behind)") for source, f, n in records if len(f)]


def recording_warnings(profile, blocks: Iterable[tuple[np.ndarray, np.ndarray]]) -> list[str]:
    """:class:`RecordingCheck` of the ``(positions, visible)`` blocks of one recording read through ``profile``."""
    check = RecordingCheck(profile)
    for positions, visible in blocks:
        check.update(positions, visible)
    return check.warnings()


# -- proposals ----------------------------------------------------------------------------------------------------

_PARENTS: dict[str, tuple[str, ...]] = {
    # a part's bone in a scheme without a hierarchy (joint positions): the first of these parts that is present
    "chest": ("root",), "neck": ("chest", "root"), "head": ("neck", "chest", "root"), "head_top": ("head",),
    "nose": ("head", "neck", "chest", "root"), "left_eye": ("nose", "head"), "left_ear": ("left_eye", "head"),
    "left_shoulder": ("chest", "neck", "root"), "left_elbow": ("left_shoulder",), "left_wrist": ("left_elbow",),
    "left_hand": ("left_wrist",), "left_hand_tip": ("left_hand", "left_wrist"), "left_hip": ("root",),
    "left_knee": ("left_hip", "root"), "left_foot": ("left_knee",), "left_toes": ("left_foot",),
    "left_toe_tip": ("left_toes",), "left_heel": ("left_foot",),
}


def _mirror(text: str) -> str:
    """The right side's name of a left side's (part or joint name in any of :data:`SCHEMES`)."""
    for a, b in (("Left", "Right"), ("left", "right"), ("LEFT", "RIGHT"), ("_L", "_R"), (".L", ".R")):
        if a in text:
            return text.replace(a, b)
    text = re.sub(r"_l$", "_r", text)  # knee_l
    return re.sub(r"(^|:)(L(?=[A-Z_])|l_)", lambda m: m.group(1) + ("R" if m.group(2) == "L" else "r_"), text)


def _mirror_part(part: str) -> str:
    """A right part's left counterpart (``right_knee`` -> ``left_knee``); other parts unchanged."""
    return "left_" + part[6:] if part.startswith("right_") else part


def _with_right(table: Mapping[str, tuple[Candidate, ...]]) -> dict[str, tuple[Candidate, ...]]:
    out: dict[str, tuple[Candidate, ...]] = {}
    for part, joints in table.items():
        out[part] = joints
        if part.startswith("left_"):
            out[_mirror(part)] = tuple(_mirror(j) if isinstance(j, str) else tuple(map(_mirror, j)) for j in joints)
    return out


PARTS_ORDER = ("root", "chest", "neck", "head", "head_top", "nose", "left_eye", "right_eye", "left_ear", "right_ear",
               "left_shoulder", "left_elbow", "left_wrist", "left_hand", "left_hand_tip", "right_shoulder",
               "right_elbow", "right_wrist", "right_hand", "right_hand_tip", "left_hip", "left_knee", "left_foot",
               "left_heel", "left_toes", "left_toe_tip", "right_hip", "right_knee", "right_foot", "right_heel",
               "right_toes", "right_toe_tip")
"""The order of the parts in a proposed profile."""


def _match(names: Sequence[str]) -> tuple[Scheme | None, dict[str, Joint]]:
    """The scheme (of :data:`SCHEMES`) that names most of ``names``, and its part -> joint mapping (joints as the
    file spells them; a tuple for a part that is the mean of joints). Ties go to the scheme that spells more names
    exactly as the file does (CMU's ``Hips`` is not ``mixamorig:Hips``)."""
    by_norm: dict[str, str] = {}
    for n in names:
        by_norm.setdefault(_norm(n), n)
    best: tuple[tuple[int, int], Scheme | None, dict[str, Joint]] = ((0, 0), None, {})
    for scheme in SCHEMES.values():
        mapping: dict[str, Joint] = {}
        exact = 0
        for part, candidates in _with_right(scheme.parts).items():
            for c in candidates:
                if isinstance(c, str):
                    if _norm(c) in by_norm and by_norm[_norm(c)] not in mapping.values():
                        mapping[part] = by_norm[_norm(c)]
                        exact += mapping[part] == c
                        break
                elif all(_norm(j) in by_norm for j in c):
                    mapping[part] = tuple(by_norm[_norm(j)] for j in c)
                    exact += mapping[part] == c
                    break
        if (len(mapping), exact) > best[0]:
            best = ((len(mapping), exact), scheme, mapping)
    return best[1], best[2]


def _key(part: str) -> str:
    return part if re.fullmatch(r"[A-Za-z0-9_-]+", part) else json.dumps(part)


def _generic(names: Sequence[str]) -> dict[str, str]:
    """Parts for joints of no known scheme: every joint, named after itself (lower case, separators as ``_``)."""
    out: dict[str, str] = {}
    for n in names:
        part = re.sub(r"[^a-z0-9]+", "_", n.rsplit(":", 1)[-1].lower()).strip("_") or "joint"
        while part in out:
            part += "_"
        out[part] = n
    return out


def _side_pair(parts: Sequence[str], joints: Sequence[str]) -> tuple[str, str] | None:
    """A left/right pair of parts whose joint names differ only by the side (the one nearest the start)."""
    index = {j: p for p, j in zip(parts, joints)}
    for p, j in zip(parts, joints):
        if not isinstance(j, str):  # a mean of joints: on the body's midline
            continue
        right = _mirror(j)
        if right != j and right in index:
            return p, index[right]
    return None


@dataclass
class Proposal:
    """A proposed profile: its TOML text, and what it could not decide (the ``# TODO`` comments)."""

    text: str
    scheme: str | None
    todo: list[str]
    warnings: list[str] = field(default_factory=list)
    """What is probably wrong even after the proposal (a body of implausible height for its scheme's units)."""


def propose_profile(names: Sequence[str], positions: np.ndarray, *, parents: Sequence[int] | None = None,
                    name: str = "proposed", source: str = "", fps: float | None = None) -> Proposal:
    """A body profile for a recording: its joints ``names``, their positions (F, J, 3) in the file's units and axes,
    and the BVH hierarchy (``parents``, -1 for a root) if it has one.

    Parameters
    ----------
    names : sequence of str
    positions : array, shape (F, J, 3)
    parents : sequence of int, optional
        Each joint's parent index; without it (joint positions), bones come from the naming scheme.
    name, source : str
        The profile's name, and the file it is proposed for (for its comments).
    fps : float, optional
        The frame rate found in the file (None: the file did not tell, a ``# TODO``).

    Returns
    -------
    Proposal
        TOML that :func:`toolkit.recordings.profile.load_profile` reads.
    """
    names = list(names)
    positions = np.asarray(positions, dtype=float)
    todo: list[str] = []
    warnings: list[str] = []
    found, mapping = _match(names)
    if len(mapping) < 5:  # too few to be that scheme: every joint a part of its own name
        found, mapping = None, _generic(names)
        todo.append(f"no known joint-naming scheme ({', '.join(SCHEMES)}): every joint is a part named after it; "
                    "rename the parts you use (head, left_hip...) and drop the others")
    scheme = found.name if found is not None else None
    ordered = {p: mapping[p] for p in PARTS_ORDER if p in mapping}
    ordered.update({p: j for p, j in mapping.items() if p not in ordered})
    mapping = ordered
    root_note = ""
    if "root" not in mapping:
        if scheme is None:
            first = names[[i for i, p in enumerate(parents or [-1] * len(names)) if p < 0][0]]
            part = next(p for p, j in mapping.items() if j == first)
        else:
            part = next((p for p in ("left_hip", "chest", "neck", "head", "nose") if p in mapping), next(iter(mapping)))
        mapping = {"root": mapping.pop(part), **mapping}
        root_note = f"TODO: no pelvis joint in this scheme: the root is {mapping['root']!r}, the part {part!r}"
        if scheme is None:
            root_note = f"TODO: the root is the hierarchy's root joint {mapping['root']!r}: choose the body's centre"
        todo.append(root_note[6:])
    parts, joints = list(mapping), list(mapping.values())
    data = gather_joints(positions, joint_columns(names, joints))
    groups = body_groups(parts, joints)

    # up: the direction from the feet (else the hips, the root) to the head, in the file's axes
    seen = np.isfinite(data).all(axis=-1)
    upper = groups["head"]
    lower = groups["feet"] or groups["hips"] or [parts.index("root")]
    up_note = ""
    if upper and set(upper) != set(lower):
        d = _mean_of(data, seen, upper) - _mean_of(data, seen, lower)
        n = np.linalg.norm(d, axis=-1, keepdims=True)
        mean = np.nanmean(np.where(n > 0, d / np.where(n > 0, n, 1.0), np.nan), axis=0) if np.isfinite(d).any() \
            else np.full(3, np.nan)
    else:
        mean = np.full(3, np.nan)
    if np.isfinite(mean).all() and np.linalg.norm(mean) > 0:
        axis = int(np.argmax(np.abs(mean)))
        up = f"{'+' if mean[axis] > 0 else '-'}{'xyz'[axis]}"
        cos = abs(mean[axis]) / np.linalg.norm(mean)
        up_note = f"the head is above the feet along the file's {up} axis"
        if cos < UP_COSINE:
            todo.append(f"the up axis is unsure ({up} is {np.degrees(np.arccos(cos)):.0f} degrees off)")
            up_note = f"TODO: {todo[-1]}"
    else:
        extent = np.nanmax(data, axis=(0, 1)) - np.nanmin(data, axis=(0, 1)) if seen.any() else np.ones(3)
        up = f"+{'xyz'[int(np.argmax(extent))]}"
        todo.append("no head and feet to tell the up axis by: the axis of the largest extent, sign unknown")
        up_note = f"TODO: {todo[-1]}"
    from toolkit.recordings.profile import UP_AXES

    rotate = UP_AXES[up]
    world = data @ rotate.T  # the file's units, +y up

    # units: a person's height from the head to the feet where the scheme is a person's, else the body's size in
    # the file's units made plausible for its kind
    vertical, span = _extents(world, seen, _UP)
    person = _person_units(world, seen, groups, found) if found is not None and found.person else None
    if person is not None:
        units, scale, units_note, unsure = person
        if unsure:
            todo.append(unsure)
            warnings.append(f"{unsure}: check units (the comment beside it gives the height in the file's units)")
            units_note = f"TODO: {unsure} ({units_note})"
    elif np.isfinite(span).any():
        upright, height, size = _size_kind(vertical, span)
        raw = height if upright else size
        units, scale = _best_unit(raw, upright)
        low, high = UPRIGHT_HEIGHT if upright else OTHER_SPAN
        units_note = (f"the body is {raw:.4g} units {'tall' if upright else 'across'}: {raw * scale:.3g} m in "
                      f"{units}s")
        person = [f"{n} would make it {raw * v:.3g} m" for v, n in _PERSON_UNITS  # an upright body of no known
                  if upright and v != scale and PERSON_HEIGHT[0] <= raw * v <= PERSON_HEIGHT[1]]  # scheme: a person?
        if person and not PERSON_HEIGHT[0] <= raw * scale <= PERSON_HEIGHT[1]:
            units_note += f" (if it is a person: {'; '.join(person)})"
        if not low <= raw * scale <= high:
            todo.append(f"no unit makes the body {low:g} to {high:g} m {'tall' if upright else 'across'}")
            units_note = f"TODO: {todo[-1]} ({units_note})"
    else:
        units, scale, units_note = "metre", 1.0, "TODO: no frame with two joints seen: the units are a guess"
        todo.append("no frame with two joints seen to tell the units by")
    world = world * scale

    # the floor: where the feet stand, when it is not at the origin (a camera's frame)
    floor, floor_note = _floor(world, seen, groups)
    if floor is None and not floor_note and found is not None and found.camera:
        todo.append(f"{found.name} records in a camera's frame and no feet were seen to find the floor by: give "
                    "floor = HEIGHT (metres) where the floor is, for pictures")
        floor_note = f"TODO: {todo[-1]}"

    # facing: a left/right pair across the body, and a forward marker that is in front of it in every frame
    facing_note = ""
    pairs = [(a, b) for a, b in (("left_hip", "right_hip"), ("left_shoulder", "right_shoulder"),
                                 ("left_knee", "right_knee")) if a in mapping and b in mapping]
    pairs += [p for p in [_side_pair(parts, joints)] if p is not None and p not in pairs]
    both = [float((seen[:, parts.index(a)] & seen[:, parts.index(b)]).mean()) if len(seen) else 0.0 for a, b in pairs]
    pair = next((p for p, f in zip(pairs, both) if f >= 0.5), None)  # seen together in most frames
    if pair is None and pairs:
        pair = pairs[int(np.argmax(both))]
        todo.append(f"the facing pair {pair[0]!r}, {pair[1]!r} is seen together in only {max(both):.0%} of the "
                    "frames")
        facing_note = f"TODO: {todo[-1]}"
    if pair is None:
        pair = (parts[0], parts[min(1, len(parts) - 1)])
        todo.append("no left/right pair of joints found for the facing")
        facing_note = f"TODO: {todo[-1]}"
    # the left/right line alone gives the facing (the names say which is left); the nose, where there is one, also
    # gives it when a hip is hidden. The toes are no marker: running, the heel kicks up behind and the foot points
    # backwards (on the Bandai-Namco dash clips the toes seen from the ankle flip the facing in 1 frame of 10)
    candidates = [("nose", None)] if "nose" in mapping else []
    facing = _choose_facing(parts, pair, candidates, world, seen)
    chosen, flips = facing
    # the shoulders beside the hips, where both are seen in most frames: the line across the body from the two, each
    # counting by its length, turns less with a tracker's jitter than the hips alone (docs/formats.md)
    trunk = [TRUNK_PAIR] if pair == ("left_hip", "right_hip") and TRUNK_PAIR in pairs \
        and both[pairs.index(TRUNK_PAIR)] >= 0.5 else []
    body_facing = Facing(pair[0], pair[1], *chosen, also=tuple(trunk))
    if flips > FLIP_RATE * max(len(world) - 1, 1):
        todo.append(f"the facing flips in {flips} of {len(world)} frames with every marker tried")
        facing_note = f"TODO: {todo[-1]}"

    # bones: from the hierarchy, else from the scheme
    bones = []
    if parents is not None:
        part_of = {names.index(j): p for p, j in zip(parts, joints)}
        for p, j in zip(parts, joints):
            k = parents[names.index(j)]
            while k >= 0 and k not in part_of:
                k = parents[k]
            if k >= 0:
                bones.append((part_of[k], p))
    else:
        for p in parts:
            right = p.startswith("right_")
            sided = [q.replace("left_", "right_") if right else q for q in _PARENTS.get(_mirror_part(p), ())]
            parent = next((q for q in sided if q in mapping), None)
            if parent is not None:
                bones.append((parent, p))
    used = set(joint_names(joints))
    text = _format(name, source, scheme, units, units_note, up, up_note, mapping, body_facing, facing_note, bones,
                   [n for n in names if n not in used], root_note, fps, len(positions), floor, floor_note)
    return Proposal(text, scheme, todo, warnings)


PERSON_STATURE = (0.9, 2.2)
"""The distance (m) from a person's head (the mean of the head, neck, nose) to the feet (ankles, toes, heels) when
standing: a child to a tall adult. A ratio under 2.22 (CMU's unit to an inch), so that at most one unit of
:func:`_person_units` fits, save for those known for the scheme, which are tried first."""
PERSON_HEIGHT = (1.0, 2.3)
"""The height (m) of a standing person, an older child to a tall adult: named beside the units of an upright body of
no known scheme when another unit would make it one (a proposal cannot tell an inch file of a person from a small
body in centimetres)."""
_PERSON_UNITS = ((1.0, "metre"), (0.01, "centimetre"), (0.001, "millimetre"), (0.0254, "inch"))
TRUNK_PAIR = ("left_shoulder", "right_shoulder")
"""The pair a proposal adds beside the hips for the line across the body (:class:`toolkit.body.Facing` ``also``)."""
FLOOR_OFFSET = 0.1
"""A floor further than this (m) from ``y = 0`` is proposed as the profile's ``floor``."""


def _person_units(world: np.ndarray, seen: np.ndarray, groups: Mapping[str, list[int]], scheme: Scheme
                  ) -> tuple[str, float, str, str] | None:
    """``(units as the profile writes them, metres per unit, comment, unsure)`` for a person's skeleton, from the
    distance between the head and the feet in the frames where it is longest (its 90th percentile: standing), in
    the file's units (``world``: +y up). The first unit (the scheme's own, then metre, centimetre, millimetre, inch)
    that makes it a person's (:data:`PERSON_STATURE`); ``unsure`` says why when none does. None without a head and
    feet."""
    if not groups["head"] or not groups["feet"]:
        return None
    head, feet = _mean_of(world, seen, groups["head"]), _mean_of(world, seen, groups["feet"])
    length = np.linalg.norm(head - feet, axis=-1)
    if not np.isfinite(length).any():
        return None
    raw = float(np.nanpercentile(length, 90))
    if raw <= 0:
        return None
    candidates: list[tuple[float, str]] = list(scheme.units)
    candidates += [(v, n) for v, n in _PERSON_UNITS if not any(np.isclose(v, c) for c, _ in scheme.units)]
    low, high = PERSON_STATURE
    fits = [(v, n) for v, n in candidates if low <= raw * v <= high]
    if fits:
        value, label = fits[0]
        unsure = ""
    else:
        value, label = min(candidates, key=lambda c: max(np.log(low / (raw * c[0])), np.log(raw * c[0] / high)))
        unsure = (f"the head is {raw * value:.3g} m from the feet with units {label.split(',')[0]}, and a person's is "
                  f"{low:g} to {high:g} m: no unit known for {scheme.name} fits")
    text = next((n for v, n in _PERSON_UNITS if np.isclose(v, value)), repr(value))
    note = f"the head is {raw:.4g} units from the feet: {raw * value:.3g} m in {label}"
    others = [f"{n.split(',')[0]} would make it {raw * v:.3g} m" for v, n in fits[1:]]
    if others:
        note += f" (also a person's: {'; '.join(others)})"
    return text, value, note, unsure


def _floor(world: np.ndarray, seen: np.ndarray, groups: Mapping[str, list[int]]) -> tuple[float | None, str]:
    """The floor's height (m, +y up) where the feet stand (the 5th percentile over frames of the lowest foot joint
    seen), and its comment; None when the floor is within :data:`FLOOR_OFFSET` of 0 (a comment says so) or there
    are no feet seen (no comment)."""
    if not groups["feet"]:
        return None, ""
    y = np.where(seen[:, groups["feet"]], world[:, groups["feet"], 1], np.nan)
    lowest = np.nanmin(np.where(np.isfinite(y).any(axis=1, keepdims=True), y, np.inf), axis=1)
    lowest = lowest[np.isfinite(lowest)]
    if not len(lowest):
        return None, ""
    floor = round(float(np.percentile(lowest, 5)), 2)
    if abs(floor) <= FLOOR_OFFSET:
        return None, f"the feet stand on y = 0 (within {FLOOR_OFFSET:g} m): no floor offset"
    return floor, (f"the feet stand at y = {floor:g} m, not on y = 0 (a camera's frame?): this puts them on the "
                   "floor")


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _choose_facing(parts: list[str], pair: tuple[str, str], candidates: list[tuple[str, str | None]],
                   world: np.ndarray, seen: np.ndarray) -> tuple[tuple[str | None, str | None], int]:
    """The first forward marker (with the part it is seen from) that is apart from it and keeps the facing steady;
    else the steadiest (none at all when no marker is apart)."""
    from plugins.lib.root_frame import facing_heading

    size = np.nanmedian(_extents(world, seen, _UP)[1]) if seen.any() else 0.0
    tried = []
    for forward, behind in [*candidates, (None, None)]:
        if forward is not None:
            base = parts.index(behind) if behind else parts.index("root")
            gap = np.linalg.norm(world[:, parts.index(forward)] - world[:, base], axis=-1)
            if not np.nanmedian(gap) > 0.01 * size:  # an end site on its joint: no direction
                continue
        body = Body(tuple(parts), "root", Facing(pair[0], pair[1], forward, behind))
        heading = facing_heading(np.where(seen[..., None], world, 0.0), seen, body)
        flips = len(facing_flips(heading))
        if flips <= FLIP_RATE * max(len(world) - 1, 1):
            return (forward, behind), flips
        tried.append(((forward, behind), flips))
    return min(tried, key=lambda t: t[1])


def _format(name: str, source: str, scheme: str | None, units: str, units_note: str, up: str, up_note: str,
            mapping: Mapping[str, str], facing: Facing, facing_note: str, bones: list[tuple[str, str]],
            unmapped: list[str], root_note: str, fps: float | None, frames: int, floor: float | None = None,
            floor_note: str = "") -> str:
    q = json.dumps
    lines = [f"# Body profile proposed by `likeme profile` for {source or 'a recording'} ({frames} frames; "
             f"{'joint names of the ' + scheme + ' scheme' if scheme else 'joint names of no known scheme'}).",
             "# Check it, edit the lines marked TODO, then: likeme validate --body THIS_FILE RECORDINGS..."]
    if fps is None:
        lines.append("# TODO: the file gives no frame rate (a CSV without a time column): give it where you read it")
    lines.append("bones = [" + ",\n         ".join(", ".join(f"[{q(a)}, {q(b)}]" for a, b in bones[i:i + 3])
                                                 for i in range(0, len(bones), 3)) + "]")
    lines += ["", "[profile]", f"name = {q(name)}",
              f"description = {q('proposed by likeme profile' + (' from ' + source if source else ''))}",
              f"units = {units if _is_number(units) else q(units)}   # {units_note}", f"up = {q(up)}   # {up_note}"]
    if floor is not None:
        lines.append(f"floor = {floor:g}   # {floor_note}")
    elif floor_note.startswith("TODO"):
        lines.append(f"# {floor_note}")
    lines += ["",
              "# likeme part = source joint", "[parts]"]
    if root_note:
        lines.append(f"# {root_note}")
    lines += [f"{_key(p)} = {q(j) if isinstance(j, str) else '{mean = ' + q(list(j)) + '}'}"
              for p, j in mapping.items()]
    if unmapped:
        shown = ", ".join(unmapped[:30]) + (f" and {len(unmapped) - 30} more" if len(unmapped) > 30 else "")
        lines.append(f"# joints not mapped: {shown}")
    lines += ["", "# a left/right pair across the body; forward: a part in front of the body, seen from behind",
              "[facing]"]
    if facing_note:
        lines.append(f"# {facing_note}")
    if facing.also:
        lines.append("# the hips and the shoulders: the line across the body from both turns less with a tracker's jitter")
    lines += [f"{key} = {q(value)}" for key, value in facing.table().items()]
    return "\n".join(lines) + "\n"
