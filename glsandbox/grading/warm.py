"""The warm template: a process that holds one GL context, already drawn with, to fork renderers from.

A renderer forked from the cold zygote spends most of its life starting
llvmpipe: 20 to 50 ms for the context and 60 to 145 ms for the first draw
(compiling the draw's shaders), against a few milliseconds for a picture in
a process that has drawn before. Forking after a context exists is safe only
when the context has nothing a fork cannot copy:

- no worker threads: llvmpipe's rasterizer threads would be missing in the
  child, which then waits for them forever. ``LP_NUM_THREADS=0`` makes
  llvmpipe draw on the calling thread (a 320x240 picture is cheap that way)
  and gives the same pixels;
- no device and no shared memory: a hardware driver maps GPU memory that a
  fork would share between submissions, and holds the device's descriptor.
  Only a software rasterizer (llvmpipe, softpipe) that opened no descriptor
  and mapped nothing writable and shared qualifies (Mesa's shader-cache
  index aside: every process that opens a context maps that file alike,
  cold renderers too, and an entry it points to is checked when read);
- Mesa's shader-cache thread (``disk$``) holding no lock at the moment of
  the fork: :func:`quiet` waits until it sleeps on its queue.

Each fork is copy on write: a submission's renderer writes into its own copy
of the context, and the template, which never runs a submission's code, stays
as it was for the next one. When any check fails, :func:`open_template`
says no and the zygote forks renderers cold, as before.
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Iterable

__all__ = ["open_template", "quiet", "SOFTWARE"]

#: The renderers (``GL_RENDERER``) that draw in the process's own memory and nowhere else.
SOFTWARE = ("llvmpipe", "softpipe")

#: A scene that draws every shading glsandbox has, so their programs are compiled before any fork.
_WARM_SCENE = """name = "warm-up"
[camera]
eye = [2.5, 2.0, 3.5]
[[lights]]
position = [2, 3, 4]
"""


def _threads() -> dict[str, str]:
    """This process's threads: id -> name."""
    names = {}
    for tid in os.listdir("/proc/self/task"):
        try:
            with open(f"/proc/self/task/{tid}/comm") as handle:
                names[tid] = handle.read().strip()
        except OSError:
            pass
    return names


def _descriptors() -> set[str]:
    found = set()
    for fd in os.listdir("/proc/self/fd"):
        try:
            found.add(os.readlink(f"/proc/self/fd/{fd}"))
        except OSError:  # the descriptor listdir itself used
            pass
    return found


def _shared_writable() -> set[str]:
    """The file mappings this process could write and another process sees (``rw-s``), but
    Mesa's shader cache's (its index, which every process that opens a context maps alike)."""
    from glsandbox.grading.sandbox import shader_cache_dirs

    caches = shader_cache_dirs()
    found = set()
    with open("/proc/self/maps") as handle:
        for line in handle:
            fields = line.split(maxsplit=5)
            if fields[1][1] == "w" and fields[1][3] == "s":
                path = fields[5].strip() if len(fields) > 5 else "[anonymous]"
                if not any(path.startswith(cache + os.sep) for cache in caches):
                    found.add(path)
    return found


def quiet(timeout: float = 1.0) -> bool:
    """Wait until every thread but this one sleeps on a futex (Mesa's cache thread idle on its
    queue, holding no lock a forked child could need); False if one is still busy at ``timeout``."""
    me = str(os.getpid())
    end = time.monotonic() + timeout
    while True:
        busy = False
        for tid in _threads():
            if tid == me:
                continue
            try:
                with open(f"/proc/self/task/{tid}/stat") as handle:
                    state = handle.read().rsplit(")", 1)[1].split()[0]
                with open(f"/proc/self/task/{tid}/wchan") as handle:
                    wchan = handle.read()
            except OSError:  # the thread ended
                continue
            busy = busy or state != "S" or not wchan.startswith("futex")
        if not busy:
            return True
        if time.monotonic() > end:
            return False
        time.sleep(0.002)


def _warm_up(renderer, sizes: Iterable[tuple[int, int]]) -> int:
    """Draw every shading once at each size (programs compiled, targets allocated); how many drew.
    A shading draws on the first built-in mesh it accepts (``vertex_color`` needs a coloured one)."""
    from glsandbox.errors import SandboxError
    from glsandbox.lesson import find_lesson
    from glsandbox.scene import SHADINGS

    drawn = 0
    with tempfile.TemporaryDirectory(prefix="glsandbox-warm-") as folder:
        for shading in SHADINGS:
            for mesh in ("cube24", "cube"):
                path = os.path.join(folder, f"{shading}-{mesh}.toml")
                with open(path, "w") as handle:
                    handle.write(_WARM_SCENE + f'[[nodes]]\nmesh = "{mesh}"\nshading = "{shading}"\n')
                try:
                    lesson = find_lesson(path)
                except SandboxError:
                    continue
                for size in sizes:
                    renderer.render(lesson.from_settings({}), size)
                drawn += 1
                break
    return drawn


def open_template(backend: str | None, sizes: Iterable[tuple[int, int]]):
    """A warmed :class:`~glsandbox.frame.HeadlessRenderer` safe to fork, or None (no GL, a hardware
    driver, a descriptor or a thread a fork cannot copy). Call only in a process that exists to be
    the template: a context that fails the checks stays open in it."""
    os.environ["LP_NUM_THREADS"] = "0"  # llvmpipe: no rasterizer threads (read when the context opens)
    # No on-disk shader cache in a template. Mesa's cache thread (disk$N) waits on a condition
    # variable; a fork copies that waiter's state but not the thread, so the first cache write in
    # a child (a shader no process had compiled before: a student's own shader file) signalled a
    # condition variable whose copied waiter never answers, and the child hung until its time
    # limit (graded TIMEOUT). The warm-up below compiles the built-in programs every fork
    # inherits; a submission's other programs compile in its child (about 10-20 ms each here).
    os.environ["MESA_SHADER_CACHE_DISABLE"] = "true"
    threads, descriptors, shared = set(_threads()), _descriptors(), _shared_writable()
    try:
        from glsandbox.frame import HeadlessRenderer

        renderer = HeadlessRenderer(backend)
        name = str(renderer.host.ctx.info.get("GL_RENDERER", ""))
        if not name.startswith(SOFTWARE) or _descriptors() != descriptors or _shared_writable() != shared:
            return None
        if not _warm_up(renderer, sizes):
            return None
    except Exception:  # noqa: BLE001 - no GL here: the cold renderers report it, one line each
        return None
    # llvmpipe's own threads are named llvmpipe-N; Mesa's cache thread (disk$N) is checked before each fork.
    if any("disk$" not in name for tid, name in _threads().items() if tid not in threads):
        return None
    return renderer if quiet() else None
