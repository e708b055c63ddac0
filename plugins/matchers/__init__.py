"""Matchers: which of the observer's own movements a segment is.

Registers ``path-search`` (B&B §5.2), ``forward-model`` (K&G §4.4) and the ``dtw`` baseline.
"""
