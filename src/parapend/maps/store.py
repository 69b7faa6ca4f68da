"""The Zarr store of a sweep: its layout and attributes, the creation behind a "being
created" marker, the lock, the check of a store against its sweep (:func:`_verify`) and
:func:`open_sweep`; see the package text ("The store").
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import os
import shutil
import stat
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..fileio import TEMP_PREFIX
from .spec import _AXIS_ATTRS, _CODE, _SUCCESS, AXES, NOT_COMPUTED, STATUSES, VARIABLES, SweepSpec

__all__ = ["open_sweep"]


# -- the store -----------------------------------------------------------------------------

def _attrs(spec: SweepSpec, command: str | None) -> dict:
    from .. import __version__

    a = {"title": "parapend design map", "parapend_version": __version__,
         "command": command or "parapend.sweep()", "sweep": spec.to_json(),
         "excitation": spec.excitation, "harmonics": spec.harmonics,
         "conventions": "theta'' + gamma theta' - (1 + q(t)) sin(theta) = T(t), theta from "
                        "the upright; P = -<T theta'> > 0 is harvested (docs/design.md)"}
    if spec.excitation == "square":
        a["square_alpha"] = "default" if spec.square_alpha is None else spec.square_alpha
    if spec.excitation == "fourier":
        a["fourier"] = str(spec.fourier)
    return a


def _var_attrs(name: str, spec: SweepSpec | None = None) -> dict:
    long, units = VARIABLES[name] if spec is None else spec.attrs(name)
    a = {"long_name": long}
    if units:
        a["units"] = units
    if name.endswith("status"):
        a.update(flag_values=list(range(len(STATUSES))), flag_meanings=" ".join(STATUSES),
                 comment="-1: not computed; success: converged or no_power")
    return a


def _template(spec: SweepSpec, command: str | None):
    """The whole store as a lazy Dataset (dask arrays of fill values) and its encoding."""
    own = getattr(spec, "template", None)  # another product on the engine (a power matrix)
    if own is not None:
        return own(command)
    import dask.array as da
    import xarray as xr
    from zarr.codecs import ZstdCodec

    dims, shape, chunks = spec.dims, spec.shape, spec.chunks
    data, enc = {}, {}
    for v in (*spec.variables, "done"):
        if v == "done":
            arr = da.zeros(shape, dtype=bool, chunks=chunks)
            fill = False
            attrs = {"long_name": "block finished (written after the block's data)"}
        elif v.endswith("status"):
            arr = da.full(shape, NOT_COMPUTED, dtype=np.int8, chunks=chunks)
            fill, attrs = NOT_COMPUTED, _var_attrs(v)
        else:
            arr = da.full(shape, np.nan, dtype=float, chunks=chunks)
            fill, attrs = np.nan, _var_attrs(v, spec)
        data[v] = (dims, arr, attrs)
        # zstd with its checksum: a chunk altered on disk fails to decode (found by _verify)
        enc[v] = {"chunks": chunks, "fill_value": fill,
                  "compressors": (ZstdCodec(level=0, checksum=True),)}
    coords = {}
    for a in AXES:
        vals = spec.values[a]
        long, units = _AXIS_ATTRS[a]
        if len(vals) >= 2:
            coords[a] = (a, np.array(vals), {"long_name": long, "units": units})
        elif len(vals) == 1:
            coords[a] = ((), vals[0], {"long_name": long, "units": units})
    ds = xr.Dataset(data, coords=coords, attrs=_attrs(spec, command))
    return ds, enc


@contextlib.contextmanager
def _locked(path: Path):
    """An exclusive, non-blocking ``flock`` on the store's directory for the sweep's time."""
    import fcntl

    fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise ParameterError(f"store: {str(path)!r} is being written by another parapend "
                                 "sweep; wait for it to finish or choose another --store") \
                from None
        yield
    finally:
        os.close(fd)  # releases the lock


@contextlib.contextmanager
def _quiet_zarr():
    """Zarr warns about foreign files (a ``.partial`` left by a killed write): they are
    removed on resume, and a reader need not see the warning."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Object at .* is not recognized")
        yield


#: The title every sweep store carries in its root attributes.
_TITLE = "parapend design map"
#: ``parapend_store`` of the root ``zarr.json`` a sweep writes first into a store it creates
#: (see :func:`_prepare`): the directory is parapend's, and its creation has not finished.
_CREATING = "creating"
#: A temporary directory that an earlier version's store creation left beside the store
#: (``kill -9``) is removed once it is this old (seconds): a creation takes well under one.
_STALE_SECONDS = 600


def _own_names(spec=None) -> set:
    """The names a sweep (or a power matrix) writes at the top of its store (its
    temporaries aside): either may replace the other's store with ``--overwrite``."""
    from ..performance.spec import STORE_NAMES

    return {*VARIABLES, "done", *AXES, "zarr.json", *STORE_NAMES,
            *getattr(spec, "names", ()), *getattr(spec, "variables", ())}


def _short(err: BaseException) -> str:
    return " ".join(str(err).split())[:160] or type(err).__name__


def _root_attrs(path: Path) -> dict | None:
    """The attributes of the Zarr 3 group whose ``zarr.json`` is in ``path``, or None."""
    try:
        meta = json.loads((path / "zarr.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(meta, dict) or meta.get("node_type") != "group":
        return None
    attrs = meta.get("attributes")
    return attrs if isinstance(attrs, dict) else None


def _identify(path: Path) -> tuple[str, str | None]:
    """What the directory ``path`` holds, by what parapend itself writes there: ``("store",
    identity)`` for a sweep store (root attributes with the title and the sweep's identity),
    ``("creating", None)`` for a creation that did not finish (the root ``zarr.json`` that
    :func:`_prepare` writes first), ``("empty", None)`` when it holds nothing but parapend's
    temporaries, else ``("foreign", None)``."""
    attrs = _root_attrs(path)
    if attrs is not None and attrs.get("parapend_store") == _CREATING:
        return "creating", None
    if attrs is not None and attrs.get("title") == _TITLE and isinstance(attrs.get("sweep"),
                                                                         str):
        return "store", attrs["sweep"]
    if all(e.name.startswith(TEMP_PREFIX) for e in path.iterdir()):
        return "empty", None
    return "foreign", None


def _store_spec(path: Path) -> str | None:
    """The sweep identity recorded in a store's root metadata, or None."""
    try:
        return _identify(path)[1]
    except OSError:
        return None


def stored_points(spec, store, overwrite: bool = False) -> int:
    """How many of ``spec``'s points the store ``store`` holds finished and sound (0: none,
    no store, another sweep's, ``overwrite``, or one that cannot be read): what a rerun
    resumes, for its announced estimate. Read-only and unlocked, by the run's own check
    (:func:`_verify`: a file that cannot be a chunk is never read)."""
    if store is None or overwrite:
        return 0
    path = Path(store)
    if not path.is_dir() or _store_spec(path) != spec.to_json():
        return 0
    try:
        done, _ = _verify(path, spec)
    except (ParameterError, OSError):  # the run says what is wrong
        return 0
    return sum(int(np.prod([s.stop - s.start for s in spec.block_slices(b)]))
               for b in range(spec.blocks) if done[b])


def _refuse_other(path: Path, spec: SweepSpec, overwrite: bool) -> str:
    """What ``path`` holds (:func:`_identify`'s kind), after refusing a directory that is not
    parapend's, and a store of another sweep unless ``overwrite``."""
    kind, recorded = _identify(path)
    if kind == "foreign":
        raise ParameterError(f"store: {str(path)!r} exists and is not a parapend sweep store "
                             "(parapend never deletes such a directory, --overwrite or not); "
                             "choose another --store")
    if kind == "store" and not overwrite and recorded != spec.to_json():
        raise ParameterError(f"store: {str(path)!r} holds a different sweep (other axes, "
                             "excitation, harmonics or threshold, or an efficiency map "
                             "or a hull's record optimum of an earlier version); "
                             "choose another --store, or --overwrite to replace it")
    return kind


def check_resumable(spec, store, overwrite: bool = False) -> None:
    """Refuse, before any work is announced, a ``store`` that the run would refuse when it
    opens it: a directory that is not parapend's, or a store of another sweep (unless
    ``overwrite``). Read-only and unlocked; the run checks again under its lock."""
    if store is None:
        return
    path = Path(store)
    try:
        if path.is_dir():
            _refuse_other(path, spec, overwrite)
    except OSError:  # unreadable: the run's own check of the path says so
        pass


def _write_marker(path: Path) -> None:
    """Make the root ``zarr.json`` of ``path`` say "a parapend store being created", atomically
    (a temporary beside it, then a rename): from then on the directory is recognised as
    parapend's, whatever interrupts the creation."""
    meta = {"zarr_format": 3, "node_type": "group",
            "attributes": {"title": _TITLE, "parapend_store": _CREATING}}
    fd, tmp = tempfile.mkstemp(prefix=TEMP_PREFIX, dir=path)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(json.dumps(meta))
        os.replace(tmp, path / "zarr.json")
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _create(path: Path, spec: SweepSpec, command: str | None) -> None:
    """Write the whole layout into a temporary directory inside the store (so that a
    ``kill -9`` leaves it where the next run on the store removes it), then move its entries
    in, the root ``zarr.json`` last: a store whose root attributes hold the sweep is
    complete."""
    ds, enc = _template(spec, command)
    tmp = Path(tempfile.mkdtemp(prefix=TEMP_PREFIX, dir=path))
    try:
        ds.to_zarr(tmp, mode="w-", compute=False, encoding=enc, consolidated=False,
                   zarr_format=3)
        names = sorted(e.name for e in tmp.iterdir() if e.name != "zarr.json")
        for name in names:
            os.replace(tmp / name, path / name)
        os.replace(tmp / "zarr.json", path / "zarr.json")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _remove(entry: Path) -> None:
    if entry.is_dir() and not entry.is_symlink():
        shutil.rmtree(entry)
    else:
        entry.unlink()


def _remove_stale_temps(parent: Path) -> None:
    """Remove the temporary directories that an earlier version's store creation, killed,
    left beside a store: named ``.tmp-parapend-*``, directories (parapend's other
    temporaries are files), holding nothing but a store's entries (and a root ``zarr.json``
    with a sweep store's title, if any) and untouched for ten minutes."""
    own, now = _own_names(), time.time()
    try:
        entries = [e for e in parent.iterdir() if e.name.startswith(TEMP_PREFIX)]
    except OSError:
        return
    for e in entries:
        try:
            if e.is_symlink() or not e.is_dir() or now - e.stat().st_mtime < _STALE_SECONDS:
                continue
            names = {c.name for c in e.iterdir()}
            if not names or not names <= own:
                continue
            if "zarr.json" in names and (_root_attrs(e) or {}).get("title") != _TITLE:
                continue
            shutil.rmtree(e)
        except OSError:
            continue


def _prepare(path: Path, spec: SweepSpec, command: str | None, overwrite: bool) -> None:
    """Under the lock: create the store, or check that it holds this sweep (resume).

    Only a directory that parapend recognises as its own (a sweep store, a creation cut short,
    or an empty directory) is ever emptied: anything else is refused, ``--overwrite`` or
    not, and so is a store that also holds files parapend did not write."""
    _remove_stale_temps(path.parent if str(path.parent) else Path("."))
    kind = _refuse_other(path, spec, overwrite)
    if kind == "store" and not overwrite:
        for p in path.rglob("*.partial"):  # a chunk write cut short by kill -9
            with contextlib.suppress(OSError):
                p.unlink()
        return
    # an empty directory, a creation cut short, or --overwrite of a sweep store: emptied,
    # after its root says "being created", and only of the names a sweep writes
    own = _own_names(spec)
    entries = list(path.iterdir())
    extra = sorted(e.name for e in entries
                   if e.name not in own and not e.name.startswith(TEMP_PREFIX))
    extra += _foreign_inside(path, [e for e in entries if e.name in own and e.is_dir()
                                    and not e.is_symlink()])
    if extra:
        raise ParameterError(f"store: {str(path)!r} also holds {extra[0]!r}, which parapend "
                             "did not write; move it away or choose another --store")
    _write_marker(path)
    for e in entries:
        if e.name != "zarr.json":
            with contextlib.suppress(FileNotFoundError):
                _remove(e)
    _create(path, spec, command)


def _foreign_inside(path: Path, arrays) -> list[str]:
    """Files inside the array directories ``arrays`` that a sweep does not write (its own are
    ``zarr.json`` and the chunks: ``c`` of a scalar, under ``c/`` otherwise, ``.partial``
    writes cut short among them): a user's note in ``power/`` was deleted with the store."""
    out = []
    for a in arrays:
        for d, _, files in os.walk(a):
            rel = Path(d).relative_to(a).parts
            for f in files:
                if (not rel and f in ("zarr.json", "c")) or (rel and rel[0] == "c"):
                    continue
                out.append(str(Path(d, f).relative_to(path)))
    return sorted(out)


def _check_store_path(store) -> Path:
    if store is None or not str(store).strip():
        raise ParameterError("store: expected a directory name, e.g. map.zarr")
    path = Path(store)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise ParameterError(f"store: directory {str(parent)!r} does not exist")
    if path.exists() and not path.is_dir():
        raise ParameterError(f"store: {str(path)!r} is a file, expected a Zarr store "
                             "(a directory)")
    if path.is_symlink() and not path.exists():
        # a link to a store not made yet: the store is made where it points
        target = Path(os.path.realpath(path))
        if not target.parent.is_dir():
            raise ParameterError(f"store: {str(path)!r} is a link to {str(target)!r}, whose "
                                 "directory does not exist")
    return path


def make_store_dir(path: Path) -> None:
    """Make the store's directory (none if it exists); through a link to a directory not
    made yet, the directory it points to (``mkdir`` of the link itself says "File
    exists")."""
    if path.is_symlink() and not path.exists():
        Path(os.path.realpath(path)).mkdir(exist_ok=True)
    else:
        path.mkdir(exist_ok=True)


# -- verifying a store -----------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class _StoredSpec(SweepSpec):
    """A sweep read back from a store's identity: its chunks are the recorded ones."""

    stored_chunks: tuple = ()

    @property
    def chunks(self) -> tuple[int, ...]:
        return self.stored_chunks


def _spec_of(identity) -> SweepSpec | None:
    """The :class:`SweepSpec` (its layout) of a store's recorded identity, or None."""
    try:
        d = json.loads(identity)
        if isinstance(d, dict) and d.get("kind") == "power_matrix":
            from ..performance.spec import MatrixSpec

            return MatrixSpec.from_json(identity)
        if isinstance(d, dict) and d.get("kind") == "persistence":
            from ..dynamics._persist_spec import PersistenceSpec

            return PersistenceSpec.from_json(identity)
        values = {a: tuple(float(v) for v in d["axes"][a]) for a in AXES}
        spec = _StoredSpec(values, str(d["excitation"]), d["square_alpha"], d["fourier"],
                           int(d["harmonics"]), bool(d["threshold"]), None,
                           tuple(int(c) for c in d["chunks"]))
        ok = (len(spec.chunks) == len(spec.dims) >= 1
              and all(1 <= c <= n for c, n in zip(spec.chunks, spec.shape)))
    except (TypeError, ValueError, KeyError, AttributeError):
        return None
    return spec if ok else None


def _damaged(path: Path, what: str) -> ParameterError:
    return ParameterError(f"store: {str(path)!r} is damaged ({what}); compute it again with "
                          "parapend sweep --overwrite, or choose another --store")


def _expected(name: str):
    """dtype and fill value of a store's array."""
    if name == "done":
        return np.dtype(bool), False
    # mode, failure: the hull's power matrix's codes
    if name.endswith("status") or name in ("mode", "failure"):
        return np.dtype(np.int8), NOT_COMPUTED
    return np.dtype(float), math.nan


def _array(group, path: Path, spec: SweepSpec, name: str):
    """The store's array ``name``, checked against the sweep's layout."""
    import zarr

    try:
        a = group[name]
    except KeyError:
        raise _damaged(path, f"array {name!r} is missing") from None
    except Exception as err:  # noqa: BLE001 - metadata that cannot be read
        raise _damaged(path, f"array {name!r} is unreadable: {_short(err)}") from None
    dtype, fill = _expected(name)
    if not isinstance(a, zarr.Array):
        raise _damaged(path, f"{name!r} is not an array")
    try:
        same_fill = (math.isnan(a.fill_value) if isinstance(fill, float)
                     else a.fill_value == fill)
    except TypeError:
        same_fill = False
    if (np.dtype(a.dtype) != dtype or tuple(a.shape) != spec.shape
            or tuple(a.chunks) != spec.chunks or not same_fill):
        raise _damaged(path, f"array {name!r} is {np.dtype(a.dtype)} {list(a.shape)} in "
                             f"chunks {list(a.chunks)}, fill {a.fill_value}; expected {dtype} "
                             f"{list(spec.shape)} in chunks {list(spec.chunks)}, fill {fill}")
    return a


def _check_coords(group, path: Path, spec: SweepSpec) -> None:
    own = getattr(spec, "coordinates", None)
    wanted = (own() if own is not None else
              {a: (np.array(spec.values[a]) if len(spec.values[a]) >= 2
                   else np.array(spec.values[a][0])) for a in AXES if spec.values[a]})
    for a, want in wanted.items():
        try:
            got = np.asarray(group[a][...], dtype=float)
        except Exception as err:  # noqa: BLE001 - missing or unreadable
            raise _damaged(path, f"coordinate {a!r} is missing or unreadable: "
                                 f"{_short(err)}") from None
        if got.shape != want.shape or not np.array_equal(got, want):
            raise _damaged(path, f"coordinate {a!r} differs from the sweep's values")


def _read(a, name: str, spec: SweepSpec, blocks, skip=frozenset()) -> tuple[np.ndarray, set]:
    """All of array ``a`` and the blocks (of ``blocks``) whose chunk cannot be read: at
    once, or block by block when that fails or when some chunks must not be read at all
    (``skip``: not chunk files, :func:`_chunk_files`); the others hold the fill value."""
    if not skip:
        try:
            return np.asarray(a[...]), set()
        except Exception:  # noqa: BLE001 - a chunk that cannot be decoded: found below
            pass
    dtype, fill = _expected(name)
    out, bad = np.full(spec.shape, fill, dtype=dtype), set()
    for b in blocks:
        if b in skip:
            continue
        sl = spec.block_slices(b)
        try:
            out[sl] = a[sl]
        except Exception:  # noqa: BLE001 - recorded
            bad.add(b)
    return out, bad


def _chunk_bytes(name: str, spec: SweepSpec) -> int:
    """The most bytes a chunk of array ``name`` can take: its values uncompressed, zstd's
    worst-case expansion (under 1 %) and the frame and checksum."""
    raw = int(np.prod(spec.chunks)) * _expected(name)[0].itemsize
    return raw + raw // 64 + 4096


def _chunk_files(path: Path, name: str, limit: int) -> tuple[set, set]:
    """The chunk keys present in array ``name``'s directory (``c/0/3``, ...), and those of
    them that cannot be a chunk of this array and are never read: not a regular file (a
    link, a FIFO, a device: a link to /dev/zero was read until memory ran out) or larger
    than ``limit`` bytes (a 1 GB file took 2.2 GB to find undecodable)."""
    root = path / name
    out, bad = set(), set()
    for d, _, files in os.walk(root):
        rel = os.path.relpath(d, root)
        for f in files:
            if f != "zarr.json" and not f.endswith(".partial"):
                key = f if rel == "." else f"{rel}/{f}".replace(os.sep, "/")
                out.add(key)
                try:
                    st = os.lstat(os.path.join(d, f))
                except OSError:
                    bad.add(key)
                    continue
                if not stat.S_ISREG(st.st_mode) or st.st_size > limit:
                    bad.add(key)
    return out, bad


def _chunk_key(array, spec: SweepSpec, block: int) -> str:
    """The key (relative file name, ``c/0/3``) of a block's chunk in ``array``."""
    return array.metadata.encode_chunk_key(
        tuple(int(i) for i in np.unravel_index(block, spec.block_grid)))


def _verify(path: Path, spec: SweepSpec) -> tuple[np.ndarray, dict]:
    """Check a store against its sweep, cheaply: what a resume or a reader relies on.

    The arrays and coordinates must have the sweep's layout (else :class:`ParameterError`,
    one line). Then every block whose ``done`` mask is set must have every variable's chunk
    present (the data are written with ``write_empty_chunks``: a finished block has them
    all, NaN or not), decodable (zstd with a checksum), a status code at every point and a
    finite power where the status is a success. Returns ``done`` (per block: finished and
    sound) and ``damaged`` (block -> what is wrong), which includes blocks whose mask cannot
    be read.
    """
    import zarr

    nb = spec.blocks
    with _quiet_zarr():
        try:
            group = zarr.open_group(path, mode="r", zarr_format=3)
        except Exception as err:  # noqa: BLE001 - damaged root metadata
            raise _damaged(path, f"its root cannot be read: {_short(err)}") from None
        arrays = {v: _array(group, path, spec, v) for v in ("done", *spec.variables)}
        _check_coords(group, path, spec)
        keys = [_chunk_key(arrays["done"], spec, b) for b in range(nb)]
        block_of = {k: b for b, k in enumerate(keys)}
        # files that cannot be chunks are never read, whichever block they belong to
        foreign = {}
        for v in ("done", *spec.variables):
            present, bad = _chunk_files(path, v, _chunk_bytes(v, spec))
            foreign[v] = (present, {block_of[k] for k in bad if k in block_of})
        damaged = {b: f"{v}: not a chunk file" for v in reversed(("done", *spec.variables))
                   for b in foreign[v][1]}
        mask, unreadable = _read(arrays["done"], "done", spec, range(nb),
                                 skip=foreign["done"][1])
        damaged.update({b: "done: unreadable chunk" for b in unreadable})
        slices = [spec.block_slices(b) for b in range(nb)]
        done = np.array([b not in damaged and bool(mask[slices[b]].all()) for b in range(nb)],
                        dtype=bool)
        finished = np.flatnonzero(done).tolist()
        if not finished:
            return done, damaged
        values = {}
        for v in spec.variables:
            present, skip = foreign[v]
            for b in finished:
                if b not in damaged and keys[b] not in present:
                    damaged[b] = f"{v}: chunk missing"
            values[v], bad = _read(arrays[v], v, spec, [b for b in finished if b not in damaged],
                                   skip=skip | set(damaged))
            for b in sorted(bad):
                damaged.setdefault(b, f"{v}: chunk unreadable")
    success = [_CODE[s] for s in _SUCCESS]
    for b in finished:
        if b in damaged:
            continue
        sl = slices[b]
        for st_name, val_name in (("status", "power"),
                                  ("threshold_status", "damping_threshold")):
            if st_name not in values:
                continue
            st = values[st_name][sl]
            if not ((st >= 0) & (st < len(STATUSES))).all():
                damaged[b] = f"{st_name}: a point without a status"
            elif not np.isfinite(values[val_name][sl][np.isin(st, success)]).all():
                damaged[b] = f"{val_name}: NaN where the status is a success"
    for b in damaged:
        done[b] = False
    return done, damaged


def _damage_line(spec: SweepSpec, damaged: dict) -> str:
    points = sum(int(np.prod([s.stop - s.start for s in spec.block_slices(b)]))
                 for b in damaged)
    first = damaged[min(damaged)]
    return (f"{len(damaged)} of {spec.blocks} blocks ({points} points) marked finished have "
            f"missing or unreadable data ({first}{', ...' if len(damaged) > 1 else ''})")


def open_sweep(store, *, complete: bool = False):
    """Open a sweep store (Zarr directory, or a NetCDF export) as an ``xarray.Dataset``.

    A Zarr store is verified first (:func:`_verify`): a store whose creation did not finish,
    or one with missing or unreadable data in a finished block, is refused with one line
    (running the sweep again recomputes those blocks). ``complete=True`` also refuses a
    store whose ``done`` mask is not all set.
    """
    import xarray as xr

    path = Path(store)
    if not path.exists():
        raise ParameterError(f"store: {str(store)!r} does not exist")
    if path.is_dir():
        attrs = _root_attrs(path)
        if attrs is None or attrs.get("title") != _TITLE:
            raise ParameterError(f"store: {str(store)!r} is not a parapend sweep store (no "
                                 "readable zarr.json with a sweep's attributes)")
        if attrs.get("parapend_store") == _CREATING:
            raise ParameterError(f"store: {str(store)!r} was not created completely (the "
                                 "sweep was interrupted while creating it); run the sweep "
                                 "again")
        spec = _spec_of(attrs.get("sweep"))
        if spec is None:
            raise _damaged(path, "its sweep identity cannot be read")
        _, damaged = _verify(path, spec)
        if damaged:
            raise ParameterError(f"store: {str(store)!r} is damaged: "
                                 f"{_damage_line(spec, damaged)}; run the same sweep again "
                                 "(its 'command' attribute) to recompute them")
    try:
        if path.is_dir():
            with _quiet_zarr():
                ds = xr.open_zarr(path, consolidated=False, zarr_format=3).load()
        else:
            with xr.open_dataset(path) as f:
                ds = f.load()
    except Exception as err:  # noqa: BLE001 - any file that is not a readable sweep store
        raise ParameterError(f"store: cannot read {str(store)!r} as a sweep store: "
                             f"{_short(err)}") from None
    if "sweep" not in ds.attrs or "done" not in ds:
        raise ParameterError(f"store: {str(store)!r} is not a parapend sweep store")
    ds["done"] = ds["done"].astype(bool)
    if complete and not bool(ds["done"].all()):
        raise ParameterError(f"store: {str(store)!r} is not complete ({int(ds['done'].sum())} "
                             f"of {ds['done'].size} points); run the same sweep again to "
                             "finish it")
    return ds
