"""State files under attack (issue 21): bad --save targets fail before the run, concurrent writers lose nothing,
a full disk loses nothing silently, and corrupted files are refused with a ConfigError, leaving the character as it
was."""

from __future__ import annotations

import contextlib
import copy
import errno
import io
import json
import multiprocessing
import os
import stat
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from tests.conftest import CHARACTERS, ROOT
from toolkit import ConfigError, create_plugin_manager, load_character, load_scenario
from toolkit.state import (
    MAX_DEPTH,
    Checkpoint,
    StateFile,
    character_state,
    check_save_target,
    checksum,
    load_state,
    read_state,
    save_state,
    state_text,
    write_atomic,
)

ENV = {**os.environ, "LIKEME_DISABLE_PLUGIN_AUTOLOAD": "1"}


def likeme(args, monkeypatch=None):
    """Run the likeme command in-process; (exit status, stderr)."""
    from likeme.cli import main

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        status = main([str(a) for a in args])
    return status, err.getvalue()


@pytest.fixture
def no_run(monkeypatch):
    """Fail the test if a scenario is composed or run: the check must come first."""
    import toolkit.scenario

    def refuse(*args, **kwargs):
        raise AssertionError("the scenario was loaded before the --save target was checked")

    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")
    monkeypatch.setattr(toolkit.scenario, "load_scenario", refuse)


# -- the --save target, before any work -----------------------------------------------------------------


@pytest.mark.parametrize("make, target, message", [
    (lambda d: None, "missing/s.json", "the folder {d}/missing does not exist"),
    (lambda d: (d / "f.txt").write_text("x"), "f.txt/s.json", "{d}/f.txt is a file, not a folder"),
    (lambda d: (d / "sub").mkdir(), "sub", "{d}/sub: is a folder, not a file"),
    (lambda d: (d / "notes.txt").write_text("my notes\n"), "notes.txt",
     "exists and is not a likeme state file; refusing"),
    (lambda d: ((d / "ro.json").write_text('{"format": "likeme-state"}'), (d / "ro.json").chmod(0o444)), "ro.json",
     "{d}/ro.json: the file is read-only"),
])
def test_a_bad_save_target_fails_before_the_scenario_runs(tmp_path, no_run, make, target, message):
    make(tmp_path)
    status, err = likeme(["run", "learn_windmill", "--save", tmp_path / target])
    assert status == 1
    assert err.startswith("likeme: error: ") and message.format(d=tmp_path) in err, err
    assert err.count("\n") == 1  # one line, no traceback
    if target == "notes.txt":
        assert (tmp_path / "notes.txt").read_text() == "my notes\n"
    assert not list(tmp_path.glob("**/.*.tmp"))


def _check_as_nobody(path, queue):
    os.setgid(65534)
    os.setuid(65534)
    try:
        check_save_target(path)
        queue.put("ok")
    except ConfigError as err:
        queue.put(str(err))


def test_a_read_only_folder_fails_before_the_scenario_runs(tmp_path, no_run):
    folder = Path(tempfile.mkdtemp(prefix="likeme-ro-"))  # under /tmp, which every user may reach
    try:
        folder.chmod(0o555)
        target = folder / "s.json"
        if os.geteuid() == 0:  # root writes anywhere: check as an ordinary user, in a child process
            queue = multiprocessing.get_context("fork").Queue()
            child = multiprocessing.get_context("fork").Process(target=_check_as_nobody, args=(target, queue))
            child.start()
            child.join()
            message = queue.get(timeout=10)
        else:
            status, message = likeme(["run", "learn_windmill", "--save", target])
            assert status == 1
        assert f"{target}: cannot write in the folder {folder}: Permission denied" in message, message
        assert list(folder.iterdir()) == []
    finally:
        folder.chmod(0o755)
        folder.rmdir()


def test_a_good_target_passes_and_leaves_nothing_behind(tmp_path):
    assert check_save_target(tmp_path / "s.json") == tmp_path / "s.json"
    assert list(tmp_path.iterdir()) == []


# -- modes and temporary files ----------------------------------------------------------------------------


def test_a_new_file_gets_the_umask_default_and_an_old_one_keeps_its_mode(tmp_path):
    old = os.umask(0o022)
    try:
        write_atomic(tmp_path / "new.json", "{}\n")
        assert stat.S_IMODE((tmp_path / "new.json").stat().st_mode) == 0o644
        (tmp_path / "kept.json").write_text("old\n")
        (tmp_path / "kept.json").chmod(0o640)
        write_atomic(tmp_path / "kept.json", "new\n")
        assert stat.S_IMODE((tmp_path / "kept.json").stat().st_mode) == 0o640
        assert (tmp_path / "kept.json").read_text() == "new\n"
    finally:
        os.umask(old)


# -- a full disk -----------------------------------------------------------------------------------------


@pytest.fixture
def full_disk(monkeypatch):
    """Writing a file fails with ENOSPC while ``full[0]`` is true (directories still sync)."""
    full = [True]
    real = os.fsync

    def fsync(fd):
        if full[0] and stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    return full


def windmill():
    pm = create_plugin_manager(autoload=False)
    return pm, load_scenario(CHARACTERS / "scenarios" / "learn_windmill.toml", pm)


def test_a_full_disk_during_the_run_is_reported_and_the_state_saved_when_there_is_room(tmp_path, full_disk):
    pm, scenario = windmill()
    reports = []
    path = tmp_path / "s.json"
    checkpoint = Checkpoint(scenario.world, path, every=0, report=reports.append)
    pm.register(checkpoint)
    world = scenario.world
    while not checkpoint.dirty:
        world.step()
    world.step()  # the save after learning fails
    assert checkpoint.error == f"{path}: could not save state: No space left on device"
    assert checkpoint.dirty and not path.exists()
    for _ in range(40):
        world.step()
    assert len(reports) == 1 and "kept and saved again at the next checkpoint" in reports[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == [".s.json.lock"]  # no temporary file left behind
    full_disk[0] = False
    for _ in range(int(world.fps) + 1):  # retried after a second of world time
        world.step()
    assert checkpoint.error is None and not checkpoint.dirty
    assert "learned-1" in read_state(path)["actors"]["max"]["components"]["motor"]["state"]["learned"]
    assert reports[-1] == f"{path}: saved after all"


def test_a_full_disk_at_the_end_exits_1_naming_the_file_and_the_reason(tmp_path, full_disk, monkeypatch):
    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "nowhere"))  # the fallback fails too
    status, err = likeme(["run", "learn_windmill", "--save", tmp_path / "s.json"])
    assert status == 1
    last = err.strip().splitlines()[-1]
    assert last == (f"likeme: error: {tmp_path}/s.json: could not save state: No space left on device; what this run "
                    f"learned could not be saved anywhere; expected a folder with space this user can write"), err
    assert "plugin 'checkpoint'" not in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == [".s.json.lock"]


def test_a_failed_final_save_goes_to_the_temporary_folder_if_it_can(tmp_path, monkeypatch):
    _, scenario = windmill()
    world = scenario.run()
    spare = tmp_path / "spare"
    spare.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(spare))
    checkpoint = Checkpoint(world, tmp_path / "s.json", report=lambda m: None)
    (tmp_path / "s.json").mkdir()  # made a folder after the check: the save fails
    with pytest.raises(ConfigError, match=r"s.json: could not save state: .*what this run learned is saved in "):
        checkpoint.finish()
    (saved,) = spare.iterdir()
    assert "learned-1" in read_state(saved)["actors"]["max"]["components"]["motor"]["state"]["learned"]


# -- concurrent writers --------------------------------------------------------------------------------------


def test_a_writer_that_finds_the_file_changed_saves_beside_it(tmp_path):
    path = tmp_path / "s.json"
    first, second = StateFile(path, report=lambda m: None), StateFile(path, report=print)
    assert first.save('{"format": "likeme-state", "n": 1}\n') == path
    where = second.save('{"format": "likeme-state", "n": 2}\n')
    assert where == tmp_path / f"s.conflict-{os.getpid()}.json" == second.diverted
    assert json.loads(path.read_text())["n"] == 1 and json.loads(where.read_text())["n"] == 2
    assert first.save('{"format": "likeme-state", "n": 3}\n') == path  # the first writer's own version: overwritten
    assert second.save('{"format": "likeme-state", "n": 4}\n') == where  # the second keeps to its own file
    assert json.loads(path.read_text())["n"] == 3 and json.loads(where.read_text())["n"] == 4
    assert "another process wrote" in str(second.conflict_error()) and str(where) in str(second.conflict_error())


def component(data, key):
    """Max's state of component ``key`` in state-file data."""
    return data["actors"]["max"]["components"][key]["state"]


def waiting_for_lock(pids):
    """The processes among ``pids`` blocked on an flock (Linux's /proc/locks lists waiters as ``-> FLOCK``)."""
    found = set()
    for line in Path("/proc/locks").read_text().splitlines():
        fields = line.split()
        if "->" in fields and fields[fields.index("->") + 1] == "FLOCK":
            found |= {int(f) for f in fields if f.isdigit()} & set(pids)
    return found


@pytest.mark.skipif(not Path("/proc/locks").exists(), reason="needs Linux's /proc/locks to see who waits for a lock")
def test_two_runs_saving_to_one_file_lose_nothing(tmp_path):
    """Two processes learn different things (a movement; a belief about ice cream) and save to one file at once.

    The test holds the file's lock until both runs wait for it, so both have started (and checked the target)
    before either saves: the second writer must find the file changed and save beside it."""
    import fcntl

    path = tmp_path / "s.json"
    lock = os.open(tmp_path / ".s.json.lock", os.O_RDWR | os.O_CREAT)
    fcntl.flock(lock, fcntl.LOCK_EX)
    try:
        runs = {name: subprocess.Popen([sys.executable, "-m", "likeme", "run", name, "--save", path],
                                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=ENV, cwd=ROOT)
                for name in ("learn_windmill", "ice_cream")}
        pids = {proc.pid for proc in runs.values()}
        for _ in range(6000):  # at most 10 minutes
            if waiting_for_lock(pids) == pids:
                break
            assert all(proc.poll() is None for proc in runs.values()), "a run ended without trying to save"
            time.sleep(0.1)
    finally:
        os.close(lock)
    learned = {
        "learn_windmill": lambda d: "learned-1" in component(d, "motor").get("learned", {}),
        "ice_cream": lambda d: component(d, "action")["beliefs"].get("ice_cream") == "food",
    }
    beside = []
    for name, proc in runs.items():
        err = proc.communicate(timeout=600)[1]
        conflict = tmp_path / f"s.conflict-{proc.pid}.json"
        if conflict.exists():  # its learning went beside the file, and it said so
            assert proc.returncode == 1, err
            assert err.strip().endswith(f"what this run learned is saved in {conflict}; expected one run saving to a "
                                        f"state file at a time (merge by loading one and running again)"), err
            assert "another process wrote this state file" in err
            assert learned[name](read_state(conflict))
            beside.append(name)
        else:  # the other one: its learning is in the file
            assert proc.returncode == 0, err
            assert learned[name](read_state(path))
    assert len(beside) == 1
    assert not list(tmp_path.glob(".*.tmp"))


# -- loading: the character must be the one the state was saved from ------------------------------------------


def test_a_state_saved_from_moritz_does_not_load_into_max(tmp_path):
    pm = create_plugin_manager(autoload=False)
    world = load_scenario(CHARACTERS / "scenarios" / "imitation_games.toml", pm).run()
    path = tmp_path / "moritz.json"
    save_state(world.actors["moritz"].character, path)
    max_ = load_character(CHARACTERS / "max_learner.toml", pm)
    before = character_state(max_)
    with pytest.raises(ConfigError, match=r"moritz.json: key actors: no state of Max in the file; expected the state "
                                          r"of one character named Max; available: moritz \(Moritz\)"):
        load_state(max_, path)
    assert character_state(max_) == before


def test_a_file_without_a_checksum_is_read_as_version_1_only(tmp_path):
    _, scenario = windmill()
    world = scenario.run()
    data = json.loads(Path(_save(world, tmp_path / "s.json")).read_text())
    del data["checksum"]
    (tmp_path / "v2.json").write_text(json.dumps(data))
    with pytest.raises(ConfigError, match=r"v2.json: key checksum: missing checksum"):
        read_state(tmp_path / "v2.json")
    data["version"] = 1  # written before the checksum: read, with every other check
    (tmp_path / "v1.json").write_text(json.dumps(data))
    fresh = windmill()[1].world
    load_state(fresh, tmp_path / "v1.json")
    assert character_state(fresh.actors["max"].character) == character_state(world.actors["max"].character)


def _save(world, path):
    save_state(world, path)
    return path


# -- loading corrupted files: only ConfigError, and nothing changed ---------------------------------------------


@pytest.fixture(scope="module")
def real_states(tmp_path_factory):
    """State files written by scenarios that learn: (scenario, file text)."""
    folder = tmp_path_factory.mktemp("real")
    out = []
    for name in ("learn_windmill", "imitation_games", "hand_arm_games"):  # a posegraph; wrist and hand command graphs
        pm = create_plugin_manager(autoload=False)
        world = load_scenario(CHARACTERS / "scenarios" / f"{name}.toml", pm).run()
        out.append((name, _save(world, folder / f"{name}.json").read_text()))
    return out


class Worlds:
    """Fresh worlds by scenario, made again only after a load changed one."""

    def __init__(self):
        self.worlds = {}

    def get(self, name):
        if name not in self.worlds:
            pm = create_plugin_manager(autoload=False)
            self.worlds[name] = load_scenario(CHARACTERS / "scenarios" / f"{name}.toml", pm).world
        return self.worlds[name]

    def spoilt(self, name):
        self.worlds.pop(name, None)


WORLDS = Worlds()


def paths(value, prefix=()):
    """Every key path inside parsed JSON."""
    yield prefix
    if isinstance(value, dict):
        for k, v in value.items():
            yield from paths(v, (*prefix, k))
    elif isinstance(value, list):
        for i, v in enumerate(value[:3]):
            yield from paths(v, (*prefix, i))


def deep(n):
    value = 1
    for _ in range(n):
        value = [value]
    return value


HOSTILE = st.one_of(
    st.sampled_from([[], {}, "abc", "\ud800", "learned-\udfff", {"x\udbff": 1}, 5, -1, 0, None, True, 1.5,
                     ["reach", "eat"], [["x"]], {"a": 1},
                     10**30, -(10**40), 2**53 + 1, 1e300, deep(MAX_DEPTH + 5), deep(40), "", "hub", [[1, 2]],
                     [1, 2, 3]]),
    st.recursive(st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False, allow_infinity=False)
                 | st.text(max_size=5),
                 lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=3), inner, max_size=3),
                 max_leaves=8),
)


@st.composite
def corruptions(draw, texts):
    """A real state file corrupted one way: a value replaced, a key deleted or renamed (signed again, so that the
    checks behind the checksum are reached, or not), the text truncated, bytes flipped, a number edited."""
    name, text = draw(st.sampled_from(texts))
    how = draw(st.sampled_from(["replace", "replace", "replace", "delete", "rename", "truncate", "flip", "number"]))
    if how in ("replace", "delete", "rename"):
        data = json.loads(text)
        where = draw(st.sampled_from([p for p in paths(data) if p]))
        parent = data
        for k in where[:-1]:
            parent = parent[k]
        last = where[-1]
        if how == "replace":
            parent[last] = draw(HOSTILE)
        elif how == "delete":
            parent.pop(last)
        elif isinstance(parent, dict):
            parent[draw(st.sampled_from(["x", "learned-1", "hub", "left_wrist", "beliefs", "", "\ud800"]))] = \
                parent.pop(last)
        if draw(st.booleans()):
            with contextlib.suppress(ValueError, RecursionError):
                data["checksum"] = checksum(data)
        with contextlib.suppress(ValueError, RecursionError):  # a hostile value json cannot write: leave it out
            return name, json.dumps(data).encode()
        return name, text.encode()
    raw = text.encode()
    if how == "truncate":
        return name, raw[: draw(st.integers(0, len(raw) - 1))]
    if how == "flip":
        raw = bytearray(raw)
        for _ in range(draw(st.integers(1, 4))):
            i = draw(st.integers(0, len(raw) - 1))
            raw[i] ^= 1 << draw(st.integers(0, 7))
        return name, bytes(raw)
    digits = [i for i, c in enumerate(text) if c.isdigit()]
    i = draw(st.sampled_from(digits))
    return name, (text[:i] + str((int(text[i]) + 1) % 10) + text[i + 1:]).encode()  # valid JSON, wrong content


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                  HealthCheck.too_slow, HealthCheck.data_too_large])
@given(data=st.data())
def test_corrupted_state_files_raise_only_config_error_and_change_nothing(real_states, tmp_path_factory, data):
    name, raw = data.draw(corruptions(real_states))
    path = tmp_path_factory.mktemp("bad") / "s.json"
    path.write_bytes(raw)
    world = WORLDS.get(name)
    before = {a: character_state(actor.character) for a, actor in world.actors.items()}
    try:  # into the world (as --load does), or into Max alone
        load_state(world if data.draw(st.booleans()) else world.actors["max"].character, path)
    except ConfigError as err:
        event("refused: " + ("checksum" if "checksum does not match" in str(err) else "not JSON" if "JSON" in str(err)
                             else "by a component" if ".state" in str(err) else "by the schema"))
        assert str(err).startswith(str(path)), err
        assert {a: character_state(actor.character) for a, actor in world.actors.items()} == before
    else:  # a change that is still a valid state (a drive's level, say), signed again: it loaded
        event("loaded")
        WORLDS.spoilt(name)
        state_text(world)  # what loaded can be saved again, and the world runs with it
        for _ in range(3):
            world.step()


@pytest.mark.parametrize("edit, message", [
    (lambda d: d["actors"]["max"]["components"]["motor"]["state"].update(learned=[]), "key actors.max.components.motor.state.learned: invalid learned movements"),
    (lambda d: d["actors"]["max"]["components"]["action"]["state"]["transitions"].append(["reach", "eat", "abc"]), "invalid count 'abc'"),
    (lambda d: d["actors"]["max"]["components"]["action"]["state"]["transitions"].append([["reach"], "eat", 1]), "invalid transition [['reach'], 'eat', 1]"),
    (lambda d: d["actors"]["max"]["components"]["action"].update(state=5), "key actors.max.components.action.state: int instead of a table"),
    (lambda d: d["actors"]["max"]["components"]["action"]["state"].update(beliefs=deep(100)), f"nested more than {MAX_DEPTH} deep"),
    (lambda d: d["actors"]["max"]["components"]["action"]["state"]["drives"].update(play=10**40), "integer too large (41 digits)"),
    (lambda d: d.update(time="@1e999"), "key time: not a finite number: inf"),  # json reads 1e999 as inf
])
def test_the_corruptions_the_issue_lists_are_refused_and_change_nothing(real_states, tmp_path, edit, message):
    data = json.loads(dict(real_states)["learn_windmill"])
    edit(data)
    with contextlib.suppress(ValueError):
        data["checksum"] = checksum(data)
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data).replace('"@1e999"', "1e999"))
    world = windmill()[1].world
    before = copy.deepcopy({a: character_state(actor.character) for a, actor in world.actors.items()})
    with pytest.raises(ConfigError) as info:
        load_state(world, path)
    assert message in str(info.value)
    assert {a: character_state(actor.character) for a, actor in world.actors.items()} == before


def test_a_load_that_fails_in_a_later_component_changes_no_earlier_one(real_states, tmp_path):
    """The motor state is good, the action state is not: the posegraph must not have learned the movement."""
    data = json.loads(dict(real_states)["learn_windmill"])
    data["actors"]["max"]["components"]["action"]["state"]["drives"]["hunger"] = 7
    data["checksum"] = checksum(data)
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    world = windmill()[1].world
    with pytest.raises(ConfigError, match="drives.hunger: invalid level 7"):
        load_state(world, path)
    assert "learned-1" not in world.actors["max"].character.motor.movements()


@pytest.mark.parametrize("text, message", [
    ("[" * 5000 + "]" * 5000, "nested too deeply"),
    ('{"format": "likeme-state", "version": 2, "actors": {}, "x": ' + "9" * 5000 + "}", "not JSON likeme reads"),
    ('{"format": "likeme-state", "version": 2, "actors": {}, "time": NaN}', "NaN is not a finite"),
    ('{"format": "likeme-state", "version": 2, "actors": {}, "checksum": "sha256:00"}', "key checksum: checksum does not"),
])
def test_hostile_json_is_refused(tmp_path, text, message):
    path = tmp_path / "s.json"
    path.write_text(text)
    with pytest.raises(ConfigError, match=message):
        read_state(path)


def test_a_component_without_a_check_is_restored_from_its_snapshot(real_states, tmp_path):
    """Components whose set_state takes no ``check`` (third-party plugins written before it) are applied first, with a
    snapshot; when a later one fails, the earlier ones are restored from their snapshots."""
    from plugins.action.hierarchical import Hierarchical
    from plugins.motor.posegraph import Posegraph

    data = json.loads(dict(real_states)["learn_windmill"])
    data["actors"]["max"]["components"]["action"]["state"]["beliefs"] = {"pear": "toy"}
    data["actors"]["max"]["components"]["motor"]["state"]["learned"]["learned-1"]["poses"] = [[[0, 0]]]
    data["checksum"] = checksum(data)
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    world = windmill()[1].world
    max_ = world.actors["max"].character
    calls = []

    def action_set_state(state):  # an old-style set_state: no check keyword
        calls.append(dict(state))
        Hierarchical.set_state(max_.action, state)

    def motor_set_state(state):
        Posegraph.set_state(max_.motor, state)

    max_.action.set_state, max_.motor.set_state = action_set_state, motor_set_state
    before = character_state(max_)
    with pytest.raises(ConfigError, match=r"key actors.max.components.motor.state.learned.learned-1.poses: invalid"):
        load_state(world, path)
    assert calls[0]["beliefs"] == {"pear": "toy"} and len(calls) == 2  # applied, then restored
    assert character_state(max_) == before


def test_a_save_sweeps_away_what_a_killed_writer_left(tmp_path):
    stale = tmp_path / ".s.json.k1l2l3.tmp"
    stale.write_text('{"half": ')
    other = tmp_path / ".t.json.abc.tmp"  # another file's: not ours to remove
    other.write_text("x")
    StateFile(tmp_path / "s.json").save('{"format": "likeme-state"}\n')
    assert sorted(p.name for p in tmp_path.iterdir()) == [".s.json.lock", ".t.json.abc.tmp", "s.json"]


def test_a_component_that_returns_nan_is_named_when_saving(tmp_path):
    from toolkit import PluginError

    world = windmill()[1].world
    max_ = world.actors["max"].character
    max_.action.drives["hunger"].level = float("nan")
    with pytest.raises(PluginError, match=r"plugin 'hierarchical' failed in get_state: returned a number that is not"):
        save_state(world, tmp_path / "s.json")
    assert not (tmp_path / "s.json").exists()


# -- hostile names: lock files, links, long names, lone surrogates (issue 38) ------------------------------------


def test_a_lock_file_planted_as_a_symbolic_link_is_refused_before_the_run(tmp_path, no_run):
    victim = tmp_path / "elsewhere" / "victim"
    victim.parent.mkdir()
    (tmp_path / ".s.json.lock").symlink_to(victim)
    status, err = likeme(["run", "learn_windmill", "--save", tmp_path / "s.json"])
    assert status == 1 and err.count("\n") == 1, err
    assert f"its lock file {tmp_path}/.s.json.lock is a symbolic link, which a save does not follow" in err
    assert not victim.exists() and not (tmp_path / "s.json").exists()


def test_a_lock_file_planted_during_the_run_is_not_followed(tmp_path):
    """A link put in place of the lock after the check: the save fails (reported, kept in memory), and nothing is
    created or opened where the link points."""
    target = StateFile(tmp_path / "s.json")
    victim = tmp_path / "victim"
    (tmp_path / ".s.json.lock").symlink_to(victim)
    with pytest.raises(OSError, match=r"the lock file .*/\.s\.json\.lock is a symbolic link; not following it"):
        target.save('{"format": "likeme-state"}\n')
    assert not victim.exists() and not (tmp_path / "s.json").exists()
    existing = tmp_path / "existing"
    existing.write_text("precious\n")
    (tmp_path / ".s.json.lock").unlink()
    (tmp_path / ".s.json.lock").symlink_to(existing)
    with pytest.raises(OSError, match="symbolic link"):
        target.save('{"format": "likeme-state"}\n')
    assert existing.read_text() == "precious\n"


def test_the_lock_and_temporary_files_are_opened_exclusively_without_following_links(tmp_path, monkeypatch):
    """The flags every save opens its lock and temporary files with: ``O_NOFOLLOW`` for both, ``O_EXCL`` for the
    temporary file (created new, never an existing file or link)."""
    real = os.open
    opened = []

    def spy(path, flags, *args, **kwargs):
        opened.append((Path(os.fsdecode(path)).name, flags))
        return real(path, flags, *args, **kwargs)

    world = windmill()[1].world
    monkeypatch.setattr(os, "open", spy)
    save_state(world, tmp_path / "s.json")
    lock = [flags for name, flags in opened if name == ".s.json.lock"]
    temporary = [flags for name, flags in opened if name.startswith(".s.json.") and name.endswith(".tmp")]
    assert lock and temporary, opened
    assert all(flags & os.O_NOFOLLOW and flags & os.O_CREAT for flags in lock)
    assert all(flags & os.O_NOFOLLOW and flags & os.O_EXCL and flags & os.O_CREAT for flags in temporary)


def test_a_loop_of_links_is_one_line_for_save_and_load(tmp_path, no_run):
    (tmp_path / "a.json").symlink_to(tmp_path / "b.json")
    (tmp_path / "b.json").symlink_to(tmp_path / "a.json")
    status, err = likeme(["run", "learn_windmill", "--save", tmp_path / "a.json"])
    assert status == 1 and err == f"likeme: error: {tmp_path}/a.json: a loop of symbolic links; expected --save " \
                                  "FILE (a state file to write, or a link to one)\n"
    status, err = likeme(["run", "learn_windmill", "--load", tmp_path / "a.json"])
    assert status == 1 and err.count("\n") == 1 and "Too many levels of symbolic links" in err, err


def test_a_link_to_a_new_file_is_still_a_good_target(tmp_path):
    (tmp_path / "link.json").symlink_to(tmp_path / "new.json")
    assert check_save_target(tmp_path / "link.json") == tmp_path / "new.json"


@pytest.mark.parametrize("length, message", [
    (300, "a file name of 300 bytes is too long"),
    (240, "a file name of 240 bytes is too long; expected a name of at most 223 bytes"),
])
def test_a_name_too_long_for_the_saves_own_files_is_refused_before_the_run(tmp_path, no_run, length, message):
    status, err = likeme(["run", "learn_windmill", "--save", tmp_path / ("s" * length)])
    assert status == 1 and err.count("\n") == 1 and message in err, err
    assert list(tmp_path.iterdir()) == []


def test_the_longest_name_allowed_saves_with_its_conflict_file(tmp_path):
    """223 bytes: the lock, the temporary files and a conflict file's temporary file all fit in 255."""
    path = tmp_path / ("s" * 218 + ".json")
    target = StateFile(path)
    target.save('{"format": "likeme-state"}\n')
    path.write_text('{"format": "likeme-state", "other": 1}\n')  # another writer
    target.report = lambda message: None
    assert target.save('{"format": "likeme-state"}\n') == target.conflict_path


def test_a_lone_surrogate_in_a_state_file_is_one_line(tmp_path):
    data = {"format": "likeme-state", "version": 2, "actors": {"max": {"character": "Max\udfff", "components": {}}}}
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data).replace("}}}}", '}}}, "checksum": "sha256:00"}'))
    with pytest.raises(ConfigError, match=r"key actors.max.character: a string holding the lone surrogate \\udfff"):
        read_state(path)


def test_a_component_that_returns_a_lone_surrogate_is_named_when_saving(tmp_path):
    from toolkit import PluginError

    world = windmill()[1].world
    world.actors["max"].character.action.beliefs["pear\ud800"] = "food"
    with pytest.raises(PluginError, match=r"'hierarchical' failed in get_state: returned a string holding the lone "
                                          r"surrogate \\ud800"):
        save_state(world, tmp_path / "s.json")
    assert not (tmp_path / "s.json").exists()


def _reference_refuses(value, depth=0):
    """The schema's bounds on a JSON value, written plainly (recursively): True if any is broken."""
    if depth > MAX_DEPTH:
        return True
    if isinstance(value, bool) or value is None:
        return False
    if isinstance(value, int):
        return abs(value) > 2**53
    if isinstance(value, float):
        return value != value or value in (float("inf"), float("-inf"))
    if isinstance(value, str):
        return len(value) > 4096 or any("\ud800" <= c <= "\udfff" for c in value)
    if isinstance(value, dict):
        return any(_reference_refuses(k) or _reference_refuses(v, depth + 1) for k, v in value.items())
    return any(_reference_refuses(v, depth + 1) for v in value)


JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-(2**60), 2**60) | st.floats()
    | st.text(alphabet=st.characters(codec=None, categories=None), max_size=4) | st.sampled_from(["\ud800", "x" * 4097]),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=2) | st.just("\udfff"), inner,
                                                                  max_size=3),
    max_leaves=12)


@settings(max_examples=300, deadline=None)
@given(value=JSON_VALUES, depth=st.integers(0, MAX_DEPTH + 2))
def test_the_walk_refuses_exactly_what_the_schema_bounds_refuse(value, depth):
    """The iterative walk that checks every value of a state file (one step per value, key paths spelt out only for
    an error) refuses exactly what a plain recursive reading of the bounds refuses."""
    from toolkit.state import _walk

    nested = value
    for _ in range(depth):
        nested = [nested]
    try:
        _walk(nested, (), Path("s.json"))
    except ConfigError:
        refused = True
    else:
        refused = False
    assert refused == _reference_refuses(nested)
