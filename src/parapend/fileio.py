"""Writing output files: atomically, with the user's umask, and one typed error on failure.

Every file parapend writes (CSV, JSON, HTML, figures, NetCDF) goes through :func:`write_bytes`
(or a function built on it): the data go to a hidden temporary ``.tmp-parapend-*`` in the
destination's directory, which then replaces the destination with :func:`os.replace`. So a
reader sees the old file or the new one, never half of one; the temporary is removed on any
exception, ``KeyboardInterrupt`` included; and the new file gets the mode a plain ``open``
would give it, ``0o666 & ~umask`` (:func:`tempfile.mkstemp` alone would leave 0600), also when
it replaces an existing file.

Destinations that are not regular files (``/dev/null``, ``/dev/stdout``, a FIFO) are written
in place: there is nothing to replace atomically there. Any failure, from a missing or
read-only directory to a full disk or a name too long for the file system, raises
:class:`~parapend.errors.OutputError` with a one-line message naming the path and the
operating system's reason.
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import stat
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

from .errors import OutputError, ParameterError

__all__ = ["FIGURE_FORMATS", "TEMP_PREFIX", "OutputError", "check_target", "output_error",
           "save_figure", "umask", "write_bytes", "write_dataset", "write_text"]

#: Prefix of every temporary file: hidden, and recognizable as parapend's.
TEMP_PREFIX = ".tmp-parapend-"

#: Figure formats :func:`save_figure` writes, by file-name suffix.
FIGURE_FORMATS = ("png", "svg", "pdf")

# Metadata that would make two renderings of one figure differ (dates, version strings).
_FIGURE_METADATA = {"png": {"Software": None}, "svg": {"Date": None},
                    "pdf": {"CreationDate": None, "ModDate": None, "Producer": None}}


def umask() -> int:
    """The process's file-mode creation mask, read without changing it where possible.

    Linux reports it in ``/proc/self/status``; elsewhere it is read with the
    set-and-restore idiom of :func:`os.umask` (not atomic between threads).
    """
    try:
        with open("/proc/self/status", encoding="ascii", errors="replace") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _reason(exc: BaseException) -> str:
    """The OS's reason for ``exc`` on one line; works for exceptions without ``strerror``."""
    reason = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
    return " ".join(str(reason).split())


def output_error(path, exc: BaseException) -> OutputError:
    """An :class:`OutputError` for ``path``: ``cannot write 'PATH': REASON`` on one line."""
    name = " ".join(str(path).split()) if str(path) else "''"
    return OutputError(f"cannot write {name!r}: {_reason(exc)}")


def _target(path) -> Path:
    """The file to write: ``path`` with its symbolic links resolved, checked for sanity."""
    if isinstance(path, str) and path == "":
        raise OutputError("cannot write '': expected a file name, got an empty string")
    p = Path(path)
    try:
        if p.is_symlink():
            p = p.resolve()
        if p.is_dir():
            raise OutputError(f"cannot write {str(path)!r}: Is a directory")
    except OSError as exc:  # e.g. a name too long for the file system
        raise output_error(path, exc) from None
    return p


def named_fifo(path) -> bool:
    """True when ``path`` (or the file a link leads to) is a named pipe in the file system:
    writing there waits for ever for a reader, so no output goes there. A pipe reached
    through ``/dev/stdout`` or ``/dev/fd/N`` (``parapend ... --save /dev/stdout | ...``)
    is the process's own descriptor, not a named pipe."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return False
    if not stat.S_ISFIFO(st.st_mode):
        return False
    real = os.path.realpath(path)
    return not (real.startswith(("/proc/", "/dev/fd/")) or ":[" in real)


def _write_in_place(path: Path, write: Callable[[str], None], shown) -> None:
    """Write to a destination that is not a regular file (device, FIFO) directly."""
    try:
        write(str(path))
    except OSError as exc:
        raise output_error(shown, exc) from None


#: Free space (bytes) below which a failed write is put down to a full disk.
_LOW_SPACE = 1 << 20


def _full_disk(directory, exc: OSError) -> OSError:
    """``exc``, or an ``ENOSPC`` error when the disk is full: HDF5 (NetCDF) reports a full
    disk as "Permission denied" or "HDF error", and the file it failed on is one that was
    just created here, so a full disk is the likely reason when almost no space is left."""
    if exc.errno in (errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC)):
        return exc
    try:
        st = os.statvfs(directory)
    except (OSError, AttributeError):  # no statvfs (Windows)
        return exc
    root = hasattr(os, "geteuid") and os.geteuid() == 0
    free = (st.f_bfree if root else st.f_bavail) * st.f_frsize
    if free >= _LOW_SPACE:
        return exc
    return OSError(errno.ENOSPC, f"{os.strerror(errno.ENOSPC)} ({free} bytes free; the "
                                 f"writer reported: {_reason(exc)})")


def _atomic(path, write: Callable[[str], None]) -> Path:
    """Call ``write(tmp)`` to fill a temporary beside ``path``, then move it onto ``path``."""
    target = _target(path)
    try:
        st = os.stat(target)
    except OSError:
        st = None
    if st is not None and not stat.S_ISREG(st.st_mode):
        if named_fifo(target):
            raise OutputError(f"cannot write {str(path)!r}: a FIFO (named pipe), which waits "
                              "for a reader for ever; give a regular file")
        _write_in_place(target, write, path)
        return target
    directory = target.parent if str(target.parent) else Path(".")
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(dir=directory, prefix=TEMP_PREFIX, suffix=target.suffix)
        os.close(fd)
        try:
            write(tmp)
        except OSError as exc:
            raise _full_disk(directory, exc) from None
        os.chmod(tmp, 0o666 & ~umask())
        os.replace(tmp, target)
        tmp = None
    except OSError as exc:
        raise output_error(path, exc) from None
    finally:  # any exception, KeyboardInterrupt included: leave no temporary behind
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
    return target


def write_bytes(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically, with mode ``0o666 & ~umask``.

    Parameters
    ----------
    path : str or os.PathLike
        Destination file. Its directory must exist.
    data : bytes

    Returns
    -------
    pathlib.Path
        The file written (symbolic links resolved).

    Raises
    ------
    OutputError
        The file cannot be written; the message names ``path`` and the OS's reason.
    """
    data = bytes(data)

    def write(name: str) -> None:
        with open(name, "wb") as fh:
            fh.write(data)

    return _atomic(path, write)


def write_text(path, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically (no newline translation); see :func:`write_bytes`."""
    return write_bytes(path, text.encode(encoding))


@contextlib.contextmanager
def _figure_rc() -> Iterator[None]:
    from matplotlib import rc_context

    from .style import RC

    with rc_context({**RC, "svg.hashsalt": "parapend"}):  # deterministic SVG ids
        yield


def figure_bytes(fig, fmt: str = "png", dpi: int = 200) -> bytes:
    """Render ``fig`` to bytes in ``fmt`` (png, svg, pdf), reproducibly: no dates, no
    version strings, fixed SVG ids, so one figure gives identical bytes on every run."""
    fmt = fmt.lower()
    if fmt not in FIGURE_FORMATS:
        raise ParameterError(f"figure format: expected one of {', '.join(FIGURE_FORMATS)}, "
                             f"got {fmt!r}")
    buf = io.BytesIO()
    with _figure_rc():
        fig.savefig(buf, format=fmt, dpi=dpi, bbox_inches="tight",
                    metadata=_FIGURE_METADATA[fmt])
    return buf.getvalue()


def save_figure(fig, path, dpi: int = 200, close: bool = True) -> Path:
    """Save a matplotlib figure as PNG, SVG or PDF (by the suffix of ``path``), atomically.

    The bytes are reproducible (:func:`figure_bytes`). ``close`` releases a figure made with
    pyplot (pyplot is not imported here if it is not already loaded).

    Raises
    ------
    ParameterError
        The suffix is not ``.png``, ``.svg`` or ``.pdf``.
    OutputError
        The file cannot be written.
    """
    fmt = Path(path).suffix.lstrip(".").lower()
    if fmt not in FIGURE_FORMATS:
        raise ParameterError(f"figure file: expected a name ending in .png, .svg or .pdf, "
                             f"got {str(path)!r}")
    try:
        data = figure_bytes(fig, fmt, dpi)
    finally:
        plt = sys.modules.get("matplotlib.pyplot")
        if close and plt is not None:
            plt.close(fig)
    return write_bytes(path, data)


def write_dataset(ds, path) -> Path:
    """Write an ``xarray.Dataset`` to NetCDF at ``path`` atomically; see :func:`write_bytes`.

    The NetCDF library's failures (``RuntimeError: NetCDF: HDF error``) are
    :class:`OutputError` too, with "No space left on device" when the disk is full."""
    def write(name: str) -> None:
        try:
            ds.to_netcdf(name)
        except RuntimeError as exc:
            raise OSError(errno.EIO, f"NetCDF library: {_reason(exc)}") from None

    return _atomic(path, write)


def check_target(path, name: str, suffixes=None, directory: bool = False) -> Path:
    """Check, before any long work, that ``path`` can be written: a name (ending in one of
    ``suffixes``), in an existing directory where a file can be created (a temporary is
    made and removed: a read-only mount, ``/proc``, no permission fail here), and not itself
    a directory (unless ``directory``: a store written as a directory). Raises
    :class:`ParameterError` naming the option ``name`` on one line; returns the path.

    The library's counterpart of the command line's ``_check_output`` (the command that
    solved every bin and then could not write its NetCDF lost the work)."""
    if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
        raise ParameterError(f"{name}: expected a file name, got {path!r:.60}")
    p = Path(path)
    if suffixes and p.suffix.lower() not in suffixes:
        raise ParameterError(f"{name}: expected a file name ending in {' or '.join(suffixes)}, "
                             f"got {str(path)!r:.80}")
    try:
        for anc in reversed(p.parents):
            if anc.exists() and not anc.is_dir():
                raise ParameterError(f"{name}: {str(anc)!r} is a file, not a directory")
        parent = p.parent if str(p.parent) else Path(".")
        if not parent.is_dir():
            raise ParameterError(f"{name}: directory {str(parent)!r} does not exist")
        if p.is_dir() and not directory:
            raise ParameterError(f"{name}: {str(path)!r} is a directory, expected a file name")
        if named_fifo(p):
            raise ParameterError(f"{name}: {str(path)!r} is a FIFO (named pipe), which waits "
                                 "for a reader for ever; expected a regular file")
        try:
            max_name = os.pathconf(parent, "PC_NAME_MAX")
        except (OSError, ValueError, AttributeError):
            max_name = 255
        if len(os.fsencode(p.name)) + 24 > max_name:  # room for the temporary's prefix
            raise ParameterError(f"{name}: file name too long ({len(p.name)} characters; the "
                                 f"file system allows {max_name})")
        fd, tmp = tempfile.mkstemp(dir=parent, prefix=TEMP_PREFIX + "probe-")
        os.close(fd)
        with contextlib.suppress(OSError):
            os.unlink(tmp)
    except OSError as exc:
        raise ParameterError(f"{name}: cannot write {str(path)!r}: {_reason(exc)}") from None
    return p
