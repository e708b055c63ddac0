"""Tests of the matchers: the comparisons and decisions they share, and each matcher in its own folder."""
