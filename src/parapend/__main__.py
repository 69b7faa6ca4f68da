"""``python -m parapend``: the ``parapend`` command line."""

import sys

from .cli import main

sys.exit(main())
