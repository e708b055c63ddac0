"""Hostile inputs give documented errors only, and the ``likeme bench fuzz`` instrument can tell when they do not.

- hypothesis mutates real-looking BVH headers (rotation channels, End Sites) and CSV joint-position files; reading
  them either works (and gives consistent arrays) or raises a :class:`~toolkit.errors.LikemeError`;
- the fuzz harness classifies a planted traceback, hang, memory blow-up and documented error as such, restarts its
  worker after a hang, and makes every case again from its number alone.
"""

from __future__ import annotations

import math
import re
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from plugins.bench import fuzz, fuzz_worker
from plugins.bench.fuzz_mutate import GENERIC, HOSTILE_NUMBERS, MUTATIONS, mutate
from toolkit.errors import ConfigError, LikemeError

ROOT = Path(__file__).resolve().parents[3]

HAND = fuzz._hand_bvh()
BANDAI = fuzz._bandai_bvh(np.random.default_rng(0))
_HEADER_END = re.compile(r"^Frame Time:[^\n]*\n", re.M)


def _read_bvh_checked(data: bytes) -> None:
    """Read a BVH file from bytes; when it reads, its arrays must agree with its hierarchy."""
    from toolkit.recordings.bvh import read_bvh
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder, "m.bvh")
        path.write_bytes(data)
        try:
            bvh = read_bvh(path)
        except LikemeError as err:
            assert str(err).strip() and "\n" not in str(err).strip()
            return
        assert math.isfinite(bvh.fps) and bvh.fps > 0
        assert bvh.values.shape == (bvh.n_frames, bvh.n_channels)
        positions, rotations = bvh.forward_kinematics()
        assert positions.shape == (bvh.n_frames, len(bvh.joints), 3)


TOKENS = st.sampled_from(["{", "}", "ROOT", "JOINT", "End", "Site", "OFFSET", "CHANNELS", "MOTION", "Frames:",
                          "Frame Time:", "Xrotation", "Wrotation", "Yposition", "hips", "HIERARCHY", "3", "6", "\n"]) \
    | st.sampled_from(HOSTILE_NUMBERS) | st.text(max_size=3)
EDITS = st.lists(st.tuples(st.sampled_from(["delete", "insert", "replace", "duplicate", "count"]), st.integers(0, 10 ** 6),
                           TOKENS | st.sampled_from(HOSTILE_NUMBERS)), min_size=1, max_size=4)
"""Token edits: delete, insert, replace or duplicate any token of the header; 'count': replace the number a parser
sizes something from (``CHANNELS n``, ``Frames: n``, ``Frame Time: t``)."""
_COUNTS = re.compile(r"(CHANNELS|Frames:|Frame Time:)(\s+)(\S+)")


def _edit_header(text: str, edits: list[tuple[str, int, str]]) -> str:
    """Apply token edits to the header of a BVH file (everything up to the ``Frame Time`` line), not its frames."""
    end = _HEADER_END.search(text).end()
    tokens = re.findall(r"\S+|\s+", text[:end])
    for op, at, token in edits:
        if op == "count":
            header = "".join(tokens)
            counts = list(_COUNTS.finditer(header))
            m = counts[at % len(counts)] if counts else None
            if m is not None and token.strip():
                tokens = re.findall(r"\S+|\s+", header[: m.start(3)] + token + header[m.end(3):])
            continue
        words = [i for i, t in enumerate(tokens) if not t.isspace()] or [0]
        i = words[at % len(words)]
        if op == "delete" and tokens:
            del tokens[i]
        elif op == "insert":
            tokens[i:i] = [token, " "]
        elif op == "replace" and tokens:
            tokens[i] = token
        elif tokens:
            tokens[i:i] = [tokens[i], " "]
    return "".join(tokens) + text[end:]


@settings(max_examples=150, deadline=None, derandomize=True)
@given(edits=EDITS, seed=st.sampled_from(["hand", "bandai"]))
def test_mutated_bvh_headers_give_documented_errors_only(edits, seed):
    text = _edit_header(HAND if seed == "hand" else BANDAI, edits)
    _read_bvh_checked(text.encode("utf-8", "surrogatepass"))


@settings(max_examples=150, deadline=None, derandomize=True)
@given(case=st.integers(0, 2 ** 32 - 1), seed=st.sampled_from(["hand", "bandai"]))
def test_structurally_mutated_bvh_files_give_documented_errors_only(case, seed):
    data, _ = mutate((HAND if seed == "hand" else BANDAI).encode(), "bvh", np.random.default_rng(case))
    _read_bvh_checked(data)


def test_unmutated_seeds_read():
    """The seeds are good files: whatever fails is the mutation's doing."""
    from toolkit.recordings.bvh import parse_bvh
    for text, joints in ((HAND, 6), (BANDAI, 23)):
        bvh = parse_bvh(text)
        assert len(bvh.joints) == joints and bvh.n_frames > 1 and any(j.end_site for j in bvh.joints)
        assert any("rotation" in c for j in bvh.joints for c in j.channels)


# -- CSV joint positions (toolkit.recordings.positions) -------------------------------------------------------------


def _csv_seed(with_time: bool) -> str:
    rng = np.random.default_rng(3)
    return fuzz._positions_csv(["root", "head", "left_hand", "right_hand"], rng.normal(size=(8, 4, 3)), 30.0, with_time)


def _read_positions_checked(data: bytes) -> None:
    from toolkit.recordings import positions
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder, "p.csv")
        path.write_bytes(data)
        try:
            read = positions.read_positions(path, fps=30.0)
        except LikemeError as err:
            assert str(err).strip()
            return
        arr = np.asarray(read.positions)
        assert arr.ndim == 3 and arr.shape[1:] == (len(read.names), 3)
        assert math.isfinite(read.fps) and read.fps > 0


@settings(max_examples=100, deadline=None, derandomize=True)
@given(case=st.integers(0, 2 ** 32 - 1), with_time=st.booleans())
def test_mutated_position_csv_files_give_documented_errors_only(case, with_time):
    data, _ = mutate(_csv_seed(with_time).encode(), "csv", np.random.default_rng(case))
    _read_positions_checked(data)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(header=st.lists(st.sampled_from(["time", "root_x", "root_y", "root_z", "head_x", "head_y", "head_z", "head_w",
                                        "", "x", "root_x_x", "\ufefftime"]), max_size=9),
       cell=st.sampled_from(HOSTILE_NUMBERS), rows=st.integers(0, 4))
def test_position_csv_headers_give_documented_errors_only(header, cell, rows):
    lines = [",".join(header)] + [",".join([cell] * len(header))] * rows
    _read_positions_checked(("\n".join(lines) + "\n").encode())


# -- the mutations ---------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("fmt,seed", [("bvh", HAND), ("toml", (ROOT / "characters" / "morris.toml").read_text()),
                                      ("json", '{\n "a": [\n  1,\n  {"b": "c"}\n ],\n "d": 4.5\n}\n'), ("csv", _csv_seed(True))])
def test_every_mutation_changes_its_input_and_is_deterministic(fmt, seed):
    data = seed.encode()
    for name, mutation in {**GENERIC, **MUTATIONS[fmt]}.items():
        outputs = [mutation(data, np.random.default_rng(k)) for k in range(12)]
        assert any(o != data for o in outputs), f"{name} never changes a {fmt} file"
        assert outputs == [mutation(data, np.random.default_rng(k)) for k in range(12)], f"{name} is not deterministic"
    assert mutate(data, fmt, np.random.default_rng(7)) == mutate(data, fmt, np.random.default_rng(7))


# -- the instrument: planted failures --------------------------------------------------------------------------------


def plant_traceback(path, fps):
    return {}["not there"]


def plant_hang(path, fps):
    time.sleep(600)


def plant_documented(path, fps):
    raise ConfigError("planted", file=path, expected="nothing")


def plant_memory(path, fps):
    return np.ones(2 ** 34, dtype=np.uint8) + 1  # 16 GiB, over the worker's limit


def plant_ok(path, fps):
    return None


@pytest.fixture(scope="module")
def worker():
    w = fuzz_worker.Worker(memory_mb=1024)
    w.start()
    yield w
    w.close()


def _call(worker, name, timeout=20.0):
    with tempfile.TemporaryDirectory() as folder:
        return worker.run({"cwd": folder, "input": "x", "call": f"tests.plugins.bench.test_fuzz:{name}", "argv": None}, timeout)


def test_the_harness_classifies_planted_outcomes(worker):
    answer = _call(worker, "plant_traceback")
    assert fuzz_worker.classify(answer) == "traceback"
    assert answer["exception"] == "KeyError" and answer["where"].startswith("tests/plugins/bench/test_fuzz.py:")
    assert fuzz_worker.classify(_call(worker, "plant_documented")) == "documented"
    assert fuzz_worker.classify(_call(worker, "plant_ok")) == "ok"
    assert fuzz_worker.classify(_call(worker, "plant_memory")) == "memory"
    assert fuzz_worker.classify(_call(worker, "plant_ok")) == "ok"  # a fresh worker after a MemoryError, this module imported
    restarts = worker.restarts
    started = time.monotonic()
    hang = _call(worker, "plant_hang", timeout=2.0)
    assert fuzz_worker.classify(hang) == "hang" and hang["where"].startswith("tests/plugins/bench/test_fuzz.py:")  # located by a stack dump
    assert time.monotonic() - started < 15 and worker.restarts == restarts + 1
    assert fuzz_worker.classify(_call(worker, "plant_documented")) == "documented"  # a fresh worker after the hang


def test_the_harness_runs_cli_commands(worker):
    """Exit 0 is ok; an error line with status 1 (argparse's too) is documented; more than one line is not."""
    max_toml = str(ROOT / "characters" / "max.toml")
    with tempfile.TemporaryDirectory() as folder:
        run = lambda argv: worker.run({"cwd": folder, "input": "", "call": None, "argv": argv}, 60.0)  # noqa: E731
        assert fuzz_worker.classify(run(["validate", max_toml])) == "ok"
        assert fuzz_worker.classify(run(["validate", "gone.bvh"])) == "documented"
        assert fuzz_worker.classify(run(["validate"])) == "documented"  # argparse: one line, status 1
        two = run(["validate", "gone.bvh", "gone.toml"])
        assert two["rc"] == 1 and fuzz_worker.classify(two) == "traceback"  # two error lines are not one documented error


@pytest.fixture(scope="module")
def seeds():
    from toolkit import create_plugin_manager

    with tempfile.TemporaryDirectory() as folder:
        yield fuzz.make_seeds(Path(folder), create_plugin_manager(), seed=0)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(index=st.integers(0, 10 ** 6), seed=st.integers(0, 10 ** 6), target=st.sampled_from(fuzz.TARGETS))
def test_a_case_is_made_again_from_its_number(seeds, index, seed, target):
    a, b = fuzz.make_case(index, target, seeds, seed), fuzz.make_case(index, target, seeds, seed)
    assert (a.data, a.argv, a.call, a.mutations) == (b.data, b.argv, b.call, b.mutations)
    assert a.mutations and a.name.startswith(f"case{index:05d}")


def test_seeds_are_good_inputs(seeds):
    """Every seed, unmutated, passes the command the fuzzer runs it through (so a failure is the mutation's)."""
    from plugins.bench.fuzz import _command  # noqa: PLC2701

    for target in ("bvh", "toml", "profile", "scenario", "state", "npy", "c3d"):
        for seed in seeds[target]:
            argv = [a.replace("{input}", str(seed["path"])) for a in _command(target, seed, np.random.default_rng(0))]
            answer = fuzz_worker.run_one({"cwd": str(Path(seed["path"]).parent), "argv": argv})
            assert fuzz_worker.classify(answer) == "ok", (argv, answer["stderr"])


def test_bench_fuzz_reports_and_fails_on_findings(tmp_path, capsys):
    """A short run through ``likeme bench fuzz``: the table, the closing line, status 1 exactly when something failed,
    and the failing inputs with their stderr in --out."""
    from likeme.cli import main

    status = main(["bench", "fuzz", "--n", "12", "--targets", "state,bvh", "--seed", "3", "--timeout", "20",
                   "--out", str(tmp_path / "cases"), "--quiet"])
    tmp_path = tmp_path / "cases"  # created by the command
    out = capsys.readouterr().out
    closing = out.strip().splitlines()[-1]
    m = re.fullmatch(r"fuzz: 12 inputs, (\d+) tracebacks, (\d+) hangs, (\d+) over memory", closing)
    assert m, closing
    bad = sum(map(int, m.groups()))
    assert status == (1 if bad else 0)
    assert len(list(tmp_path.glob("case*.stderr"))) == bad
    for kept in tmp_path.glob("case*.stderr"):
        assert "# replay (in this folder): likeme " in kept.read_text()
    assert "state" in out and "bvh" in out


def test_bench_fuzz_refuses_an_out_that_is_a_file(tmp_path, capsys):
    from likeme.cli import main

    (tmp_path / "f").write_text("x")
    assert main(["bench", "fuzz", "--n", "1", "--out", str(tmp_path / "f")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "key --out: not a folder" in err[0]


def test_bench_fuzz_refuses_unknown_targets(capsys):
    from likeme.cli import main

    assert main(["bench", "fuzz", "--targets", "bvh,yaml"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown fuzz target(s) ['yaml']" in err[0] and "available: bvh, toml" in err[0]


def test_the_new_shapes_are_made(seeds):
    """Issue 38's shapes: .npy headers and archives, C3D header fields and cuts, special files, hostile bench option
    values, writes on a full disk, hostile strings in state files."""
    from plugins.bench.fuzz_mutate import mutation_names

    assert {"npy_header", "npy_archive"} <= set(mutation_names("npy"))
    assert {"c3d_header", "c3d_cut"} <= set(mutation_names("c3d"))
    cases = [fuzz.make_case(i, t, seeds, 5) for t in ("special", "bench", "output") for i in range(60)]
    specials = {c.special for c in cases if c.target == "special"}
    assert specials == set(fuzz.SPECIAL_FILES)
    assert any(c.full for c in cases if c.target == "output") and not all(c.full for c in cases if c.target == "output")
    places = {c.mutations[0] for c in cases if c.target == "output"}
    assert places == {"full disk", "read-only folder", "disk with room"}
    assert not any(c.full and c.read_only for c in cases) and not any(c.read_only for c in cases if c.target != "output")
    options = {c.argv[-2] for c in cases if c.target == "bench"}
    assert {"--frames", "--noise", "--nodes", "--minutes", "--episodes"} <= options


@pytest.mark.parametrize("target", ["special", "bench", "output", "npy", "c3d"])
def test_the_new_targets_find_nothing(tmp_path, target):
    """A few cases of each new target through the harness: every one is ok or a documented one-line error."""
    from toolkit import create_plugin_manager

    results = fuzz.run_fuzz(create_plugin_manager(), n=6, seed=3, targets=(target,), timeout=60.0, memory_mb=1024)
    assert [r.outcome for r in results if r.outcome not in ("ok", "documented")] == [], \
        [(r.case.command(), r.answer.get("stderr", "")[-500:]) for r in results]


def test_a_read_only_folder_refuses_root_as_every_user(tmp_path):
    """``permission_bits_hold``: a folder of mode 0o555 refuses a file to this process inside (root's capabilities
    to pass permission bits lowered there), and root, if it is root, writes there again once out."""
    import os

    folder = tmp_path / "out"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        with fuzz_worker.permission_bits_hold(folder) as held:
            assert held == "held"
            with pytest.raises(PermissionError):
                (folder / "x").write_text("x")
            assert (tmp_path / "elsewhere").write_text("y") == 1  # only the mode stops it: the rest is writable
        if os.geteuid() == 0:
            (folder / "x").write_text("x")  # root's capabilities are back
            (folder / "x").unlink()
    finally:
        folder.chmod(0o755)


def test_read_only_cases_are_one_line_naming_the_folder():
    """Output cases in a read-only folder (as root too): every command that writes is refused in one documented
    line naming what it could not write and why (one case of each command); none ran as if it had written."""
    from toolkit import create_plugin_manager

    pm = create_plugin_manager()
    with tempfile.TemporaryDirectory() as tmp:
        seeds = fuzz.make_seeds(Path(tmp) / "seeds", pm, seed=21)
        chosen = [i for i in range(400) if fuzz.make_case(i, "output", seeds, 21).read_only]
        commands = {}
        for i in chosen:  # one case of each command
            commands.setdefault(" ".join(fuzz.make_case(i, "output", seeds, 21).argv), i)
        results = fuzz._run_cases(sorted(commands.values()), ("output",), seeds, 21, timeout=120.0, memory_mb=1024,
                                  tmp=Path(tmp))
    assert len(results) == len(fuzz.OUTPUTS)
    for r in results:
        lines = [x for x in r.answer["stderr"].splitlines() if x.startswith("likeme: error: ")]
        assert r.outcome == "documented" and r.answer["read_only"] == "held", (r.case.command(), r.answer)
        assert len(lines) == 1 and "Permission denied" in lines[0], (r.case.command(), lines)
