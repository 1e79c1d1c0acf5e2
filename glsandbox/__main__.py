"""``python -m glsandbox``: the ``glsandbox`` command, for when the script is not on PATH."""

import sys

from glsandbox.launch import main

if __name__ == "__main__":
    sys.exit(main())
