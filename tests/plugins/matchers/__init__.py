"""Tests of the matchers: the comparisons, searches and decisions they share, and each matcher in its own folder."""
