"""Views: pictures of a character's representations and of running scenarios (``likeme show``, ``likeme run --render``).

Registers the ``body``, ``posegraph``, ``motor-command-graph``, ``scenario``, ``hub-signal``, ``speed-profile`` and
``prediction-error`` views; ``plotting`` and ``demonstration`` are what the signal views share.
"""
