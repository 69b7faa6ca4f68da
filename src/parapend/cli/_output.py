"""Every file the command line writes goes through this module.

Kept thin on purpose: the functions here are the one place to rewire when file writing
changes (e.g. umask-respecting atomic writes in ``parapend.fileio``). A failure to write
(read-only or pseudo file system, full disk, permission) becomes an :class:`OutputError`
with one line naming the file; the command line prints it and exits with code 1.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["OutputError", "probe_dir", "save_figure", "write_dataset", "write_text"]


class OutputError(OSError):
    """An output file or directory could not be written; the message is one line."""


def _fail(path, exc: BaseException) -> OutputError:
    text = str(exc).strip()
    why = getattr(exc, "strerror", None) or (text.splitlines()[0] if text else
                                              type(exc).__name__)
    return OutputError(f"cannot write {str(path)!r}: {why}")


def probe_dir(directory) -> None:
    """Create and remove a temporary file in ``directory``: fail before any long work if it
    cannot be written (``/proc``, ``/sys``, a read-only mount, no permission)."""
    d = Path(directory) if str(directory) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(dir=d, prefix=".parapend-probe-")
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise OutputError(f"cannot create files in directory {str(d)!r}: "
                          f"{exc.strerror or exc}") from None


def write_text(path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file (an old file is never half-written)."""
    p = Path(path)
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(dir=p.parent if str(p.parent) else ".", prefix=".tmp-")
        with os.fdopen(fd, "w", newline="") as fh:
            fh.write(text)
        os.replace(tmp, p)
    except OSError as exc:
        raise _fail(p, exc) from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)


def write_dataset(ds, path) -> None:
    """Write a Dataset to NetCDF through a temporary file (an old file is never half-written)."""
    p = Path(path)
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(dir=p.parent if str(p.parent) else ".", prefix=".tmp-",
                                   suffix=".nc")
        os.close(fd)
        ds.to_netcdf(tmp)
        os.replace(tmp, p)
    except (OSError, RuntimeError) as exc:  # netCDF4/h5py report a full disk as RuntimeError
        raise _fail(p, exc) from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)


def save_figure(fig, path) -> None:
    """Save a matplotlib figure by extension (PNG, SVG, PDF) via :mod:`parapend.plotting`."""
    from ..plotting import save_figure as _save

    try:
        _save(fig, path)
    except OSError as exc:
        raise _fail(path, exc) from None


def plot(func, data, path) -> None:
    """Draw ``func(data, path)`` (a :mod:`parapend.plotting` function that saves to ``path``)."""
    try:
        func(data, path)
    except OSError as exc:
        raise _fail(path, exc) from None
