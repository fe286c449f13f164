"""``python -m zmpwalk.cli``: the ``zmpwalk`` command."""

import sys

from zmpwalk.cli import main

sys.exit(main())
