"""``python -m parapend``: the ``parapend`` command line."""

import sys

from ._entry import main

sys.exit(main())
