"""The benchmarks' plain-text tables (rich): the same text as padding each cell by hand to its column's width."""

from __future__ import annotations

import string

from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.bench import text_table


def reference_table(rows, columns, header=True, indent=2):
    """Hand padding: each column as wide as its widest cell, two spaces between columns, no trailing spaces."""
    lines = ([[name for name, _ in columns]] if header else []) + [[str(c) for c in row] for row in rows]
    widths = [max(len(line[i]) for line in lines) for i in range(len(columns))]
    pad = {"left": str.ljust, "right": str.rjust}
    return "\n".join((" " * indent + "  ".join(pad[j](cell, w) for cell, w, (_, j) in zip(line, widths, columns)))
                     .rstrip() for line in lines)


cell = st.text(alphabet=string.ascii_letters + string.digits + string.punctuation + " ", min_size=1, max_size=12).map(
    str.rstrip).filter(bool)  # leading spaces (an indented label) kept; rich drops a cell's trailing ones


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 6).flatmap(lambda n: st.tuples(
    st.lists(st.tuples(cell, st.sampled_from(["left", "right"])), min_size=n, max_size=n),
    st.lists(st.lists(st.one_of(st.just(""), cell), min_size=n, max_size=n), min_size=1, max_size=8),
    st.booleans(), st.integers(0, 4))))
def test_a_table_is_the_hand_padded_text(case):
    columns, rows, header, indent = case
    assert text_table(rows, columns, header=header, indent=indent) == reference_table(rows, columns, header, indent)


def test_markup_is_text_and_wide_tables_do_not_wrap():
    rows = [["[bold]x[/bold] :smile:", "1"], ["y" * 300, "22"]]  # wider than any terminal; rich markup and emoji codes
    lines = text_table(rows, [("name", "left"), ("n", "right")]).splitlines()
    assert lines[1] == "  [bold]x[/bold] :smile:" + " " * (300 - 22) + "   1"
    assert lines[2] == "  " + "y" * 300 + "  22" and len(lines) == 3
