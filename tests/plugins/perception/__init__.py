"""Tests of plugins/perception/."""
