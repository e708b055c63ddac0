"""Tests of plugins/lib/."""
