"""``python -m parapend.cli``."""

import sys

from . import main

sys.exit(main())
