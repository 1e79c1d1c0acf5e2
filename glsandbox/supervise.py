"""A lesson file's commands run in a child process, so a lesson that ends it says so.

``glsandbox render my_lesson.py`` (and ``run``, ``tour --lessons DIR``) imports
the user's code. Code that calls ``os._exit(0)`` or crashes the interpreter (a
segfault) on import ends the process with no Python left to report it: from
inside, it would look like a quiet success. So the command runs once more as a
child, and this process (which imports none of the user's code) waits for it:
the child tells it on a pipe that it reached the end of its command; a child
that ends without saying so is one ``error:`` line here, exit 1.

Ctrl-C: SIGINT sent to this process alone is passed on to the child; sent to
the whole process group it reaches both, and this one waits for the child's
own answer (exit 130) rather than leaving it behind.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

#: Set in the child: it is the one that runs the command (and holds the pipe's end to write).
CHILD_ENV = "GLSANDBOX_SUPERVISED_FD"
#: The commands that import a user's lesson file.
COMMANDS = ("render", "run", "tour")
#: What this process exits with when the child ended without finishing its command.
EXIT_LESSON_ENDED = 1


def user_code_in(words: list[str]) -> str | None:
    """The lesson file or folder of ``words`` that imports user code, or None (a built-in lesson)."""
    if not words or words[0] not in COMMANDS:
        return None
    if words[0] == "tour":
        for i, word in enumerate(words):
            if word == "--lessons" and i + 1 < len(words):
                return words[i + 1]
            if word.startswith("--lessons="):
                return word.partition("=")[2]
        return None
    # The first lesson file among the words, wherever it is: an option's value may come before it
    # (``render --size 32x24 mine.py``). Supervising a command that needed none costs a process only.
    return next((w for w in words[1:] if not w.startswith("-") and w.endswith(".py") and Path(w).is_file()), None)


def finished() -> None:
    """In the child: tell the parent the command reached its end (any exit status)."""
    fd = os.environ.pop(CHILD_ENV, None)
    if fd is not None:
        try:
            os.write(int(fd), b"done")
            os.close(int(fd))
        except OSError:
            pass


def supervised(words: list[str], source: str) -> int:
    """Run ``glsandbox WORDS`` as a child and answer for it (see the module doc)."""
    read_end, write_end = os.pipe()
    env = {**os.environ, CHILD_ENV: str(write_end)}
    child = subprocess.Popen([sys.executable, "-m", "glsandbox.cli", *words], env=env, pass_fds=(write_end,))
    os.close(write_end)
    forwarded = False

    def forward(signum: int, frame: object) -> None:
        nonlocal forwarded
        if not forwarded:  # sent to us alone, or to the group (then the child has it already: once is enough)
            forwarded = True
            try:
                child.send_signal(signal.SIGINT)
            except ProcessLookupError:
                pass

    previous = signal.signal(signal.SIGINT, forward)
    try:
        chunks = []
        while chunk := os.read(read_end, 16):
            chunks.append(chunk)
        status = child.wait()
    finally:
        signal.signal(signal.SIGINT, previous)
        os.close(read_end)
    if b"".join(chunks) == b"done":
        return status
    if forwarded:
        return 130
    if status < 0:
        name = signal.Signals(-status).name
        print(f"error: {source}: the lesson's process died ({name}) before its picture", file=sys.stderr)
    else:
        print(f"error: {source}: the lesson ended the process (exit status {status}, e.g. os._exit) "
              "before its picture", file=sys.stderr)
    return EXIT_LESSON_ENDED
