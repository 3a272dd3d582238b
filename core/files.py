"""Reading and writing the files of scenes and results, safely.

Rules (each refusal is a ``ValueError`` starting with the path):

* A file is read only if it is a regular file: a named pipe, a device or a directory is
  refused without blocking (it is opened non-blocking and checked with ``fstat`` on the
  open descriptor, so it cannot be swapped between the check and the read).
* A write is atomic (a temporary file in the same directory, flushed, renamed over the
  target): readers see the old file or the complete new one.
* An existing target must be a regular file that is not read-only (no write permission
  bit set, or not writable by this user): a file the user protected is refused, never
  replaced (``os.replace`` would ignore its mode, and so would a superuser).
* A symbolic link is written *through*: the file it points to is replaced and the link
  stays a link (the temporary file lives next to the target).
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path


def read_regular_file(path: str | os.PathLike, max_bytes: int) -> bytes:
    """The bytes of the regular file ``path``, at most ``max_bytes`` [bytes].

    Raises ValueError for a file that is not regular or larger than ``max_bytes``
    (checked before reading and again while reading, in case it grew), ``OSError`` if
    it cannot be opened.
    """
    path = Path(path)
    # O_NONBLOCK: opening a named pipe for reading would otherwise wait for a writer
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            kind = "a directory" if stat.S_ISDIR(info.st_mode) else "a named pipe" if (
                stat.S_ISFIFO(info.st_mode)) else "a device or socket"
            raise ValueError(f"{path}: not a regular file (it is {kind})")
        if info.st_size > max_bytes:
            raise ValueError(f"{path}: file is {info.st_size} bytes, over the limit of "
                             f"{max_bytes} bytes")
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        with os.fdopen(fd, "rb") as fh:
            fd = -1
            raw = fh.read(max_bytes + 1)
    finally:
        if fd >= 0:
            os.close(fd)
    if len(raw) > max_bytes:
        raise ValueError(f"{path}: file is over the limit of {max_bytes} bytes")
    return raw


def writable_target(path: str | os.PathLike) -> Path:
    """The file a write to ``path`` replaces (a symlink resolved to its target).

    Raises ValueError if that file exists and is not a regular file or is read-only, if
    ``path`` names a directory, or if the folder it would go in does not exist or may not
    be written (found before the work whose result it is, not after).
    """
    path = Path(path)
    target = Path(os.path.realpath(path)) if path.is_symlink() else path
    try:
        info = os.stat(target)
    except FileNotFoundError:
        folder = target.parent
        if not folder.is_dir():
            raise ValueError(f"{path}: the folder {folder} does not exist (create it or "
                             "choose another file)") from None
        if not os.access(folder, os.W_OK | os.X_OK):
            raise ValueError(f"{path}: the folder {folder} may not be written (choose "
                             "another file)") from None
        return target
    if stat.S_ISDIR(info.st_mode):
        raise ValueError(f"{path}: is a directory, not a file")
    if not stat.S_ISREG(info.st_mode):
        raise ValueError(f"{path}: not a regular file (a named pipe, device or socket); "
                         "write to a regular file")
    if not (info.st_mode & 0o222) or not os.access(target, os.W_OK):
        raise ValueError(f"{path}: is read-only; it is not replaced (make it writable or "
                         "choose another file)")
    return target


def same_file(first: str | os.PathLike, second: str | os.PathLike) -> bool:
    """Whether two paths name the same file (through links and ``..``), existing or not."""
    try:
        return os.path.samefile(first, second)
    except OSError:
        return os.path.realpath(first) == os.path.realpath(second)


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` (UTF-8, ``\\n`` line ends) to ``path`` atomically
    (:func:`atomic_write_bytes`)."""
    atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically, under the rules of this module.

    A temporary file in the target's directory is flushed to disk, then renamed over the
    target; an existing target keeps its mode. Raises ValueError (see
    :func:`writable_target`) or ``OSError``.
    """
    target = writable_target(path)
    directory = target.parent if str(target.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{target.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        # mkstemp creates the file readable by its owner only; keep an existing file's
        # mode, else use the usual mode of a new file
        try:
            mode = target.stat().st_mode & 0o777
        except FileNotFoundError:
            mode = 0o644
        os.chmod(tmp, mode)
        os.replace(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
