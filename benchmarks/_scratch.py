"""A scratch folder per benchmark module, made when first asked for and removed at exit.

A module-level ``tempfile.TemporaryDirectory`` is removed by the garbage collector
when the module object goes (the tests import benchmark modules afresh), which
Python reports as a ResourceWarning inside whatever runs then; this folder is
removed explicitly at interpreter exit instead.
"""

from __future__ import annotations

import atexit
import shutil
import tempfile
from pathlib import Path


def scratch_folder(prefix: str) -> Path:
    """A new empty folder named ``<prefix>...`` under the system's temp dir, removed at exit."""
    folder = Path(tempfile.mkdtemp(prefix=prefix))
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    return folder
