"""``likeme profile``: a body profile proposed for a recording (:mod:`likeme.profiles`), checked on the same recording,
printed or written to ``--out``; what it could not decide is marked ``# TODO``."""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from likeme.cli.common import warn
from toolkit.errors import ConfigError

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.manager import PluginManager

__all__ = ["add_parser", "handle", "PROFILE_FRAMES"]


def add_parser(sub: Any) -> None:
    """``likeme profile``."""
    p = sub.add_parser("profile", help="propose a body profile for a recording (BVH, or CSV joint positions)")
    p.add_argument("file", metavar="FILE", help="a BVH file, or a CSV of joint positions (JOINT_x, JOINT_y, JOINT_z)")
    p.add_argument("--out", metavar="PROFILE.toml", help="write the profile there (default: print it)")
    p.set_defaults(handler=handle)


PROFILE_FRAMES = 20_000
"""The frames of a recording ``likeme profile`` reads (from its start): enough to see a body's size, up and facing."""


def _read_recording(path: str) -> tuple[list[str], Any, list[int] | None, float | None, int]:
    """A recording's joint names, positions (F, J, 3) in its own units and axes (at most :data:`PROFILE_FRAMES`),
    hierarchy (BVH) or None, frame rate (None: the file does not tell) and number of frames."""
    import numpy as np

    from toolkit.recordings import SUFFIXES, open_recording

    named = tuple(s for s in SUFFIXES if s != ".npy")  # a .npy array has no joint names to propose parts from
    suffix = Path(path).suffix.lower()
    if suffix not in named:
        raise ConfigError(f"cannot propose a profile for a {suffix or 'suffix-less'} file", file=path, key=("FILE",),
                          expected="a BVH file, a CSV of joint positions or a C3D file (a .npy array has no joint "
                                   "names)", available=named)
    with open_recording(path, need_fps=False) as recording:  # the proposal needs no frame rate
        kept, count = [], 0
        for block in recording.blocks():
            kept.append(block[: PROFILE_FRAMES - count])
            count += len(kept[-1])
            if count >= PROFILE_FRAMES:
                break
    positions = np.concatenate(kept) if kept else np.zeros((0, len(recording.names), 3))
    frames = recording.n_frames if recording.n_frames is not None else len(positions)
    parents = list(recording.parents) if recording.parents is not None else None
    return list(recording.names), positions, parents, recording.fps, frames


def handle(args: argparse.Namespace, pm: PluginManager) -> int:
    """Propose a body profile for a recording (``likeme.profiles.propose_profile``), check it on the same
    recording, and print it or write it to ``--out``; what it could not decide is marked ``# TODO``."""
    import numpy as np

    from likeme.profiles import propose_profile, recording_warnings
    from toolkit.files import check_regular_file, scratch_folder, write_output
    from toolkit.recordings.profile import load_profile

    check_regular_file(args.file, "recording", "motion")
    names, positions, parents, fps, frames = _read_recording(args.file)
    if len(positions) == 0:
        raise ConfigError("no frames", file=args.file, expected="a recording with at least one frame")
    stem = re.sub(r"[^A-Za-z0-9_-]+", "-", Path(args.out or args.file).stem).strip("-") or "proposed"
    proposal = propose_profile(names, positions, parents=parents, name=stem, source=Path(args.file).name, fps=fps)
    text = proposal.text if proposal.text.endswith("\n") else proposal.text + "\n"  # a text file ends its last line
    with scratch_folder() as tmp:  # the proposal must load and pass its own checks on this recording
        profile = load_profile(write_output(tmp / f"{stem}.toml", text, "draft profile"))
    converted = profile.convert(positions, names)
    warnings = recording_warnings(profile, [(converted, np.isfinite(converted).all(axis=-1))])
    if args.out:
        write_output(args.out, text, "profile")
        print(f"wrote {args.out}", file=sys.stderr)
    else:
        print(text, end="")
    if len(positions) < frames:
        print(f"likeme: note: {args.file}: proposed from the first {len(positions)} of {frames} frames",
              file=sys.stderr)
    for text in proposal.todo:
        print(f"likeme: note: {args.file}: TODO: {text}", file=sys.stderr)
    warn(args.file, proposal.warnings + warnings)  # the proposal's own (an implausible height), then the checks'
    return 0
