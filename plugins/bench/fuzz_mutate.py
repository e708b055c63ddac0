"""Mutations of real-looking input files for ``likeme bench fuzz`` (see :mod:`plugins.bench.fuzz`).

Every mutation is a function ``(data: bytes, rng: numpy.random.Generator) -> bytes`` and is deterministic given the
generator's state. Generic ones work on any text (tokens, lines, bytes); the format-aware ones know where a parser
takes its sizes from (a BVH file's ``Frames:``, ``Frame Time:`` and ``CHANNELS``; a TOML file's ``key = value``
lines; a JSON state file's tree; a CSV file's header and columns) and put hostile values there.

:func:`mutate` stacks one to three mutations, picked from the generic ones and those of the file's format, and
returns the new bytes with the names of the mutations applied (the case's label in the fuzz report).
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable

import numpy as np

__all__ = ["HOSTILE_NUMBERS", "HOSTILE_STRINGS", "MUTATIONS", "mutate", "mutation_names", "NPY_SHAPES",
           "C3D_FIELDS"]

Mutation = Callable[[bytes, np.random.Generator], bytes]

HOSTILE_NUMBERS = (
    "0", "-0", "-1", "-30", "1e-7", "1e-320", "1e300", "-1e300", "1e999", "nan", "NaN", "-nan", "inf", "-inf",
    "Infinity", "99999999999999999999999", "2147483648", "-2147483649", "4294967296", "1000000000", "1e6",
    "\u00b2", "\u00b9\u00b2", "\u0663", "\u00bd", "\uff11", "0x10", "1_000", "1e", "--1", ".", "1..5", "+", "0.0",
    "3.5", "1e-7 ", "",
)
"""What a number is replaced with: huge, tiny, negative, not finite, digits ``str.isdigit`` accepts but ``int``
does not (superscripts, Arabic-Indic, full-width), malformed and empty."""

UNICODE_BITS = ("\ufeff", "\u200b", "\x00", "\u00e9", "\u2028", "\U0001f600", "\ud7ff", "\x1b[2J", "\u202e", "\x0c",
                "\r", "\t", "\\", '"', "'", "{", "}", "[", "]", "#", "=")
"""Characters inserted at random places: BOM, zero-width space, NUL, accents, a line separator, emoji, escapes,
control characters and the punctuation of every format involved."""

_TOKEN = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[A-Za-z_][\w.]*|\s+|.", re.S)
_NUMBER = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _tokens(data: bytes) -> list[bytes]:
    return _TOKEN.findall(data)


def _pick(rng: np.random.Generator, items):
    return items[int(rng.integers(len(items)))]


def _non_space(tokens: list[bytes]) -> list[int]:
    return [i for i, t in enumerate(tokens) if not t.isspace()]


# -- generic: tokens, lines, bytes ----------------------------------------------------------------------------------


def delete_token(data: bytes, rng: np.random.Generator) -> bytes:
    """Delete one token (a word, a number or a punctuation mark)."""
    tokens = _tokens(data)
    idx = _non_space(tokens)
    if idx:
        del tokens[_pick(rng, idx)]
    return b"".join(tokens)


def duplicate_token(data: bytes, rng: np.random.Generator) -> bytes:
    """Repeat one token one to three times (``{ {``, ``OFFSET OFFSET``, ``= =``)."""
    tokens = _tokens(data)
    idx = _non_space(tokens)
    if idx:
        i = _pick(rng, idx)
        tokens.insert(i, (tokens[i] + b" ") * int(rng.integers(1, 4)))
    return b"".join(tokens)


def swap_tokens(data: bytes, rng: np.random.Generator) -> bytes:
    """Swap two tokens, mostly near each other."""
    tokens = _tokens(data)
    idx = _non_space(tokens)
    if len(idx) > 1:
        a = int(rng.integers(len(idx)))
        b = min(len(idx) - 1, max(0, a + int(rng.integers(-6, 7)))) if rng.random() < 0.7 else int(rng.integers(len(idx)))
        i, j = idx[a], idx[b]
        tokens[i], tokens[j] = tokens[j], tokens[i]
    return b"".join(tokens)


def replace_word(data: bytes, rng: np.random.Generator) -> bytes:
    """Replace one word with another word of the same file (a keyword where a name belongs, and back)."""
    tokens = _tokens(data)
    words = [i for i, t in enumerate(tokens) if t[:1].isalpha() or t[:1] == b"_"]
    if len(words) > 1:
        tokens[_pick(rng, words)] = tokens[_pick(rng, words)]
    return b"".join(tokens)


def replace_number(data: bytes, rng: np.random.Generator) -> bytes:
    """Replace one to three numbers with hostile ones (:data:`HOSTILE_NUMBERS`)."""
    tokens = _tokens(data)
    numbers = [i for i, t in enumerate(tokens) if _NUMBER.fullmatch(t)]
    for _ in range(int(rng.integers(1, 4))):
        if numbers:
            tokens[_pick(rng, numbers)] = _pick(rng, HOSTILE_NUMBERS).encode()
    return b"".join(tokens)


def truncate(data: bytes, rng: np.random.Generator) -> bytes:
    """Cut the file at a random byte."""
    return data[: int(rng.integers(len(data) + 1))]


def flip_bytes(data: bytes, rng: np.random.Generator) -> bytes:
    """Flip one to eight random bits, or set random bytes to random values."""
    out = bytearray(data)
    for _ in range(int(rng.integers(1, 9))):
        if out:
            i = int(rng.integers(len(out)))
            out[i] = out[i] ^ (1 << int(rng.integers(8))) if rng.random() < 0.5 else int(rng.integers(256))
    return bytes(out)


def add_bom(data: bytes, rng: np.random.Generator) -> bytes:
    """A UTF-8 byte-order mark in front (or, rarely, a UTF-16 one)."""
    return (b"\xef\xbb\xbf" if rng.random() < 0.8 else b"\xff\xfe") + data


def line_ends(data: bytes, rng: np.random.Generator) -> bytes:
    """CRLF, CR-only or mixed line ends; or no final newline."""
    choice = int(rng.integers(4))
    if choice == 0:
        return data.replace(b"\r\n", b"\n").replace(b"\n", b"\r\n")
    if choice == 1:
        return data.replace(b"\r\n", b"\n").replace(b"\n", b"\r")
    if choice == 2:
        lines = data.split(b"\n")
        return b"".join(line + (b"\r\n" if rng.random() < 0.5 else b"\n") for line in lines[:-1]) + lines[-1]
    return data.rstrip(b"\r\n")


def insert_unicode(data: bytes, rng: np.random.Generator) -> bytes:
    """Insert one to three unusual characters (:data:`UNICODE_BITS`) at random places, or re-encode as UTF-16."""
    if rng.random() < 0.05:
        return data.decode("utf-8", "replace").encode("utf-16")
    out = data
    for _ in range(int(rng.integers(1, 4))):
        i = int(rng.integers(len(out) + 1))
        bit = _pick(rng, UNICODE_BITS).encode("utf-8", "surrogatepass")
        out = out[:i] + bit + out[i:]
    return out


def empty(data: bytes, rng: np.random.Generator) -> bytes:
    """An empty file, only whitespace, or only a newline."""
    return _pick(rng, (b"", b"\n", b"   \n\t\n", b"\r\n"))


def repeat_block(data: bytes, rng: np.random.Generator) -> bytes:
    """Repeat a random run of lines 2 to 500 times."""
    lines = data.splitlines(keepends=True)
    if not lines:
        return data
    a = int(rng.integers(len(lines)))
    b = min(len(lines), a + int(rng.integers(1, 12)))
    times = int(_pick(rng, (2, 3, 10, 100, 500)))
    return b"".join(lines[:b] + lines[a:b] * (times - 1) + lines[b:])


def delete_lines(data: bytes, rng: np.random.Generator) -> bytes:
    """Delete one to five consecutive lines."""
    lines = data.splitlines(keepends=True)
    if lines:
        a = int(rng.integers(len(lines)))
        del lines[a: a + int(rng.integers(1, 6))]
    return b"".join(lines)


def swap_lines(data: bytes, rng: np.random.Generator) -> bytes:
    """Swap two lines."""
    lines = data.splitlines(keepends=True)
    if len(lines) > 1:
        i, j = int(rng.integers(len(lines))), int(rng.integers(len(lines)))
        lines[i], lines[j] = lines[j], lines[i]
    return b"".join(lines)


def random_bytes(data: bytes, rng: np.random.Generator) -> bytes:
    """Splice 1 to 64 random bytes in (the only mutation that is noise)."""
    i = int(rng.integers(len(data) + 1))
    return data[:i] + rng.integers(0, 256, int(rng.integers(1, 65)), dtype=np.uint8).tobytes() + data[i:]


GENERIC: dict[str, Mutation] = {f.__name__: f for f in (
    delete_token, duplicate_token, swap_tokens, replace_word, replace_number, truncate, flip_bytes, add_bom, line_ends,
    insert_unicode, empty, repeat_block, delete_lines, swap_lines, random_bytes)}


# -- BVH -------------------------------------------------------------------------------------------------------------


def _sub_line(data: bytes, pattern: bytes, repl: Callable[[re.Match], bytes]) -> bytes:
    return re.sub(pattern, repl, data, count=1, flags=re.M)


FRAME_TIMES = ("1e-7", "1e-6", "1e-9", "0.00001", "1e-320", "0", "-0.0333333", "nan", "inf", "1e300", "\u00b2", "",
               "0.0333333 0.1", "1/30")
"""What ``Frame Time:`` becomes: tiny above all (filters are sized as seconds x fps), then zero, negative, not
finite, huge, not a number."""


def bvh_frame_time(data: bytes, rng: np.random.Generator) -> bytes:
    """A hostile ``Frame Time:`` (:data:`FRAME_TIMES`)."""
    value = _pick(rng, FRAME_TIMES)
    return _sub_line(data, rb"^(\s*Frame Time:)[^\r\n]*", lambda m: m.group(1) + b" " + value.encode())


def bvh_frames(data: bytes, rng: np.random.Generator) -> bytes:
    """A hostile ``Frames:`` count: huge, zero, negative, more or fewer than the lines present, not a number."""
    value = _pick(rng, HOSTILE_NUMBERS + ("1000000000000", "0", "1", "3", "100000"))
    return _sub_line(data, rb"^(\s*Frames:)[^\r\n]*", lambda m: m.group(1) + b" " + value.encode())


def bvh_channels(data: bytes, rng: np.random.Generator) -> bytes:
    """A hostile ``CHANNELS`` count or list on one joint (0, huge, ``\u00b2``, one name too many or too few)."""
    lines = data.splitlines(keepends=True)
    idx = [i for i, line in enumerate(lines) if line.strip().startswith(b"CHANNELS")]
    if not idx:
        return data
    i = _pick(rng, idx)
    parts = lines[i].split()
    choice = int(rng.integers(4))
    if choice == 0 and len(parts) > 1:
        parts[1] = _pick(rng, HOSTILE_NUMBERS + ("0", "7", "100000", "-3")).encode()
    elif choice == 1 and len(parts) > 2:
        del parts[-1]
    elif choice == 2:
        parts.append(_pick(rng, (b"Xrotation", b"Wrotation", b"Xposition", b"xrotation")))
    else:
        parts = parts[:2]
    ending = b"\r\n" if lines[i].endswith(b"\r\n") else b"\n"
    lines[i] = b"  " + b" ".join(parts) + ending
    return b"".join(lines)


def bvh_deep_nesting(data: bytes, rng: np.random.Generator) -> bytes:
    """Joints nested 50 to 3,000 deep inside the first joint block (each one with an offset and three channels)."""
    depth = int(_pick(rng, (50, 200, 1000, 3000)))
    m = re.search(rb"\{\s*OFFSET[^\r\n]*\r?\n\s*CHANNELS[^\r\n]*\r?\n", data)
    if not m:
        return data
    opening = b"".join(b"JOINT n%d\n{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n" % k for k in range(depth))
    inner = opening + b"}\n" * depth
    return data[: m.end()] + inner + data[m.end():]


def bvh_motion_rows(data: bytes, rng: np.random.Generator) -> bytes:
    """Frame lines: one made ragged, one value hostile, rows duplicated many times, or all removed."""
    head, sep, rest = data.partition(b"MOTION")
    if not sep:
        return data
    lines = rest.splitlines(keepends=True)
    rows = [i for i, line in enumerate(lines) if _NUMBER.match(line.strip() or b"x") and b":" not in line]
    if not rows:
        return data
    choice = int(rng.integers(4))
    i = _pick(rng, rows)
    if choice == 0:
        values = lines[i].split()
        lines[i] = b" ".join(values[: int(rng.integers(len(values) + 1))] + values[: int(rng.integers(3))]) + b"\n"
    elif choice == 1:
        values = lines[i].split()
        values[int(rng.integers(len(values)))] = _pick(rng, HOSTILE_NUMBERS).encode()
        lines[i] = b" ".join(values) + b"\n"
    elif choice == 2:
        lines[i:i + 1] = [lines[i]] * int(_pick(rng, (10, 1000, 20000)))
    else:
        lines = [line for k, line in enumerate(lines) if k not in set(rows)]
    return head + sep + b"".join(lines)


def bvh_end_site(data: bytes, rng: np.random.Generator) -> bytes:
    """Damage an ``End Site`` block: channels in it, a joint in it, no braces, or ``End`` without ``Site``."""
    m = re.search(rb"End Site\s*\{[^}]*\}", data)
    if not m:
        return data
    block = m.group(0)
    choice = int(rng.integers(4))
    if choice == 0:
        block = block.replace(b"{", b"{\nCHANNELS 3 Zrotation Xrotation Yrotation\n", 1)
    elif choice == 1:
        block = block.replace(b"}", b"JOINT x\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\n}", 1)
    elif choice == 2:
        block = block.replace(b"{", b"").replace(b"}", b"")
    else:
        block = block.replace(b"End Site", b"End")
    return data[: m.start()] + block + data[m.end():]


def bvh_names(data: bytes, rng: np.random.Generator) -> bytes:
    """A joint renamed: duplicate name, empty, a name with spaces or unicode, a keyword."""
    names = list(re.finditer(rb"^(\s*(?:ROOT|JOINT)[ \t]+)(\S+)", data, flags=re.M))
    if not names:
        return data
    m = _pick(rng, names)
    new = _pick(rng, [n.group(2) for n in names] + [b"", b"two words", "h\u00fcfte".encode(), b"MOTION", b"{", b"End"])
    return data[: m.start(2)] + new + data[m.end(2):]


BVH_MUTATIONS: dict[str, Mutation] = {f.__name__: f for f in (
    bvh_frame_time, bvh_frames, bvh_channels, bvh_deep_nesting, bvh_motion_rows, bvh_end_site, bvh_names)}


# -- TOML ------------------------------------------------------------------------------------------------------------

HOSTILE_TOML_VALUES = (
    "1e300", "-1e300", "nan", "inf", "-inf", "0", "-1", "1e-7", "9223372036854775807", "99999999999999999999",
    '"abc"', '""', "[]", '["x"]', "{}", "true", '"\u00b2"', "[1, [2, [3]]]", '{ a = 1 }', "1979-05-27",
    '"' + "x" * 5000 + '"', "[" + ", ".join(["0.0"] * 2000) + "]",
)
"""What a TOML value is replaced with: numbers outside every range, other types, empty and huge collections."""

_TOML_ASSIGN = re.compile(rb"^([ \t]*[A-Za-z0-9_\"'.\- ]+?[ \t]*=[ \t]*)([^\r\n]*)", re.M)


def toml_value(data: bytes, rng: np.random.Generator) -> bytes:
    """Replace the value of one ``key = value`` line with a hostile one (:data:`HOSTILE_TOML_VALUES`)."""
    lines = list(_TOML_ASSIGN.finditer(data))
    if not lines:
        return data
    m = _pick(rng, lines)
    return data[: m.start(2)] + _pick(rng, HOSTILE_TOML_VALUES).encode() + data[m.end(2):]


SIZING_NUMBERS = ("1e300", "1e9", "1e6", "100000000", "2147483648", "9223372036854775807", "nan", "inf", "-inf", "-1",
                  "0", "-0.0", "1e-7", "1e-300")
"""What a number that may size memory or time (a frame rate, a duration, a count) is replaced with."""


def toml_number(data: bytes, rng: np.random.Generator) -> bytes:
    """Replace one number of a value (``fps = 30.0``, ``tail = 1.5``, ``random = 12``, a key time) with a size that
    is huge, tiny, negative, zero or not finite (:data:`SIZING_NUMBERS`)."""
    spans = []
    for m in _TOML_ASSIGN.finditer(data):
        value = m.group(2).split(b"#")[0]
        spans += [(m.start(2) + n.start(), m.start(2) + n.end()) for n in _NUMBER.finditer(value)
                  if not value[:n.start()].count(b'"') % 2]  # not inside a string
    if not spans:
        return data
    a, b = spans[int(rng.integers(len(spans)))]
    return data[:a] + _pick(rng, SIZING_NUMBERS).encode() + data[b:]


_TOML_SCALAR = re.compile(rb"^([ \t]*[A-Za-z0-9_\-]+[ \t]*=[ \t]*)([-+]?[0-9][0-9_.eE+\-]*)[ \t]*(?:#[^\r\n]*)?$", re.M)


def toml_scalar(data: bytes, rng: np.random.Generator) -> bytes:
    """Replace a whole numeric value (``fps = 30.0``, ``tail = 1.5``, ``random = 12``, ``seed = 3``) with a size that
    is huge, tiny, negative, zero or not finite (:data:`SIZING_NUMBERS`): where a scenario's or a component's time
    and memory come from."""
    lines = list(_TOML_SCALAR.finditer(data))
    if not lines:
        return toml_number(data, rng)
    m = _pick(rng, lines)
    return data[: m.start(2)] + _pick(rng, SIZING_NUMBERS).encode() + data[m.end(2):]


def toml_wrap(data: bytes, rng: np.random.Generator) -> bytes:
    """Wrap one value in a list (``held_by = ["max"]``, ``up = ["+y"]``) or an inline table."""
    lines = [m for m in _TOML_ASSIGN.finditer(data) if m.group(2).strip() and not m.group(2).strip().startswith(b"[")]
    if not lines:
        return data
    m = _pick(rng, lines)
    value = m.group(2).split(b"#")[0].strip()
    new = b"[" + value + b"]" if rng.random() < 0.7 else b"{ value = " + value + b" }"
    return data[: m.start(2)] + new + data[m.end(2):]


def toml_deep(data: bytes, rng: np.random.Generator) -> bytes:
    """A value nested 50 to 5,000 deep: arrays, inline tables or dotted table headers."""
    depth = int(_pick(rng, (50, 500, 5000)))
    lines = list(_TOML_ASSIGN.finditer(data))
    choice = int(rng.integers(3))
    if choice == 0:
        value = b"[" * depth + b"1" + b"]" * depth
    elif choice == 1:
        value = b"{ a = " * depth + b"1" + b" }" * depth
    else:
        header = b"[" + b".".join(b"t%d" % k for k in range(depth)) + b"]\nx = 1\n"
        return data + b"\n" + header
    if not lines:
        return data + b"\nx = " + value + b"\n"
    m = _pick(rng, lines)
    return data[: m.start(2)] + value + data[m.end(2):]


def toml_tables(data: bytes, rng: np.random.Generator) -> bytes:
    """A table header duplicated, turned into an array of tables, or renamed to a neighbour's name."""
    headers = list(re.finditer(rb"^\[+([^\]\r\n]+)\]+", data, flags=re.M))
    if not headers:
        return data
    m = _pick(rng, headers)
    choice = int(rng.integers(3))
    if choice == 0:
        return data + b"\n" + m.group(0) + b"\n"
    if choice == 1:
        new = b"[[" + m.group(1) + b"]]" if not m.group(0).startswith(b"[[") else b"[" + m.group(1) + b"]"
    else:
        new = _pick(rng, headers).group(0)
    return data[: m.start()] + new + data[m.end():]


def toml_extends(data: bytes, rng: np.random.Generator) -> bytes:
    """``extends`` / ``character`` pointing at itself, at a folder, at a device, at nothing, or not a string."""
    target = _pick(rng, (b'"."', b'"/dev/null"', b'"/"', b'""', b'"max"', b"3", b'["max"]', b'"../../../../etc/passwd"',
                         b'"nobody"', b'"/dev/zero"', b'"/proc/self/status"'))
    m = re.search(rb"^([ \t]*(?:extends|character)[ \t]*=[ \t]*)([^\r\n]*)", data, flags=re.M)
    if not m:
        return data.replace(b"[character]\n", b"[character]\nextends = " + target + b"\n", 1)
    return data[: m.start(2)] + target + data[m.end(2):]


TOML_MUTATIONS: dict[str, Mutation] = {f.__name__: f for f in (
    toml_value, toml_number, toml_scalar, toml_wrap, toml_deep, toml_tables, toml_extends)}


# -- JSON (state files) ----------------------------------------------------------------------------------------------

_DEEP = "__FUZZ_DEEP__"


def _hostile_json(rng: np.random.Generator):
    """A hostile JSON value; deep nesting comes back as ``(_DEEP, depth)`` and is spliced in as text."""
    choice = int(rng.integers(14))
    if choice == 12:
        return [0] * int(_pick(rng, (1000, 100000)))
    if choice == 13:
        return (_DEEP, int(_pick(rng, (100, 1000, 100000))))
    return [[], {}, _pick(rng, HOSTILE_STRINGS), "", None, True, -1, 0, 10 ** 400, 1e308, float("nan"),
            float("inf")][choice]


HOSTILE_STRINGS = ("abc", "\ud800", "\udfff", "\x1b]0;owned\x07\x1b[2J", "a" * 5000, "\u202e", "line\nbreak", "\x00")
"""Strings a state file's value or key is replaced with: a lone surrogate (which UTF-8 cannot hold), terminal
escapes, a long string, a right-to-left override, a line break, NUL."""


def _paths(node, path=()):
    yield path
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node[:50]):
            yield from _paths(v, (*path, i))


def json_node(data: bytes, rng: np.random.Generator) -> bytes:
    """Replace, delete, rename or multiply one node of the JSON tree (the file stays valid JSON).

    Deep nesting that :func:`json.dumps` cannot write is spliced in as text.
    """
    try:
        tree = json.loads(data)
    except (ValueError, RecursionError):
        return data
    paths = list(_paths(tree))[1:]
    if not paths:
        return data
    path = _pick(rng, paths)
    parent = tree
    for k in path[:-1]:
        parent = parent[k]
    key = path[-1]
    choice = int(rng.integers(5))
    depth = 0
    if choice <= 1:
        value = _hostile_json(rng)
        if isinstance(value, tuple):
            depth, value = value[1], _DEEP
        parent[key] = value
    elif choice == 2:
        del parent[key]
    elif choice == 3 and isinstance(parent, dict):
        parent[_pick(rng, ("", "x", str(key).upper(), str(key) + " ", *HOSTILE_STRINGS))] = parent.pop(key)
    elif isinstance(parent, list):
        parent.extend([parent[key]] * int(_pick(rng, (10, 1000))))
    else:
        parent[key] = [parent[key]]
    text = json.dumps(tree, indent=1, allow_nan=True)
    if depth:
        text = text.replace(f'"{_DEEP}"', "[" * depth + "1" + "]" * depth, 1)
    return text.encode()


JSON_MUTATIONS: dict[str, Mutation] = {"json_node": json_node}


# -- CSV (joint positions) -------------------------------------------------------------------------------------------


def csv_header(data: bytes, rng: np.random.Generator) -> bytes:
    """The header: a column duplicated, dropped, renamed (``_w``, no suffix, empty), or ``time`` moved or doubled."""
    head, sep, rest = data.partition(b"\n")
    cols = head.rstrip(b"\r").split(b",")
    choice = int(rng.integers(5))
    i = int(rng.integers(len(cols)))
    if choice == 0:
        cols.insert(i, cols[i])
    elif choice == 1 and len(cols) > 1:
        del cols[i]
    elif choice == 2:
        cols[i] = _pick(rng, (b"", cols[i][:-2], cols[i][:-1] + b"w", cols[i] + b"_x", b"time", b"x_x_x"))
    elif choice == 3:
        cols = cols[::-1]
    else:
        cols.append(b"time")
    return b",".join(cols) + sep + rest


def csv_cells(data: bytes, rng: np.random.Generator) -> bytes:
    """Cells: hostile numbers, quoted or empty cells, a ragged row, ``;`` as separator, or time going backwards."""
    lines = data.split(b"\n")
    rows = [k for k in range(1, len(lines)) if lines[k].strip()]
    if not rows:
        return data
    k = _pick(rng, rows)
    cells = lines[k].split(b",")
    choice = int(rng.integers(5))
    if choice == 0:
        for _ in range(int(rng.integers(1, 4))):
            cells[int(rng.integers(len(cells)))] = _pick(rng, HOSTILE_NUMBERS).encode()
    elif choice == 1:
        cells[int(rng.integers(len(cells)))] = _pick(rng, (b'""', b'"1,5"', b"", b" ", b"NA", b"null"))
    elif choice == 2:
        cells = cells[: int(rng.integers(len(cells)))] if rng.random() < 0.5 else cells + cells[:3]
    elif choice == 3:
        return data.replace(b",", b";")
    else:
        lines[k], lines[rows[0]] = lines[rows[0]], lines[k]
        return b"\n".join(lines)
    lines[k] = b",".join(cells)
    return b"\n".join(lines)


def csv_rows(data: bytes, rng: np.random.Generator) -> bytes:
    """Rows: only the header, one row repeated 10 to 100,000 times, or a comment line."""
    head, sep, rest = data.partition(b"\n")
    rows = rest.splitlines(keepends=True)
    choice = int(rng.integers(3))
    if choice == 0 or not rows:
        return head + sep
    if choice == 1:
        return head + sep + rows[0] * int(_pick(rng, (10, 1000, 100000)))
    return head + sep + b"# comment\n" + rest


CSV_MUTATIONS: dict[str, Mutation] = {f.__name__: f for f in (csv_header, csv_cells, csv_rows)}

# -- .npy arrays ------------------------------------------------------------------------------------------------------

_NPY_MAGIC = b"\x93NUMPY"
NPY_SHAPES = ("(9223372036854775808, 11, 3)", "(1000000000000000000000000000000, 11, 3)", "(-1, 11, 3)",
              "(0, 11, 3)", "(4294967296, 11, 3)", "(457, 0, 3)", "(457, 11)", "()", "(457, 11, 3, 2)", "(457, 11, 4)",
              "(457, 100000, 3)", "(1e3, 11, 3)", "[457, 11, 3]", "(457,, 3)")
"""What an ``.npy`` header's shape is replaced with: beyond 64 bits, beyond any file, negative, empty, the wrong
number of axes, not a tuple, malformed."""
NPY_DESCRS = ("'|O'", "'<U3'", "'>f8'", "'<f4'", "'<i8'", "'|b1'", "'<c16'", "'V8'", "'<f16'", "'xyz'", "None")
"""What its dtype is replaced with: Python objects (pickles), strings, other byte orders and sizes, nonsense."""


def npy_header(data: bytes, rng: np.random.Generator) -> bytes:
    """The header of an ``.npy`` file: its shape, dtype or ``fortran_order`` hostile, its declared header length or
    version wrong (version 2 and 3 headers read with a 4-byte length), or the header alone (no data)."""
    if not data.startswith(_NPY_MAGIC) or len(data) < 10:
        return data
    major = data[6]
    size = int.from_bytes(data[8:10], "little") if major == 1 else int.from_bytes(data[8:12], "little")
    start = 10 if major == 1 else 12
    header, body = data[start:start + size], data[start + size:]
    choice = int(rng.integers(6))
    if choice == 0:
        header = re.sub(rb"'shape': \([^)]*\)", b"'shape': " + _pick(rng, NPY_SHAPES).encode(), header)
    elif choice == 1:
        header = re.sub(rb"'descr': '[^']*'", b"'descr': " + _pick(rng, NPY_DESCRS).encode(), header)
    elif choice == 2:
        header = header.replace(b"False", b"True") if b"False" in header else header.replace(b"True", b"False")
    elif choice == 3:  # a declared header length that does not match
        size = int(_pick(rng, (0, 1, size - 1, size + 1, 65535)))
    elif choice == 4:  # another version: 2.0 (a 4-byte length), 3.0, or one numpy does not know
        major = int(_pick(rng, (2, 3, 9)))
        return _NPY_MAGIC + bytes([major, 0]) + len(header).to_bytes(4, "little") + header + body
    else:
        body = b""
    return _NPY_MAGIC + bytes([major, data[7]]) + (size.to_bytes(2, "little") if major == 1 else
                                                   size.to_bytes(4, "little")) + header + body


def npy_archive(data: bytes, rng: np.random.Generator) -> bytes:
    """An ``.npz`` archive (a zip of arrays) in place of the array: what ``np.savez`` writes, named ``.npy``."""
    import io
    import zipfile

    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as archive:
        archive.writestr("positions.npy", data)
    return out.getvalue()


NPY_MUTATIONS: dict[str, Mutation] = {f.__name__: f for f in (npy_header, npy_archive)}


# -- C3D -------------------------------------------------------------------------------------------------------------

C3D_FIELDS = (  # (what, offset: "h" header byte offset or "p" parameter section byte, struct format, values)
    ("parameter block", "h", 0, "B", (0, 1, 3, 200, 255)),
    ("key", "h", 1, "B", (0, 0x51, 255)),
    ("points", "h", 2, "<H", (0, 1, 65535)),
    ("analog channels", "h", 4, "<H", (1, 64, 65535)),
    ("first frame", "h", 6, "<H", (0, 2, 500, 65535)),
    ("last frame", "h", 8, "<H", (0, 1, 458, 65535)),
    ("scale", "h", 12, "<f", (0.0, 1.0, -1e30, float("nan"), float("inf"))),
    ("data start", "h", 16, "<H", (0, 1, 2, 5, 65535)),
    ("analog per frame", "h", 18, "<H", (1, 65535)),
    ("rate", "h", 20, "<f", (0.0, -30.0, 1e-30, 1e30, float("nan"), float("inf"))),
    ("parameter blocks", "p", 2, "B", (0, 1, 255)),
    ("processor", "p", 3, "B", (0, 83, 85, 86, 87, 255)),
)
"""The C3D header's fields (C3D.org: header words 1-12; the parameter section's bytes 3 and 4) and their hostile
values."""


def c3d_header(data: bytes, rng: np.random.Generator) -> bytes:
    """One field of a C3D file's header or parameter section set to a hostile value."""
    import struct

    if len(data) < 512:
        return data
    _, where, offset, fmt, values = C3D_FIELDS[int(rng.integers(len(C3D_FIELDS)))]
    if where == "p":
        offset += (data[0] - 1) * 512
    if offset + struct.calcsize(fmt) > len(data):
        return data
    out = bytearray(data)
    struct.pack_into(fmt, out, offset, _pick(rng, values))
    return bytes(out)


def c3d_cut(data: bytes, rng: np.random.Generator) -> bytes:
    """The file cut at a block boundary, inside the header or parameters, or inside a frame."""
    cut = int(_pick(rng, (0, 100, 511, 512, 1024, 2048, 2560, len(data) // 2, len(data) - 1)))
    return data[:max(0, min(cut, len(data)))]


C3D_MUTATIONS: dict[str, Mutation] = {f.__name__: f for f in (c3d_header, c3d_cut)}

MUTATIONS: dict[str, dict[str, Mutation]] = {
    "bvh": BVH_MUTATIONS, "toml": TOML_MUTATIONS, "json": JSON_MUTATIONS, "csv": CSV_MUTATIONS, "npy": NPY_MUTATIONS,
    "c3d": C3D_MUTATIONS}
"""The format-aware mutations by format (every format also gets :data:`GENERIC`)."""


def mutation_names(fmt: str) -> list[str]:
    """The names of the mutations a file of format ``fmt`` can get."""
    return sorted(BYTE_LEVEL if fmt in BINARY else GENERIC) + sorted(MUTATIONS.get(fmt, {}))


BINARY = ("npy", "c3d")
"""The formats whose files are bytes, not text: only their own mutations, and the byte-level generic ones."""
BYTE_LEVEL = ("truncate", "flip_bytes", "random_bytes", "repeat_block", "empty")


def mutate(data: bytes, fmt: str, rng: np.random.Generator) -> tuple[bytes, list[str]]:
    """Apply one to three mutations to ``data`` (two in three format-aware); return the bytes and their names."""
    aware = MUTATIONS.get(fmt, {})
    if fmt in BINARY:
        generic = {k: v for k, v in GENERIC.items() if k in BYTE_LEVEL}
        applied = []
        for _ in range(int(rng.choice([1, 1, 2]))):
            pool = aware if rng.random() < 3 / 4 else generic
            name = _pick(rng, sorted(pool))
            data = pool[name](data, rng)
            applied.append(name)
        return data, applied
    applied = []
    for _ in range(int(rng.choice([1, 1, 2, 3]))):
        pool = aware if aware and rng.random() < 2 / 3 else GENERIC
        name = _pick(rng, sorted(pool))
        data = pool[name](data, rng)
        applied.append(name)
    return data, applied
