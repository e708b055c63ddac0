"""``python -m likeme``: the ``likeme`` command (:func:`likeme.cli.main`)."""

import sys

from likeme.cli import main

sys.exit(main())
