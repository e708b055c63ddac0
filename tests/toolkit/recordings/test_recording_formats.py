"""The same recordings as BVH, CSV joint positions and .npy arrays: the same observations and benchmark tables
(issue 20), files of several formats in one folder, --fps and the profile's fps, and observe going on past a bad
file."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from plugins.bench.data import convert_recordings, make_data, write_positions
from toolkit import ConfigError
from toolkit.recordings.bvh import read_bvh
from likeme.cli import main
from toolkit.recordings.profile import load_profile


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """``likeme bench make-data`` output as BVH, and copies as CSV (no time column: the profile's fps), CSV with a
    time column, and .npy (the profile's fps and joints)."""
    from toolkit.manager import create_plugin_manager

    root = tmp_path_factory.mktemp("formats")
    bvh = make_data(create_plugin_manager(), root / "bvh", streams=2, per_stream=3)
    for name, fmt, time in (("csv", "csv", False), ("timed", "csv", True), ("npy", "npy", False), ("c3d", "c3d", False)):
        shutil.copytree(bvh, root / name)
        convert_recordings(root / name, fmt, time=time)
    return root


def _observe(capsys, folder: Path, files: list[str], *extra: str) -> tuple[int, list, str]:
    status = main(["observe", "--body", str(folder / "profile.toml"), "--repertoire", str(folder / "repertoire"),
                   "--json", *extra, *files])
    out, err = capsys.readouterr()
    return status, json.loads(out) if out.strip() else [], err


def _without_file(report: list) -> list:
    return [{k: v for k, v in entry.items() if k != "file"} for entry in report]


def test_make_data_writes_every_format_with_a_profile_that_reads_it(data):
    assert sorted(p.name for p in (data / "csv" / "streams").iterdir()) == [
        "stream_1.csv", "stream_1.segments.csv", "stream_2.csv", "stream_2.segments.csv"]
    assert not list((data / "npy").rglob("*.bvh")) and list((data / "npy" / "demos").rglob("*.npy"))
    bvh_profile, npy_profile = load_profile(data / "bvh" / "profile.toml"), load_profile(data / "npy" / "profile.toml")
    assert bvh_profile.fps is None and npy_profile.fps == pytest.approx(30.0)
    assert npy_profile.array_joints == tuple(read_bvh(data / "bvh" / "streams" / "stream_1.bvh").names)
    reference = bvh_profile.read(data / "bvh" / "streams" / "stream_1.bvh")
    for name, suffix in (("csv", ".csv"), ("timed", ".csv"), ("npy", ".npy"), ("c3d", ".c3d")):
        motion = load_profile(data / name / "profile.toml").read(data / name / "streams" / f"stream_1{suffix}")
        assert motion.parts == reference.parts and motion.fps == pytest.approx(reference.fps, rel=1e-6)
        if name == "c3d":  # C3D stores 32-bit floats
            np.testing.assert_allclose(motion.positions, reference.positions, rtol=1e-6, atol=1e-6)
        else:
            np.testing.assert_array_equal(motion.positions, reference.positions)


def test_the_same_recording_as_bvh_csv_npy_and_c3d_gives_the_same_observations(data, capsys):
    status, reference, _ = _observe(capsys, data / "bvh", [str(data / "bvh" / "streams" / "stream_1.bvh")])
    assert status == 0 and reference[0]["segments"]
    for name, suffix in (("csv", ".csv"), ("timed", ".csv"), ("npy", ".npy"), ("c3d", ".c3d")):
        status, report, err = _observe(capsys, data / name, [str(data / name / "streams" / f"stream_1{suffix}")])
        assert status == 0, err
        if name != "c3d":
            assert _without_file(report) == _without_file(reference), name
            continue
        # C3D stores 32-bit floats (and its rate as one): the same segments and movements, confidences within 0.05
        assert report[0]["frames"] == reference[0]["frames"] and report[0]["fps"] == pytest.approx(reference[0]["fps"])
        for got, want in zip(report[0]["segments"], reference[0]["segments"], strict=True):
            assert [got[k] for k in ("start_frame", "end_frame", "movement", "decided_at_frame")] == \
                [want[k] for k in ("start_frame", "end_frame", "movement", "decided_at_frame")]
            assert got["confidence"] == pytest.approx(want["confidence"], abs=0.05)


def _table(text: str) -> list[list[str]]:
    """The printed benchmark table and confusion matrix, without the fps column (a measured speed)."""
    rows = []
    for line in text.splitlines():
        cells = line.split("|")
        rows.append(cells[:-3] + cells[-2:] if line.startswith("|") else [line])
    return rows


@pytest.mark.benchmark
@pytest.mark.parametrize("benchmark", ["recognition", "segmentation", "stream"])
def test_bench_gives_the_same_table_for_every_format(data, capsys, benchmark):
    def run(name: str) -> list[list[str]]:
        folder = data / name
        args = ["bench", benchmark, "--body", str(folder / "profile.toml"), "--repertoire", str(folder / "repertoire"),
                "--quiet"] + (["--matcher", "path-search"] if benchmark != "segmentation" else [])
        args += ["--demos", str(folder / "demos")] if benchmark == "recognition" else \
            ["--streams", str(folder / "streams"), "--segmenter", "hub-threshold"]
        if benchmark == "recognition":
            args += ["--json", str(folder / "items.json")]
        assert main(args) == 0
        return _table(capsys.readouterr().out)

    reference = run("bvh")
    assert len(reference) > 2
    for name in ("csv", "timed", "npy"):
        assert run(name) == reference, name
    # C3D stores 32-bit floats: the same table shape and items; a decision near a threshold may differ
    c3d = run("c3d")
    if benchmark == "segmentation":
        assert c3d == reference
    elif benchmark == "recognition":  # the same answer to every demo but one whose score is on its threshold's edge
        bvh, c3d_items = (json.loads((data / name / "items.json").read_text())["items"] for name in ("bvh", "c3d"))
        assert [Path(r["item"]).stem for r in c3d_items] == [Path(r["item"]).stem for r in bvh]
        differ = [(a, b) for a, b in zip(bvh, c3d_items) if a["recognised"] != b["recognised"]]
        assert all(abs(a["score"] - a["threshold"]) <= 0.01 * a["threshold"] for a, _ in differ), differ
    else:
        assert [row[:2] for row in c3d] == [row[:2] for row in reference]


def test_a_folder_may_mix_formats(data, tmp_path, capsys):
    mixed = tmp_path / "mixed"
    shutil.copytree(data / "bvh", mixed)
    clips = sorted((mixed / "repertoire").rglob("*.bvh"))
    for k, path in enumerate(clips):  # every other clip as a CSV, every third as .npy
        if k % 3:
            bvh = read_bvh(path)
            write_positions(path.with_suffix(".csv" if k % 3 == 1 else ".npy"), bvh.names, bvh.positions(),
                            bvh.fps if k % 3 == 1 else None)
            path.unlink()
    (mixed / "profile.toml").write_text((data / "npy" / "profile.toml").read_text())
    assert {p.suffix for p in (mixed / "repertoire").rglob("*.*")} == {".bvh", ".csv", ".npy"}
    stream = str(data / "bvh" / "streams" / "stream_2.bvh")
    status, reference, _ = _observe(capsys, data / "bvh", [stream])
    status, report, err = _observe(capsys, mixed, [stream])
    assert status == 0, err
    assert report == reference


def test_fps_option_wins_over_the_profiles_and_a_time_column_wins_over_both(data, capsys):
    csv_stream = str(data / "csv" / "streams" / "stream_1.csv")
    status, report, _ = _observe(capsys, data / "csv", [csv_stream], "--fps", "60")
    assert status == 0 and report[0]["fps"] == 60.0
    status, report, _ = _observe(capsys, data / "csv", [csv_stream])
    assert report[0]["fps"] == 30.0  # the profile's
    timed = str(data / "timed" / "streams" / "stream_1.csv")
    status, report, _ = _observe(capsys, data / "timed", [timed], "--fps", "60")
    assert report[0]["fps"] == 30.0  # the time column's
    bvh = str(data / "bvh" / "streams" / "stream_1.bvh")
    status, report, _ = _observe(capsys, data / "bvh", [bvh], "--fps", "60")
    assert report[0]["fps"] == 30.0  # the BVH's Frame Time


def test_fps_option_reaches_the_repertoires_clips_too(data, tmp_path, capsys):
    """A profile without ``fps``: the CSV repertoire's clips have no frame rate of their own either, so ``--fps``
    reads them as it reads the files watched; the observations are those of a profile that says that rate."""
    folder = tmp_path / "csv"
    folder.mkdir()
    (folder / "repertoire").symlink_to(data / "csv" / "repertoire")
    (folder / "profile.toml").write_text("\n".join(line for line in (data / "csv" / "profile.toml").read_text()
                                                   .splitlines() if not line.startswith("fps")))
    stream, fps = str(data / "csv" / "streams" / "stream_1.csv"), repr(load_profile(data / "csv" / "profile.toml").fps)
    assert main(["observe", "--body", str(folder / "profile.toml"), "--repertoire", str(folder / "repertoire"),
                 "--set", "motor.fps=0", "--fps", fps, stream]) == 1  # the clips, when --fps does not reach them
    assert "repertoire" in (err := capsys.readouterr().err) and "no frame rate" in err
    status, report, _ = _observe(capsys, folder, [stream], "--fps", fps)
    _, reference, _ = _observe(capsys, data / "csv", [stream])
    assert status == 0 and _without_file(report) == _without_file(reference)
    (folder / "streams").symlink_to(data / "csv" / "streams")
    tables = []
    for where, extra in ((folder, ("--fps", fps)), (data / "csv", ())):
        assert main(["bench", "stream", "--body", str(where / "profile.toml"), "--repertoire",
                     str(where / "repertoire"), "--streams", str(where / "streams"), *extra]) == 0
        tables.append(_table(capsys.readouterr().out))
    assert tables[0] == tables[1]


def test_without_a_frame_rate_a_csv_without_time_is_an_error_naming_it(data, tmp_path, capsys):
    profile = tmp_path / "profile.toml"
    profile.write_text((data / "bvh" / "profile.toml").read_text())  # no fps key
    with pytest.raises(ConfigError) as info:
        load_profile(profile).read(data / "csv" / "streams" / "stream_1.csv")
    assert "stream_1.csv" in str(info.value) and "no frame rate" in str(info.value)
    assert "--fps" in str(info.value)


def test_observe_reports_the_good_files_and_one_error_line_for_a_bad_one(data, tmp_path, capsys):
    bad = tmp_path / "bad.bvh"
    bad.write_text((data / "bvh" / "streams" / "stream_1.bvh").read_text()[:-400] + "x\n")
    a, b = (str(data / "bvh" / "streams" / f"stream_{k}.bvh") for k in (1, 2))
    status = main(["observe", "--body", str(data / "bvh" / "profile.toml"), "--repertoire",
                   str(data / "bvh" / "repertoire"), a, str(bad), b, str(tmp_path / "missing.csv")])
    out, err = capsys.readouterr()
    assert status == 1
    assert f"{a}: " in out and f"{b}: " in out and "bad.bvh" not in out
    lines = err.strip().splitlines()
    assert len(lines) == 2 and all(line.startswith("likeme: error: ") for line in lines)
    assert any(str(bad) in line for line in lines) and any("missing.csv" in line for line in lines)


def test_an_unknown_suffix_lists_the_formats(data, tmp_path):
    path = tmp_path / "take.txt"
    path.write_text("x")
    with pytest.raises(ConfigError) as info:
        load_profile(data / "bvh" / "profile.toml").read(path)
    assert "unknown recording format '.txt'" in str(info.value) and "available: .bvh, .csv, .npy" in str(info.value)


def test_a_csv_without_a_mapped_joint_names_the_part_and_the_joints_it_has(data, tmp_path):
    bvh = read_bvh(data / "bvh" / "streams" / "stream_1.bvh")
    names = [n if n != "nose" else "snout" for n in bvh.names]
    write_positions(tmp_path / "take.csv", names, bvh.positions()[:5])
    with pytest.raises(ConfigError) as info:
        load_profile(data / "csv" / "profile.toml").read(tmp_path / "take.csv")
    message = str(info.value)
    assert "joint 'nose' of part 'nose' is not in" in message and "key parts.nose" in message
    assert "available: root, head, snout" in message


def test_an_npy_array_takes_the_mapped_joints_without_a_joints_key(data, tmp_path):
    profile = load_profile(data / "csv" / "profile.toml")  # fps, no joints key: the arrays hold the mapped joints
    assert profile.array_joints is None and profile.npy_joints == profile.joints
    bvh = read_bvh(data / "bvh" / "streams" / "stream_1.bvh")
    order = [bvh.names.index(j) for j in profile.joints]
    np.save(tmp_path / "take.npy", bvh.positions()[:, order])
    np.testing.assert_array_equal(profile.read(tmp_path / "take.npy").positions,
                                  load_profile(data / "bvh" / "profile.toml").read(
                                      data / "bvh" / "streams" / "stream_1.bvh").positions)


@pytest.mark.parametrize("line, expected", [
    ("fps = 0", "key profile.fps: invalid fps 0"),
    ("fps = nan", "key profile.fps: invalid fps nan"),
    ('fps = "30"', "key profile.fps: invalid fps '30'"),
    ("fps = 20000", "expected frames per second of recordings without a time of their own, a number in [1/60, 10000]"),
    ("fps = 1e-300", "key profile.fps: invalid fps 1e-300"),
    ('joints = "root"', "key profile.joints: invalid joints 'root'"),
    ('joints = ["root", "root"]', "key profile.joints: joints named twice: ['root']"),
    ('joints = ["root", "head"]', "key profile.joints: joint 'nose' of part 'nose' is not in the joints list"),
])
def test_bad_fps_and_joints_keys_name_the_key(data, tmp_path, line, expected):
    path = tmp_path / "p.toml"
    text = (data / "bvh" / "profile.toml").read_text().replace("[profile]\n", f"[profile]\n{line}\n")
    path.write_text(text)
    at = text.splitlines().index(line) + 1  # the line written, under [profile]
    with pytest.raises(ConfigError) as info:
        load_profile(path)
    assert str(info.value).startswith(f"{path}:{at}:") and expected in str(info.value)


def test_validate_reads_csv_and_npy_with_and_without_a_profile(data, capsys):
    csv_file, npy_file = data / "csv" / "streams" / "stream_1.csv", data / "npy" / "streams" / "stream_1.npy"
    frames = read_bvh(data / "bvh" / "streams" / "stream_1.bvh").n_frames
    assert main(["validate", "--fps", "30", str(csv_file), str(npy_file)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].endswith(f"CSV: 11 joints, {frames} frames at 30 fps, 0 missing joint positions")
    assert out[1].endswith(f"NumPy array: 11 joints, {frames} frames at 30 fps, 0 missing joint positions")
    assert main(["validate", "--body", str(data / "npy" / "profile.toml"), str(npy_file), str(csv_file)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert all("profile 'max' maps 11, leaves 0 unmapped" in line for line in out)
    assert main(["validate", str(npy_file)]) == 1  # no frame rate without --fps or a profile
    assert "a .npy file has no frame rate" in capsys.readouterr().err


def test_a_streams_folder_of_csv_is_its_own_repertoire_without_its_segment_files(data, capsys):
    """bench segmentation without --repertoire finds hubs from the streams' ends: NAME.segments.csv is not a clip."""
    from plugins.lib.clip_repertoire import clip_files

    assert list(clip_files(data / "csv" / "streams")) == ["stream_1", "stream_2"]
    tables = []
    for name in ("bvh", "csv"):
        folder = data / name
        assert main(["bench", "segmentation", "--body", str(folder / "profile.toml"), "--streams",
                     str(folder / "streams"), "--segmenter", "hub-threshold", "--quiet"]) == 0
        tables.append(_table(capsys.readouterr().out))
    assert tables[0] == tables[1]


def test_a_piped_benchmark_starts_with_its_table_and_its_files_are_0644_under_umask_022(data, tmp_path):
    """Progress on standard error, the table first on standard output (``likeme bench recognition ... | head -n 3``),
    and what it writes readable by others as the umask allows (not mkstemp's 0600)."""
    import os
    import subprocess
    import sys

    folder = data / "bvh"
    out_json, out_png = tmp_path / "r.json", tmp_path / "r.png"
    command = [sys.executable, "-m", "likeme", "bench", "recognition", "--body", str(folder / "profile.toml"),
               "--repertoire", str(folder / "repertoire"), "--demos", str(folder / "demos"), "--matcher", "dtw",
               "--json", str(out_json), "--plot", str(out_png)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600,
                          preexec_fn=lambda: os.umask(0o022), cwd=Path(__file__).resolve().parents[3])
    assert done.returncode == 0, done.stderr
    head = done.stdout.splitlines()[:3]
    assert head[0].startswith("| plugin |") and head[1].startswith("|---") and head[2].startswith("| dtw |")
    for path in (out_json, out_png):
        assert (path.stat().st_mode & 0o777) == 0o644, oct(path.stat().st_mode)
