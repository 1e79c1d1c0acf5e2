"""Reading and writing files: PNG images and text, written atomically; inputs opened only when regular.

Every file glsandbox writes (rendered PNGs, goldens, the tour's JSON and
gallery, reports, plots) goes through :func:`atomic_write`: the bytes go to a
temporary file in the target folder under a unique name, are flushed to disk
and then moved over the target with :func:`os.replace`. A reader sees the old
file or the complete new one, never half of one; two writers of the same name
never share a temporary file; on any error the temporary file is removed.

Every file glsandbox reads by a name the user gave (scene files, textures,
shaders) is opened by :func:`open_regular`, in binary mode on every system
(Windows's ``O_BINARY``: text mode would end a PNG at its first 0x1A byte
and turn its CR LF signature bytes into LF): a named pipe, a device or a
folder is refused at once instead of blocking forever or failing later.

A path written inside a file (a scene file's texture, model or shader, a
grading file's golden) means the same on every system: :func:`written_path`.
"""

from __future__ import annotations

import glob
import io
import os
import re
import stat
import tempfile
import time
from collections.abc import Callable
from pathlib import Path, PurePath, PurePosixPath, PureWindowsPath
from typing import TYPE_CHECKING, BinaryIO

import numpy as np
from PIL import Image

if TYPE_CHECKING:  # annotations only: numpy.typing is not imported at run time (a cold start)
    import numpy.typing as npt

from glsandbox.errors import SandboxError

__all__ = ["NotARegularFile", "atomic_write", "load_png", "next_numbered", "open_regular", "png_bytes", "read_regular", "save_png",
           "write_text", "written_path"]


#: A file name may have 255 bytes; ``mkstemp`` adds 8 random characters and the suffix.
_NAME_MAX = 255
_TMP_SUFFIX = ".tmp"
#: A temporary file this old was left by a writer that was killed (``kill -9``,
#: power loss); the next write of the same name removes it.
STALE_SECONDS = 600.0


def _tmp_prefix(name: str) -> str:
    """``.<name>.``, cut so that the temporary name fits where ``name`` fits.

    The name's bytes as the file system has them (a name that is not UTF-8
    arrives with surrogate escapes), cut to whole UTF-8 characters: bytes that
    are not UTF-8 are left out of the prefix."""
    room = _NAME_MAX - len(".") - len(".") - 8 - len(_TMP_SUFFIX)
    encoded = os.fsencode(name)[:room].decode("utf-8", errors="ignore")
    return f".{encoded}."


def _remove_stale(folder: Path, prefix: str) -> None:
    """Delete this name's temporary files that no live writer can own any more."""
    cutoff = time.time() - STALE_SECONDS
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for entry in entries:
        if entry.name.startswith(prefix) and entry.name.endswith(_TMP_SUFFIX) \
                and len(entry.name) == len(prefix) + 8 + len(_TMP_SUFFIX):
            try:
                if entry.stat(follow_symlinks=False).st_mtime < cutoff:
                    os.unlink(entry.path)
            except OSError:
                pass


def atomic_write(path: str | os.PathLike[str], data: bytes | Callable[[BinaryIO], object]) -> Path:
    """Write ``data`` (bytes, or a function writing to a binary file) to ``path`` atomically.

    Parent folders are created. The temporary name is ``.<name>.<random>.tmp``
    beside the target (unique per call, made by :func:`tempfile.mkstemp`, and
    cut to fit when the name is long); temporary files of the same name older
    than :data:`STALE_SECONDS` (left by a killed writer) are removed. OS errors
    propagate as :class:`OSError`; nothing is left behind.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    prefix = _tmp_prefix(target.name)
    _remove_stale(target.parent, prefix)
    fd, tmp_name = tempfile.mkstemp(dir=target.parent, prefix=prefix, suffix=_TMP_SUFFIX)
    try:
        with os.fdopen(fd, "wb") as f:
            if callable(data):
                data(f)
            else:
                f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp_name, 0o644)  # mkstemp makes 0600; outputs are ordinary files
        _replace(tmp_name, target)
    except BaseException:
        try:
            os.unlink(tmp_name)
        except FileNotFoundError:
            pass
        raise
    return target


#: Windows refuses to replace a file another program holds open (an image viewer showing the
#: last render, an editor, a virus scanner's quick look): tries, and the wait after each.
REPLACE_TRIES = 10
REPLACE_WAIT_S = 0.05


def _replace(tmp_name: str, target: Path) -> None:
    """``os.replace``, tried again while the target is held open by another program (Windows:
    a sharing violation, PermissionError); then one PermissionError that says so."""
    for attempt in range(REPLACE_TRIES):
        try:
            os.replace(tmp_name, target)
            return
        except PermissionError:
            if attempt == REPLACE_TRIES - 1:
                raise PermissionError(13, f"cannot replace {target}: another program has it open or it is "
                                          "read-only (close it, or write to another name)", os.fspath(target)) from None
            time.sleep(REPLACE_WAIT_S)


class NotARegularFile(OSError):
    """A path that names something other than a regular file: a named pipe, a device, a socket."""

    def __init__(self, path: str | os.PathLike[str], kind: str) -> None:
        super().__init__(f"{os.fspath(path)} is {kind}, not a regular file")
        self.kind = kind


_KINDS = ((stat.S_ISFIFO, "a named pipe (FIFO)"), (stat.S_ISSOCK, "a socket"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"))


#: How a user's file is opened: read only, binary (Windows), without blocking on a pipe (POSIX),
#: not inherited by child processes.
READ_FLAGS = (os.O_RDONLY | getattr(os, "O_BINARY", 0) | getattr(os, "O_NONBLOCK", 0)
              | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOINHERIT", 0))


def written_path(text: str, folder: str | os.PathLike[str], *, windows: bool = os.name == "nt") -> Path:
    """A path written inside a file in ``folder`` (a scene file's ``texture``, ``mesh`` or
    ``shader``, a grading file's ``golden``), as this system names it.

    Written on any system, it means the same on every one: ``/`` and ``\\`` both
    separate folders (``textures\\brick.png`` from Windows works on Linux), and a
    relative path is relative to ``folder``, not the shell's working directory. A
    drive letter or UNC path (``C:\\course\\brick.png``) is absolute on Windows and
    refused elsewhere with a :class:`SandboxError`: no other system can reach it.
    """
    return Path(_written(text, PureWindowsPath(folder) if windows else PurePosixPath(folder), windows))


def _written(text: str, folder: PurePath, windows: bool) -> PurePath:
    """:func:`written_path` on pure paths (``windows`` picks the flavour, so both are tested anywhere)."""
    as_windows = PureWindowsPath(text)
    if windows:
        return as_windows if as_windows.is_absolute() or as_windows.drive else folder / as_windows
    if as_windows.drive:
        raise SandboxError(f"{text!r} is a Windows path (drive {as_windows.drive}): write it relative to the file "
                           "that names it, with / or \\ between folders")
    posix = PurePosixPath(text.replace("\\", "/"))
    return posix if posix.is_absolute() else folder / posix


def open_regular(path: str | os.PathLike[str]) -> BinaryIO:
    """Open a regular file for reading (binary), refusing anything else.

    The file is opened without blocking and checked on the open descriptor
    (no window between a check and the open): a named pipe with no writer
    would otherwise block the open, or the read, forever. Raises
    :class:`FileNotFoundError`, :class:`IsADirectoryError`,
    :class:`PermissionError`, :class:`NotARegularFile` or another
    :class:`OSError`.
    """
    fd = os.open(path, READ_FLAGS)
    try:
        mode = os.fstat(fd).st_mode
        if stat.S_ISDIR(mode):
            raise IsADirectoryError(21, "Is a directory", os.fspath(path))
        if not stat.S_ISREG(mode):
            raise NotARegularFile(path, next((kind for test, kind in _KINDS if test(mode)), "not a regular file"))
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_regular(path: str | os.PathLike[str]) -> bytes:
    """The bytes of a regular file (see :func:`open_regular`)."""
    with open_regular(path) as handle:
        return handle.read()


#: While grading (in the child rendering one submission): the folders user files must lie in,
#: the submission's first (empty: any path, the default).
_sandbox_roots: tuple[str, ...] = ()


def set_sandbox_root(root: str | os.PathLike[str] | None, also: tuple[str | os.PathLike[str], ...] = ()) -> None:
    """Refuse, from now on, user files that resolve outside ``root`` and ``also`` (glsandbox's
    own shader folders); None: any path, the default.

    Set only in the child process that renders one graded submission
    (:mod:`glsandbox.grading.sandbox`); everywhere else files are read wherever they are.
    """
    global _sandbox_roots
    _sandbox_roots = () if root is None else tuple(os.path.realpath(r) for r in (root, *also))


def inside(path: str, root: str) -> bool:
    """Whether the real path ``path`` is ``root`` or lies under it."""
    return path == root or path.startswith(root.rstrip("/") + "/")


def check_inside_sandbox(path: str | os.PathLike[str], what: str) -> None:
    """While grading: a :class:`SandboxError` when ``path`` (symlinks followed) is outside the submission."""
    if not _sandbox_roots:
        return
    real = os.path.realpath(path)
    if not any(inside(real, root) for root in _sandbox_roots):
        raise SandboxError(f"{what} {os.fspath(path)} is outside the submission; "
                           "a graded submission may read only its own files")


def open_user_file(path: str | os.PathLike[str], what: str, expected: str) -> BinaryIO:
    """:func:`open_regular` for a file the user named, every failure one line:
    ``<what> <path> not found``, ``... is a folder, expected <expected>``, ``... is a
    named pipe (FIFO), expected <expected>``, ``... is not readable (permission
    denied)``, ``... cannot be read (<reason>)`` or, while grading, ``... is outside
    the submission`` (:func:`set_sandbox_root`), as :class:`SandboxError`."""
    where = f"{what} {os.fspath(path)}"
    check_inside_sandbox(path, what)
    try:
        return open_regular(path)
    except FileNotFoundError:
        raise SandboxError(f"{where} not found") from None
    except IsADirectoryError:
        raise SandboxError(f"{where} is a folder, expected {expected}") from None
    except NotARegularFile as exc:
        raise SandboxError(f"{where} is {exc.kind}, expected {expected}") from None
    except PermissionError:
        raise SandboxError(f"{where} is not readable (permission denied)") from None
    except OSError as exc:
        raise SandboxError(f"{where} cannot be read ({exc.strerror or exc})") from None


def read_user_file(path: str | os.PathLike[str], what: str, expected: str) -> bytes:
    """The bytes of a file the user named (:func:`open_user_file`'s errors, and read errors alike)."""
    with open_user_file(path, what, expected) as handle:
        try:
            return handle.read()
        except OSError as exc:
            raise SandboxError(f"{what} {os.fspath(path)} cannot be read ({exc.strerror or exc})") from None


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write UTF-8 text atomically (see :func:`atomic_write`)."""
    return atomic_write(path, text.encode("utf-8"))


def _png_image(image: npt.ArrayLike) -> Image.Image:
    arr = np.asarray(image)
    if arr.dtype != np.uint8:
        raise TypeError(f"cannot save dtype {arr.dtype} as PNG; expected uint8")
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[:, :, 0]
    if not (arr.ndim == 2 or (arr.ndim == 3 and arr.shape[2] in (3, 4))):
        raise ValueError(f"cannot save shape {arr.shape} as PNG; expected (H, W[, 1|3|4])")
    return Image.fromarray(np.ascontiguousarray(arr))  # uint8: L, RGB or RGBA by shape


class _PngBuffer(io.BytesIO):
    """An in-memory file named ``*.png``: Pillow then takes the format from the name and
    imports only its PNG plugin, where ``format="PNG"`` imports five (BMP, GIF, JPEG, PPM
    and PNG: about 2 ms of every cold start). The bytes are the same."""

    name = "image.png"


def png_bytes(image: npt.ArrayLike) -> bytes:
    """A uint8 image, (H, W), (H, W, 1), (H, W, 3) or (H, W, 4), encoded as PNG."""
    buffer = _PngBuffer()
    _png_image(image).save(buffer)
    return buffer.getvalue()


def save_png(image: npt.ArrayLike, path: str | os.PathLike[str]) -> Path:
    """Write a uint8 image as a PNG, atomically (:func:`atomic_write`). Returns the path."""
    return atomic_write(path, png_bytes(image))


def load_png(path: str | os.PathLike[str]) -> np.ndarray:
    """Read a PNG file as a uint8 RGBA array of shape (H, W, 4).

    Greyscale, palette and RGB files are converted to RGBA (opaque alpha).

    Raises:
        FileNotFoundError: the file does not exist.
        PIL.UnidentifiedImageError: the file is not a PNG.
    """
    with Image.open(path, formats=["PNG"]) as im:
        return np.array(im.convert("RGBA"), dtype=np.uint8)


def next_numbered(folder: str | os.PathLike[str], stem: str, suffix: str = ".png") -> Path:
    """``folder/<stem>-<n><suffix>`` with ``n`` one past the highest already there (1 in
    an empty folder): a new screenshot never replaces one from an earlier run."""
    pattern = re.compile(re.escape(stem) + r"-(\d+)" + re.escape(suffix) + "$")
    folder = Path(folder)
    taken = [int(m.group(1)) for p in folder.glob(f"{glob.escape(stem)}-*{suffix}") if (m := pattern.match(p.name))]
    return folder / f"{stem}-{max(taken, default=0) + 1}{suffix}"
