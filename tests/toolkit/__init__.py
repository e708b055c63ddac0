"""Tests of the core, toolkit/: one file per module."""
