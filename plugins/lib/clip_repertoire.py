"""A movement repertoire from labelled motion-capture clips, with hubs found from the clips.

A folder with one sub-folder per movement name, each holding BVH clips of that
movement, read through a body profile (:mod:`toolkit.recordings.profile`), becomes the
repertoire of a motor system: the ``posegraph`` makes each clip a path of pose
nodes (Buchsbaum & Blumberg 2005, §4.1), the ``motor-command-graph`` turns each
clip into a chain of guiding-stroke commands by its inverse model (Kopp &
Graeser 2006, §4.3). Both use the same clips, hubs and body.

Hubs (B&B §4.1: the poses movements start and end in) are found rather than
assumed: the first and last pose of every clip are clustered (average linkage
on the eq. 1 pose distance, :mod:`plugins.lib.pose_distance`); every cluster that
holds at least ``hub_share`` of the clip ends is a hub, its medoid the hub
pose. The largest cluster is always a hub, so locomotion clips that never stand
still still get one.

Poses are root-relative in the body's own frame (§5.1, :func:`plugins.lib.root_frame.root_relative` with the
facing a centred running median over the clip), lifted to the median height of the root at the hubs, which is the
local frame a motor system uses. Hidden parts follow ``docs/conventions.md`` (held where last seen).

A repertoire can as well be built from labelled world-position motions in memory (:func:`clip_repertoire`, what
reading a folder does once the files are read) and handed to a motor system when a character is composed
(``compose_character(..., repertoire=...)``, ``compose_observer(pm, profile, repertoire)``): the motor system
then builds from it instead of its ``clips`` folder, with the same hubs and the same frames.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from plugins.lib.gaps import bridged
from plugins.lib.jitter import jitter_about_root
from plugins.lib.lowpass import low_passed
from plugins.lib.pose_distance import pose_distance
from plugins.lib.root_frame import RecordingFacing, root_relative
from toolkit import Body, ConfigError, Motion, Parameter
from toolkit.recordings.clips import ClipFolder, clip_files, example_name
from toolkit.recordings.profile import BodyProfile, load_profile

__all__ = ["Clip", "ClipRepertoire", "load_clip_repertoire", "clip_repertoire", "find_hubs", "root_relative_motion",
           "clip_files", "example_name", "CLIP_PARAMETERS", "repertoire_for"]



@dataclass(frozen=True)
class Clip:
    """One example of a movement: its label, file (or name, built in memory) and local-frame motion (root at hub
    height; its world positions in :attr:`Motion.world`); ``jitter``: each part's jitter about the root as the file
    gave it, before the low-pass, as a variance per axis (m^2, (P,); :func:`plugins.lib.jitter.jitter_about_root`),
    ``None`` where not measured."""

    movement: str
    source: Path | str
    motion: Motion
    jitter: np.ndarray | None = None


@dataclass(frozen=True)
class ClipRepertoire:
    """Clips by movement, the hub poses found from them, and the profile they were read with.

    ``folder`` is where the clips were read from (``None``: built in memory); ``hub_radius`` and ``hub_share``
    the settings the hubs were found with; ``worlds`` the clips' world positions as they were given (read from the
    files, nothing bridged or filtered), one for each clip, which a repertoire with other hub settings is built
    from again.
    """

    profile: BodyProfile
    clips: tuple[Clip, ...]
    hubs: np.ndarray  # (H, P, 3), local frame
    worlds: tuple[Motion, ...]
    folder: Path | None
    hub_radius: float = 0.06
    hub_share: float = 0.2

    @property
    def movements(self) -> list[str]:
        return sorted({c.movement for c in self.clips})

    def with_hubs(self, hub_radius: float, hub_share: float) -> ClipRepertoire:
        """This repertoire with hubs found with other settings (itself when they are its own): built again from the
        clips' world positions as they were given (:attr:`worlds`)."""
        if (hub_radius, hub_share) == (self.hub_radius, self.hub_share):
            return self
        return clip_repertoire(self.worlds, [c.movement for c in self.clips], self.profile,
                               sources=[c.source for c in self.clips], hub_radius=hub_radius, hub_share=hub_share,
                               folder=self.folder)


def root_relative_motion(world: Motion, body: Body, facing_window: float = 1.0) -> Motion:
    """A motion known whole (a repertoire's clip, a demonstration learned as a take) from world positions to
    root-relative positions in the body's frame (§5.1): a tracker's short gaps bridged first
    (:func:`plugins.lib.gaps.bridged`) and its jitter filtered out (:func:`plugins.lib.lowpass.low_passed`), the
    facing a centred running median over ``facing_window`` seconds, parts hidden longer held (docs/conventions.md);
    the world positions the pose was found from (bridged and filtered) kept beside them (:attr:`Motion.world`: where
    the body travels and how it turns, :mod:`plugins.lib.travel`, read from the same filtered root as the pose).
    Read the motion as given again, not this one's world positions, to build it once more: they are filtered
    already."""
    world = bridged(world)
    smooth = low_passed(world, keep=body.angle_mask)
    window = max(1, int(round(facing_window * world.fps)))
    pose, mask, _, _ = root_relative(smooth.positions, smooth.visible, body, RecordingFacing(window))
    return Motion(pose, world.fps, world.parts, mask, smooth.positions).filled()


PAIR_BLOCK = 2**22
"""Numbers of pose differences ``find_hubs`` holds at once (rows x n ends x P parts x 3): about 32 MB."""


def find_hubs(ends: np.ndarray, radius: float, share: float) -> np.ndarray:
    """Hub poses (H, P, 3) among the clip end poses ``ends`` (N, P, 3), largest cluster first.

    Average-linkage clusters of eq. 1 distance cut at ``radius`` metres; a cluster
    with at least ``share`` of the ends is a hub, its medoid the hub pose.
    """
    from scipy.cluster.hierarchy import fcluster, linkage
    from scipy.spatial.distance import squareform

    n = len(ends)
    if n == 1:
        return ends.copy()
    # eq. 1 between every pair of ends, a block of rows at a time: the (rows, n, P, 3) differences stay near 32 MB
    # whatever the repertoire's size (one call over all pairs needed n^2 P 3 floats: 4 GB at 2,000 movements)
    rows = max(1, PAIR_BLOCK // max(1, n * ends[0].size))
    d = np.concatenate([pose_distance(ends[i : i + rows, None], ends[None, :], True) for i in range(0, n, rows)])
    d = 0.5 * (d + d.T)
    np.fill_diagonal(d, 0.0)
    labels = fcluster(linkage(squareform(d, checks=False), "average"), t=radius, criterion="distance")
    clusters = sorted((np.flatnonzero(labels == k) for k in np.unique(labels)), key=len, reverse=True)
    hubs = []
    for i, members in enumerate(clusters):
        if i > 0 and len(members) < share * n:
            break
        medoid = members[np.argmin(d[np.ix_(members, members)].sum(axis=1))]
        hubs.append(ends[medoid])
    return np.stack(hubs)


def load_clip_repertoire(folder: str | Path, profile: str | Path | BodyProfile, *, hub_radius: float = 0.06,
                         hub_share: float = 0.2, fps: float | None = None) -> ClipRepertoire:
    """Read every clip of ``folder`` through ``profile`` and find the hubs (:func:`clip_repertoire`).

    ``fps``: the frame rate of clips without one of their own (a CSV without a ``time`` column, a ``.npy`` array),
    as for :meth:`BodyProfile.read <toolkit.recordings.profile.BodyProfile.read>`; ``None``: the profile's.
    """
    profile = profile if isinstance(profile, BodyProfile) else load_profile(profile)
    labelled = [(movement, path) for movement, files in clip_files(Path(folder)).items() for path in files]
    return clip_repertoire([profile.read(path, fps) for _, path in labelled], [movement for movement, _ in labelled],
                           profile, sources=[path for _, path in labelled], hub_radius=hub_radius,
                           hub_share=hub_share, folder=Path(folder))


def clip_repertoire(motions: Sequence[Motion], labels: Sequence[str], profile: str | Path | BodyProfile, *,
                    sources: Sequence[Path | str] | None = None, hub_radius: float = 0.06, hub_share: float = 0.2,
                    folder: Path | None = None) -> ClipRepertoire:
    """A repertoire from labelled clips of world positions in ``profile``'s parts, the hubs found from them.

    Parameters
    ----------
    motions : sequence of Motion
        World positions (metres, +y up) of the profile's body parts, in its order, one clip each.
    labels : sequence of str
        The movement of each clip.
    sources : sequence of Path or str, optional
        Where each clip comes from (its file); by default its example name (``bow``, ``bow#2``...).
    hub_radius, hub_share : float
        As :func:`find_hubs`.
    folder : Path, optional
        The folder the clips were read from, if any.
    """
    profile = profile if isinstance(profile, BodyProfile) else load_profile(profile)
    motions, labels = list(motions), [str(label) for label in labels]
    if len(motions) != len(labels):
        raise ConfigError(f"{len(motions)} clips and {len(labels)} labels", key=("labels",),
                          expected="one movement label per clip")
    if not motions:
        raise ConfigError("no clips", key=("clips",), expected="at least one labelled clip")
    if sources is None:
        counts: dict[str, int] = {}
        sources = []
        for label in labels:
            sources.append(example_name(label, counts.get(label, 0)))
            counts[label] = counts.get(label, 0) + 1
    rel: list[tuple[str, Path | str, Motion]] = []
    jitters = [jitter_about_root(world.positions, world.visible, world.fps, profile.body) for world in motions]
    for movement, source, world in zip(labels, sources, motions):
        where = {"file": source} if isinstance(source, Path) else {"key": ("clips", str(source))}
        if tuple(world.parts) != tuple(profile.body.parts):
            raise ConfigError("the clip's parts are not the profile's parts", **where,
                              expected=f"parts {list(profile.body.parts)}", available=list(world.parts))
        motion = root_relative_motion(world, profile.body)
        if motion.n_frames < 2:
            raise ConfigError(f"clip has {motion.n_frames} frame", **where, expected="at least two frames")
        rel.append((movement, source, motion))
    ends = np.stack([_filled(m, i) for _, _, m in rel for i in (0, -1)])
    hubs_rel = find_hubs(ends, hub_radius, hub_share)
    height = _root_height(rel)
    lift = np.array([0.0, height, 0.0])
    clips = tuple(Clip(mv, src, Motion(m.positions + lift, m.fps, m.parts, m.visible, m.world), jitter)
                  for (mv, src, m), jitter in zip(rel, jitters))
    return ClipRepertoire(profile, clips, hubs_rel + lift, tuple(motions), folder, hub_radius, hub_share)


def _filled(motion: Motion, frame: int) -> np.ndarray:
    """A frame of a clip (hidden parts held, as the clip is kept), a part never seen at 0."""
    return np.nan_to_num(motion.positions[frame])


def _root_height(rel: list[tuple[str, Path | str, Motion]]) -> float:
    """Median height of the root above the lowest part at the clips' ends: the hub's standing height."""
    heights = []
    for _, _, m in rel:
        for f in (0, -1):
            pose = m.positions[f]
            if m.visible[f].any():
                heights.append(-float(np.nanmin(np.where(m.visible[f], pose[:, 1], np.nan))))
    return float(np.median(heights)) if heights else 0.0


CLIP_PARAMETERS = (
    Parameter("clips", str, "", "Folder of labelled BVH clips, one sub-folder per movement, to build the repertoire "
              "from (relative to the character file); replaces poses and movements."),
    Parameter("profile", str, "", "Body profile TOML the clips are read with (relative to the character file); "
              "required with clips, and its parts must be the character's body parts."),
    Parameter("hub_radius", float, 0.06, "Clip end poses closer than this (eq. 1, m, average linkage) share a hub.",
              minimum=0.0),
    Parameter("hub_share", float, 0.2, "Share of clip ends a cluster needs to be a hub (the largest always is one).",
              minimum=0.0, maximum=1.0),
    Parameter("fps", float, 0.0, "Frame rate (Hz) of clips without one of their own (a CSV without a time column, a "
              ".npy array); 0: the profile's. A BVH's Frame Time and a CSV's time column win over it "
              "(`likeme observe --fps` sets it).", minimum=0.0),
)
"""The parameters of a motor system that can build its repertoire from clips."""

def repertoire_for(params: dict, owner: object) -> ClipRepertoire | None:
    """The clip repertoire a motor system builds from, or ``None`` when it has no clips.

    The owner's ``repertoire`` (given when it was composed, :attr:`toolkit.character.Character.repertoire`) comes
    first: a :class:`~toolkit.recordings.clips.ClipFolder` is read with these parameters' ``hub_radius``,
    ``hub_share`` and ``fps`` (once per settings: what was read is kept in the folder object), a
    :class:`ClipRepertoire` built in memory gets its hubs found with them. Otherwise the ``clips`` folder and
    ``profile`` file the parameters name, relative to the owner's character file, are read.
    """
    given = getattr(owner, "repertoire", None)
    settings = {"hub_radius": params["hub_radius"], "hub_share": params["hub_share"]}
    if given is not None:
        if params["clips"]:
            raise ConfigError("clips given twice", key=("clips",),
                              expected="either a clips folder or a repertoire given to the character, not both")
        if isinstance(given, ClipFolder):
            key = (params["hub_radius"], params["hub_share"], params.get("fps") or None)
            if key not in given.read:
                given.read[key] = load_clip_repertoire(given.folder, given.profile, fps=key[2], **settings)
            return _same_parts(owner, given.read[key])
        if not isinstance(given, ClipRepertoire):
            raise ConfigError(f"a repertoire of type {type(given).__name__}", key=("clips",),
                              expected="a toolkit.recordings.clips.ClipFolder or a "
                                       "plugins.lib.clip_repertoire.ClipRepertoire")
        return _same_parts(owner, given.with_hubs(**settings))
    if not params["clips"]:
        return None
    if not params["profile"]:
        raise ConfigError("clips without a profile", key=("profile",), expected="the body profile the clips are read with")
    file = getattr(owner, "file", None)
    base = file.parent if file is not None else Path.cwd()
    return _same_parts(owner, load_clip_repertoire((base / params["clips"]).resolve(),
                                                   (base / params["profile"]).resolve(),
                                                   fps=params.get("fps") or None, **settings))


def _same_parts(owner: object, repertoire: ClipRepertoire) -> ClipRepertoire:
    """The repertoire, or a :class:`ConfigError` when the owner's body parts are not its profile's parts."""
    body = getattr(owner, "body", None)
    if body is not None and tuple(body.parts) != tuple(repertoire.profile.body.parts):
        raise ConfigError("the body's parts are not the profile's parts", key=("profile",),
                          expected=f"[body] parts = {list(repertoire.profile.body.parts)}", available=list(body.parts))
    return repertoire
