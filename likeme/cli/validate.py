"""``likeme validate``: character, scenario, observer-template and body-profile files checked, and recordings read
through (every frame checked); with ``--body PROFILE``, warnings where the profile is probably wrong for them."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from likeme.cli.common import warn
from toolkit.arguments import fps_type
from toolkit.errors import LikemeError

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.manager import PluginManager

__all__ = ["add_parser", "handle"]


def add_parser(sub: Any) -> None:
    """``likeme validate``."""
    p = sub.add_parser("validate", help="check character, scenario and body-profile files and recordings")
    p.add_argument("files", nargs="+", metavar="FILE", help="character, scenario or profile TOML files, or "
                   "recordings (.bvh, .csv, .npy)")
    p.add_argument("--body", metavar="PROFILE", help="also check that each recording has the joints this profile "
                   "maps (and read a .npy array with its joint names), and warn where the profile is probably wrong "
                   "for it (units, up axis, facing)")
    p.add_argument("--strict", action="store_true", help="exit with status 1 on a warning too")
    p.add_argument("--fps", type=fps_type, default=None, metavar="HZ",
                   help="frame rate of recordings without one of their own (as for observe)")
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace, pm: PluginManager) -> int:
    from toolkit.character import COMPONENT_TABLES, load_character
    from toolkit.config.toml import read_toml
    from toolkit.files import check_regular_file
    from toolkit.config.observer_templates import check_observer_template, is_observer_template
    from toolkit.recordings import SUFFIXES, recording_format
    from toolkit.recordings.profile import is_profile, load_profile
    from toolkit.report import describe_character
    from toolkit.scenario import is_scenario, load_scenario

    failed = warned = 0
    try:
        profile = load_profile(args.body) if args.body else None
    except LikemeError as err:
        print(f"likeme: error: {err}", file=sys.stderr)
        return 1
    flips: list[tuple[str, Any, int]] = []  # where the facing flips in each recording, counted over them all
    if profile is not None:
        warned += warn(args.body, _profile_warnings(profile))
    for path in args.files:
        try:
            if Path(path).suffix.lower() in SUFFIXES:
                print(_validate_recording(path, profile, args.fps))
                if profile is not None:  # where the profile is probably wrong for it, in every format
                    warned += warn(path, _recording_warnings(profile, path, flips, args.fps))  # (likeme.profiles)
                continue
            table = read_toml(check_regular_file(path, "TOML file", "config"))
            if is_scenario(table):
                scenario = load_scenario(path, pm)
                world = scenario.world
                print(f"ok    {path}: scenario {scenario.name!r}: {len(world.actors)} actor(s) ({', '.join(world.actors)}), {len(world.objects)} object(s)")
            elif is_observer_template(table):
                plugins = check_observer_template(path, pm)
                comps = ", ".join(f"{k} {v}" for k, v in plugins.items())
                print(f"ok    {path}: observer template: {comps} (a body profile and clips complete it)")
            elif is_profile(table):
                prof = load_profile(path)
                print(f"ok    {path}: body profile {prof.name!r}: {len(prof.joints)} parts, units {prof.scale:g} m, up {prof.up}")
                warned += warn(path, _profile_warnings(prof))
            else:
                c = describe_character(load_character(path, pm))
                comps = ", ".join(f"{k} {c[k]['plugin']}" for k in COMPONENT_TABLES if k in c)
                moves = c["motor"].get("movements")
                print(f"ok    {path}: character {c['name']!r}: {c['parts']} parts, {moves} movements; {comps}")
        except LikemeError as err:
            failed += 1
            print(f"likeme: error: {err}", file=sys.stderr)
    if flips:
        from likeme.profiles import facing_warnings

        warned += sum(warn(path, [text]) for path, text in facing_warnings(flips))
    return 1 if failed or (warned and args.strict) else 0


def _profile_warnings(profile: Any) -> list[str]:
    from likeme.profiles import profile_warnings

    return profile_warnings(profile)


def _recording_warnings(profile: Any, path: str | Path, flips: list[tuple[str, Any, int]],
                        fps: float | None = None) -> list[str]:
    """Where ``profile`` is probably wrong for the recording ``path`` (units, up axis), read a block at a time as
    :meth:`BodyProfile.stream` gives it in any format (BVH, CSV, .npy, C3D; its ``[files]`` table applied); the
    frames where its facing flips are added to ``flips``, to be counted over every recording."""
    from likeme.profiles import RecordingCheck

    with profile.stream(path, fps=fps) as blocks:
        check = RecordingCheck(blocks.profile)  # the profile as it reads this file
        for positions, visible in blocks:
            check.update(positions, visible)
    flips.append((str(path), *check.flips()))
    return check.warnings(facing=False)


def _validate_recording(path: str, profile: Any, fps: float | None) -> str:
    """``likeme validate`` of a recording: every frame read and checked, a block at a time; with a profile, its
    joints checked against the profile's and read as it reads them."""
    import numpy as np

    from toolkit.recordings import open_recording, recording_format
    from toolkit.recordings.csv_positions import has_header

    fmt = recording_format(path)
    profile = profile.for_file(path) if profile is not None else None  # its [files] table for this file
    rate = fps if fps is not None or profile is None else profile.fps
    names = None
    if fmt == ".npy":
        names = profile.npy_joints if profile is not None else _npy_joint_names(path)
    elif fmt == ".csv" and profile is not None and not has_header(path):
        names = profile.npy_joints
    with open_recording(path, names=names, fps=rate) as recording:
        unmapped = profile.check(recording) if profile is not None else []
        frames = hidden = 0
        for block in recording.blocks():
            frames += len(block)
            hidden += int((~np.isfinite(block).all(axis=-1)).sum())
    if fmt == ".bvh":
        line = f"ok    {path}: BVH: {len(recording.names)} joints, {recording.n_frames} frames at {recording.fps:g} fps"
    else:
        line = (f"ok    {path}: {recording.kind}: {len(recording.names)} joints, {frames} frames at "
                f"{recording.fps:g} fps, {hidden} missing joint positions")
    if profile is not None:
        line += f"; profile {profile.name!r} maps {len(profile.joints)}, leaves {len(unmapped)} unmapped"
    return line


def _npy_joint_names(path: str) -> list[str] | None:
    """Placeholder joint names (``joint_0``...) for a ``.npy`` array validated without a profile, or None when its
    header is not that of an array of joints (the reader then names what is wrong)."""
    from toolkit.files import check_regular_file
    from toolkit.recordings.npy_positions import read_header

    check_regular_file(path, "recording of joint positions", "motion")
    shape = read_header(Path(path)).shape  # a header that does not match its file is an error naming it
    return [f"joint_{k}" for k in range(shape[1])] if len(shape) == 3 and 0 < shape[1] <= 10_000 else None
