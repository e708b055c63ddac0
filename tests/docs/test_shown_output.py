"""Every command output the docs show is what the command prints.

A page shows a command's output in a code block: a ``$ likeme ...`` line, then what it prints, ``...`` where lines
are left out. Each such command is checked here, or by the test named in :data:`CHECKED` (one that has what the
command needs: an installed third-party plugin). An error a page shows (a ``likeme: error: ...`` line) must be a
row of ``docs/errors.md``, which ``tests/likeme/test_errors.py`` produces from the cases it runs. The benchmark
page's figures are measurements, not outputs to reproduce, and are left out.
"""

from __future__ import annotations

import re
import shlex

import pytest

from likeme.cli import main
from tests.conftest import ROOT

PAGES = sorted(p for p in (ROOT / "docs").glob("*.md") if p.name not in ("benchmarks.md", "errors.md"))
PAGES.append(ROOT / "README.md")

CHECKED = {
    ("writing-a-plugin.md", "likeme plugins"): "tests/toolkit/test_third_party.py",
    ("writing-a-plugin.md", "likeme validate still_max.toml"): "tests/toolkit/test_third_party.py",
}
"""Commands whose shown output another test checks (with what the command needs), and that test."""


def shown(page) -> list[tuple[str, list[str]]]:
    """The commands a page shows with their output: each ``$ likeme ...`` line of a code block, with the lines after
    it up to the next ``$`` line or the block's end (``...``: lines left out)."""
    out = []
    for block in re.findall(r"^```\w*\n(.*?)^```", page.read_text(encoding="utf-8"), re.S | re.M):
        lines = block.rstrip("\n").split("\n")
        for i, line in enumerate(lines):
            if line.startswith("$ likeme "):
                rest = lines[i + 1:]
                end = next((k for k, text in enumerate(rest) if text.startswith("$ ")), len(rest))
                out.append((line[2:], rest[:end]))
    return out


def agrees(expected: list[str], printed: list[str]) -> bool:
    """Whether ``printed`` holds the ``expected`` lines in order: each run of lines between ``...`` exactly and one
    after another, the runs in order, with anything where a ``...`` stands (and, without one, nothing)."""
    runs, run = [], []
    for line in expected:
        if line.strip() == "...":
            runs.append(run)
            run = []
        else:
            run.append(line)
    runs.append(run)
    at = 0
    for k, run in enumerate(runs):
        if not run:
            continue
        places = [i for i in range(at, len(printed) - len(run) + 1) if printed[i:i + len(run)] == run]
        if k == 0 and expected[0].strip() != "...":
            places = places[:1] if places and places[0] == 0 else []
        if not places:
            return False
        at = places[0] + len(run)
    return expected[-1].strip() == "..." or at == len(printed)


def printed(command: str, capsys) -> list[str]:
    """What ``command`` (``likeme ...``) prints on standard output, run in this process."""
    capsys.readouterr()
    assert main(shlex.split(command)[1:]) == 0
    return capsys.readouterr().out.rstrip("\n").split("\n")


SHOWN = [(page, command, expected) for page in PAGES for command, expected in shown(page)]


def test_the_pages_show_commands_and_every_one_is_checked():
    assert SHOWN and any(page.name == "inspecting.md" for page, _, _ in SHOWN)
    assert set(CHECKED) <= {(page.name, command) for page, command, _ in SHOWN}, "CHECKED names a command no page shows"


@pytest.mark.parametrize("page, command, expected", SHOWN, ids=[f"{p.name}: {c}" for p, c, _ in SHOWN])
def test_a_shown_output_is_what_the_command_prints(page, command, expected, capsys):
    if (page.name, command) in CHECKED:
        pytest.skip(f"checked by {CHECKED[page.name, command]}")
    assert expected, f"{page.name} shows `{command}` without its output"
    assert agrees(expected, printed(command, capsys)), f"{page.name}: `{command}` prints something else"


def test_every_error_a_page_shows_is_a_row_of_the_errors_page():
    rows = {line.replace("DIR/", "") for line in
            re.findall(r"`(likeme: error: [^`]*)`", (ROOT / "docs" / "errors.md").read_text(encoding="utf-8"))}
    shown_errors = [(page.name, line) for page in PAGES
                    for block in re.findall(r"^```\w*\n(.*?)^```", page.read_text(encoding="utf-8"), re.S | re.M)
                    for line in block.split("\n") if line.startswith("likeme: error: ")]
    assert shown_errors
    for name, line in shown_errors:
        assert line in rows, f"{name} shows an error docs/errors.md does not have: {line}"


@pytest.mark.parametrize("expected, lines, ok", [
    (["a", "b"], ["a", "b"], True), (["a", "b"], ["a", "b", "c"], False), (["a", "..."], ["a", "b"], True),
    (["...", "b", "..."], ["a", "b", "c"], True), (["...", "c"], ["a", "b", "c"], True), (["b"], ["a", "b"], False),
    (["a", "...", "c"], ["a", "b", "c"], True), (["a", "...", "c"], ["c", "a"], False),
])
def test_what_agrees(expected, lines, ok):
    assert agrees(expected, lines) == ok


def test_a_page_with_a_checked_output_leaves_nothing_unparsed():
    """Every ``$`` line of a console block is a command this file finds (no other prompt hides an output)."""
    for page in PAGES:
        for block in re.findall(r"^```\w*\n(.*?)^```", page.read_text(encoding="utf-8"), re.S | re.M):
            for line in block.split("\n"):
                if line.startswith("$ ") and not line.startswith(("$ likeme ", "$ pip ")):
                    pytest.fail(f"{page.name}: a shown command this file does not check: {line}")
