"""Labelled clips: a folder of recordings, one sub-folder per movement (``bow/take1.bvh``, ``bow/take2.csv``,
``wave/max.bvh``), read through a body profile.

A flat folder of recordings (no sub-folders) is a folder of movements of one clip each, named after their files.
A movement's further examples are named ``bow#2``, ``bow#3``... (:func:`example_name`), so a folder's name may not
hold ``#``. What is made of the clips (hubs found from their ends, a posegraph, motor command graphs) is the
motor systems' (:mod:`plugins.lib.clip_repertoire`): a :class:`ClipFolder` is handed to the motor system of a
character composed with it (``compose_character(..., repertoire=ClipFolder(folder, profile))``), which reads the
clips with its own settings.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from toolkit.errors import ConfigError
from toolkit.recordings import is_recording

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.recordings.profile import BodyProfile

__all__ = ["ClipFolder", "clip_files", "example_name", "EXAMPLE_MARK"]

EXAMPLE_MARK = "#"
"""What joins a movement's name and the number of its further examples (``bow#2``): never in a movement's name."""


def example_name(movement: str, earlier: int) -> str:
    """The name of a movement's next example clip, after ``earlier`` ones: ``bow``, ``bow#2``, ``bow#3``..."""
    return movement if earlier == 0 else f"{movement}{EXAMPLE_MARK}{earlier + 1}"


def clip_files(folder: str | Path) -> dict[str, list[Path]]:
    """Clip files by movement name (sub-folder name), sorted; a :class:`ConfigError` if there are none."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ConfigError("not a folder", file=folder, expected="a folder with one sub-folder of BVH clips per movement")
    out: dict[str, list[Path]] = {}
    for sub in sorted(p for p in folder.iterdir() if p.is_dir()):
        files = sorted(p for p in sub.iterdir() if is_recording(p))
        if files:
            out[sub.name] = files
    if not out:  # a flat folder of recordings: each file on its own (its ends still give hubs)
        for path in sorted(p for p in folder.iterdir() if is_recording(p)):
            out[path.stem] = [path]
    for movement, files in out.items():
        if EXAMPLE_MARK in movement:  # bow#2 is the name of bow's second example: it would replace that one
            raise ConfigError(f"movement name {movement!r} contains {EXAMPLE_MARK!r}", file=files[0].parent
                              if files[0].parent != folder else files[0],
                              expected=f"movement names without {EXAMPLE_MARK!r} (it names a movement's further "
                              f"examples: {example_name('bow', 1)}, {example_name('bow', 2)}...); rename the folder")
    if not out:
        raise ConfigError("no clips found", file=folder,
                          expected="sub-folders named after movements holding .bvh, .csv or .npy clips "
                                   "(walk/take1.bvh ...)",
                          available=[p.name for p in folder.iterdir()])
    return out


@dataclass(eq=False)
class ClipFolder:
    """A folder of labelled clips and the body profile they are read with, given to a character's motor system.

    The profile is the one the caller loaded (read once, passed down: never found again from a path). ``read``
    keeps what a motor system made of the clips, by the settings it read them with, so that several characters
    composed with one folder (a benchmark comparing matchers) read it once.
    """

    folder: Path
    profile: BodyProfile
    read: dict[Any, Any] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        self.folder = Path(self.folder)

    def files(self) -> dict[str, list[Path]]:
        """The clip files by movement (:func:`clip_files`)."""
        return clip_files(self.folder)
