"""The one error type users see.

Every user mistake (bad order string, bad scene file, missing texture, a shader
that does not compile, no GL available, ...) raises :class:`SandboxError` with a
one-line message naming the file, line or value. The CLI prints
``error: <message>`` and exits with status 2; nothing half-written is left.
"""

from __future__ import annotations


class SandboxError(Exception):
    """A user-facing error with a one-line message."""

    def __init__(self, message: str) -> None:
        # Keep the promise of one line: fold any newline a library gave us.
        super().__init__(" ".join(str(message).split("\n")).strip())
