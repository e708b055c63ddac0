"""Correspondence: another body's poses mapped onto one's own before they are segmented and matched (B&B §7.1,
K&G §6).

Registers ``body-mapping``: the demonstrator's size (:mod:`plugins.lib.body_size`) and rest posture
(:mod:`plugins.lib.rest_posture`) estimated from the stream and replaced by the observer's own.
"""
