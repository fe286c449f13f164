"""``python -m zmpwalk.cli``: the ``zmpwalk`` command."""

import sys

from zmpwalk.cli import main

if __name__ == "__main__":
    sys.exit(main())
