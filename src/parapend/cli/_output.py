"""Every file the command line writes goes through this module, and from here through
:mod:`parapend.fileio`: atomic replacement, the user's umask, no temporaries left behind.

A failure to write (read-only or pseudo file system, full disk, permission, a name too long)
is an :class:`~parapend.errors.OutputError` with one line naming the file; the command line
prints it and exits with code 1 (a path refused before any work, by
:func:`~parapend.cli._common._check_output`, exits with code 2).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from .. import fileio
from ..errors import OutputError

__all__ = ["OutputError", "plot", "probe_dir", "save_figure", "save_plot", "save_result",
           "write_dataset",
           "write_text"]


def probe_dir(directory, target=None) -> None:
    """Create and remove a temporary file in ``directory``: fail before any long work if it
    cannot be written (``/proc``, ``/sys``, a read-only mount, no permission). ``target``,
    the file to be written there, is named in the message."""
    d = Path(directory) if str(directory) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(dir=d, prefix=fileio.TEMP_PREFIX + "probe-")
        os.close(fd)
        with contextlib.suppress(OSError):
            os.unlink(tmp)
    except OSError as exc:
        what = (f"cannot write {str(target)!r}" if target is not None
                else f"cannot create files in directory {str(d)!r}")
        raise OutputError(f"{what}: {exc.strerror or exc}") from None


def write_text(path, text: str) -> None:
    """Write ``text`` to ``path`` atomically (:func:`parapend.fileio.write_text`)."""
    fileio.write_text(path, text)


def write_columns(path, columns: dict) -> None:
    """Write equal-length columns as CSV (header = the keys, values as ``repr(float)``: they
    read back exactly) atomically."""
    import csv
    import io

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(list(columns))
    for row in zip(*columns.values()):
        w.writerow([repr(float(v)) for v in row])
    write_text(path, buf.getvalue())


def write_dataset(ds, path) -> None:
    """Write a Dataset to NetCDF atomically (:func:`parapend.fileio.write_dataset`)."""
    fileio.write_dataset(ds, path)


def save_figure(fig, path) -> None:
    """Save a figure by extension, PNG, SVG or PDF (:func:`parapend.fileio.save_figure`)."""
    fileio.save_figure(fig, path)


def plot(func, data, path, units=None) -> None:
    """Draw ``func(data, path)`` (a :mod:`parapend.plotting` function that saves to ``path``);
    with ``units`` (:class:`parapend.units.Units`), ``func(data, None)`` and SI axes beside
    the non-dimensional ones (:func:`parapend.units.si_figure`) before saving."""
    try:
        if units is not None:
            from ..units import si_figure

            save_figure(si_figure(func(data, None), units), path)
            return
        func(data, path)
    except OutputError:
        raise
    except OSError as exc:
        raise fileio.output_error(path, exc) from None


def save_plot(result, path) -> None:
    """Draw ``result.plot()`` (:meth:`parapend.results.Result.plot`) into ``path`` (PNG, SVG
    or PDF by extension), atomically."""
    try:
        save_figure(result.plot(), path)
    except OutputError:
        raise
    except OSError as exc:
        raise fileio.output_error(path, exc) from None


def save_result(result, path) -> None:
    """Write ``result`` to ``path`` by its extension (:meth:`parapend.results.Result.save`);
    an operating-system failure is an :class:`OutputError` naming the file."""
    try:
        result.save(path)
    except OutputError:
        raise
    except OSError as exc:
        raise fileio.output_error(path, exc) from None
