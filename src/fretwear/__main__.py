"""``python -m fretwear``: the command line (:mod:`fretwear.cli`)."""

import sys

from fretwear.cli import main

sys.exit(main())
