"""Segmenters: where one movement of the observed stream ends and the next begins.

Registers ``hub-threshold`` (B&B §5.1), ``velocity-direction`` (K&G §4.1, §4.3) and the ``ruptures`` baseline.
"""
