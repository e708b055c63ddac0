"""Tests of plugins/views/."""
