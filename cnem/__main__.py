"""``python -m cnem``: the ``cnem`` command."""

import sys

from .cli import main

sys.exit(main())
