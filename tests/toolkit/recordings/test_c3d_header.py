"""A C3D file checked against its own header before it is read (issue 38): processor byte, parameter blocks, data
start, frame count; a truncated file is an error naming it, never a shorter recording; special and unreadable files
are one line for CSV and C3D as for the other formats."""

from __future__ import annotations

import contextlib
import io
import os
import struct
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.bench.data import write_positions
from toolkit.errors import ConfigError
from toolkit.recordings.positions import read_positions

NAMES = ["hips", "head", "hand"]
FRAMES = 40


def _c3d(folder: Path, name: str = "take.c3d") -> Path:
    positions = np.random.default_rng(0).normal(size=(FRAMES, len(NAMES), 3))
    return write_positions(folder / name, NAMES, positions, fps=30.0)


@pytest.fixture(scope="module")
def whole(tmp_path_factory) -> bytes:
    return _c3d(tmp_path_factory.mktemp("c3d")).read_bytes()


def _read(tmp_path: Path, data: bytes) -> str:
    path = tmp_path / "bad.c3d"
    path.write_bytes(data)
    with pytest.raises(ConfigError) as err:
        read_positions(path)
    message = str(err.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    return message


def _patched(data: bytes, offset: int, fmt: str, value: int) -> bytes:
    out = bytearray(data)
    struct.pack_into(fmt, out, offset, value)
    return bytes(out)


def test_the_file_written_reads_whole(tmp_path, whole):
    path = tmp_path / "ok.c3d"
    path.write_bytes(whole)
    got = read_positions(path)
    assert got.positions.shape == (FRAMES, len(NAMES), 3) and got.fps == 30.0


@pytest.mark.parametrize("processor", [0, 83, 87, 255])
def test_a_processor_byte_the_format_does_not_have(tmp_path, whole, processor):
    parameters = (whole[0] - 1) * 512
    message = _read(tmp_path, _patched(whole, parameters + 3, "B", processor))
    assert f"processor type {processor} in the parameter section; expected 84 (Intel), 85 (DEC) or 86 (MIPS)" in message


def test_zero_parameter_blocks(tmp_path, whole):
    parameters = (whole[0] - 1) * 512
    assert "a parameter section of 0 blocks" in _read(tmp_path, _patched(whole, parameters + 2, "B", 0))


@pytest.mark.parametrize("block", [0, 1])
def test_a_parameter_section_inside_the_header(tmp_path, whole, block):
    message = _read(tmp_path, _patched(whole, 0, "B", block))
    assert f"the header puts the parameter section at block {block}" in message


@pytest.mark.parametrize("start", [0, 1, 3])
def test_a_data_start_inside_the_parameters(tmp_path, whole, start):
    message = _read(tmp_path, _patched(whole, 16, "<H", start))  # header word 9
    assert f"the data starts at block {start}, inside the header or parameter section" in message


def test_a_header_claiming_more_frames_than_the_file_holds(tmp_path, whole):
    message = _read(tmp_path, _patched(whole, 8, "<H", 65535))  # header word 5: the last frame
    assert "truncated: 65,535 frames declared (frames 1 to 65535)" in message


def test_not_a_c3d_file(tmp_path, whole):
    assert "not a C3D file: its second byte is 0" in _read(tmp_path, _patched(whole, 1, "B", 0))


@settings(max_examples=40)
@given(st.floats(0.0, 1.0, exclude_max=True))
def test_a_truncated_file_is_an_error_naming_it_never_a_shorter_recording(tmp_path_factory, whole, share):
    """Cut anywhere before its last frame's last byte, the file is an error: "truncated", naming the file."""
    first = (whole[0] - 1) * 512
    start = (struct.unpack_from("<H", whole, 16)[0] - 1) * 512
    end = start + FRAMES * len(NAMES) * 4 * 4
    cut = int(share * end)
    message = _read(tmp_path_factory.mktemp("cut"), whole[:cut])
    assert "truncated" in message or (cut > first and "not a readable C3D file" in message), (cut, message)


# -- special and unreadable files: one line for every format -----------------------------------------------------------


def _likeme(args, cwd) -> tuple[int, str]:
    from likeme.cli import main

    err = io.StringIO()
    here = os.getcwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            status = main([str(a) for a in args])
    finally:
        os.chdir(here)
    return status, err.getvalue()


@pytest.mark.parametrize("suffix", [".csv", ".c3d", ".bvh", ".toml", ".npy"])
@pytest.mark.parametrize("kind", ["directory", "fifo", "dangling link", "link loop", "link to an unreadable file"])
def test_special_and_unreadable_files_are_one_line(tmp_path, monkeypatch, suffix, kind):
    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")
    path = tmp_path / f"x{suffix}"
    if kind == "directory":
        path.mkdir()
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "dangling link":
        path.symlink_to(tmp_path / "nowhere")
    elif kind == "link loop":
        path.symlink_to(tmp_path / f"y{suffix}")
        (tmp_path / f"y{suffix}").symlink_to(path)
    else:
        if not Path("/proc/self/mem").exists():
            pytest.skip("needs /proc/self/mem (a regular file whose read fails)")
        path.symlink_to("/proc/self/mem")
    status, err = _likeme(["validate", path], tmp_path)
    assert status == 1 and err.count("\n") == 1 and err.startswith(f"likeme: error: {path}"), err
