"""Tests of plugins/motor/."""
