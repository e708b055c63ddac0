"""Tests of plugins/correspondence/."""
