"""Tests of toolkit/recordings/: one reader per format behind one open function, profiles, live input."""
