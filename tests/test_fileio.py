"""Output files: atomic, umask-respecting, no temporaries left, one typed one-line error."""

import errno
import os
import stat

import numpy as np
import pytest
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from parapend import fileio
from parapend.errors import OutputError, ParameterError
from parapend.fileio import save_figure, write_bytes, write_dataset, write_text


@pytest.fixture
def mask():
    """Set the umask for one test and restore it afterwards."""
    old = os.umask(0o022)
    os.umask(old)

    def set_mask(m):
        os.umask(m)
        return m

    yield set_mask
    os.umask(old)


def _mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


def _temporaries(directory):
    return [p.name for p in directory.iterdir() if p.name.startswith(".tmp")]


def _figure():
    fig = Figure(figsize=(3, 2))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.plot(np.linspace(0, 1, 50), np.sin(np.linspace(0, 6, 50)), label=r"$\theta$")
    ax.fill_between([0, 0.5], [0, 0], [1, 1], alpha=0.2)  # clip paths: ids in SVG
    ax.legend()
    ax.set_title(r"$\gamma \to 0$")
    return fig


@pytest.mark.parametrize("umask, expected", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_new_file_gets_umask_mode(tmp_path, mask, umask, expected):
    mask(umask)
    assert fileio.umask() == umask
    p = write_text(tmp_path / "a.csv", "x\n")
    assert p.read_text() == "x\n" and _mode(p) == expected


@pytest.mark.parametrize("umask, expected", [(0o022, 0o644), (0o077, 0o600)])
def test_replaced_file_gets_umask_mode(tmp_path, mask, umask, expected):
    p = tmp_path / "a.json"
    p.write_text("old")
    os.chmod(p, 0o640)
    mask(umask)
    write_bytes(p, b"new")
    assert p.read_bytes() == b"new" and _mode(p) == expected
    assert _temporaries(tmp_path) == []


def test_every_writer_respects_umask(tmp_path, mask):
    mask(0o022)
    ds = xr.Dataset({"power": ("damping", np.arange(3.0))}, coords={"damping": [0.0, 0.1, 0.2]})
    files = [write_dataset(ds, tmp_path / "d.nc"), save_figure(_figure(), tmp_path / "f.png"),
             save_figure(_figure(), tmp_path / "f.svg"), save_figure(_figure(), tmp_path / "f.pdf")]
    assert [_mode(f) for f in files] == [0o644] * 4
    with xr.open_dataset(tmp_path / "d.nc") as back:
        assert back["power"].values.tolist() == [0.0, 1.0, 2.0]
    assert _temporaries(tmp_path) == []


def test_umask_is_read_without_changing_it(mask):
    mask(0o027)
    assert fileio.umask() == 0o027
    assert os.umask(0o027) == 0o027


@pytest.mark.parametrize("exc", [KeyboardInterrupt, RuntimeError("disk on fire"), OSError(
    errno.EIO, "Input/output error")])
def test_interrupted_write_leaves_no_temporary_and_old_file(tmp_path, exc):
    p = tmp_path / "fig.png"
    p.write_bytes(b"old")

    def fail(name):
        with open(name, "wb") as fh:
            fh.write(b"half")
        raise exc

    expected = OutputError if isinstance(exc, OSError) else (
        exc if isinstance(exc, type) else type(exc))
    with pytest.raises(expected):
        fileio._atomic(p, fail)
    assert p.read_bytes() == b"old"
    assert _temporaries(tmp_path) == []


def test_interrupted_figure_leaves_no_temporary(tmp_path, monkeypatch):
    def boom(name):
        raise KeyboardInterrupt

    monkeypatch.setattr(xr.Dataset, "to_netcdf", lambda self, name, **kw: boom(name))
    with pytest.raises(KeyboardInterrupt):
        write_dataset(xr.Dataset(), tmp_path / "x.nc")
    assert list(tmp_path.iterdir()) == []


def test_temporary_name_is_hidden_and_recognizable(tmp_path):
    seen = []

    def spy(name):
        seen.append(os.path.basename(name))
        with open(name, "wb") as fh:
            fh.write(b"x")

    fileio._atomic(tmp_path / "t.svg", spy)
    assert seen[0].startswith(".tmp-parapend-") and seen[0].endswith(".svg")


def _one_line(err: OutputError, path: str):
    msg = str(err)
    assert "\n" not in msg and path in msg
    return msg


@pytest.mark.parametrize("path, reason", [
    ("/proc/x.csv", "No such file or directory"),
    ("/sys/x.png", ""),  # permission denied or read-only, depending on the kernel
    ("/nonexistent-dir/x.json", "No such file or directory"),
])
def test_unwritable_destinations(path, reason):
    if not os.path.isdir(os.path.dirname(path)) and "nonexistent" not in path:
        pytest.skip(f"{os.path.dirname(path)} does not exist here")
    with pytest.raises(OutputError) as info:
        write_text(path, "x")
    assert reason in _one_line(info.value, path)
    assert isinstance(info.value, ParameterError)  # the CLI's one-line, exit-2 handler


def test_name_too_long(tmp_path):
    path = tmp_path / ("x" * 300 + ".csv")
    with pytest.raises(OutputError, match="File name too long"):
        write_text(path, "x")
    assert _temporaries(tmp_path) == []


def test_full_disk_dev_full():
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full")
    with pytest.raises(OutputError, match="No space left on device") as info:
        write_bytes("/dev/full", b"x" * 100_000)
    _one_line(info.value, "/dev/full")
    assert stat.S_ISCHR(os.stat("/dev/full").st_mode)  # a device is written, never replaced


def test_full_disk_simulated(tmp_path, monkeypatch):
    """ENOSPC while writing a regular file: typed error, no temporary, old file intact."""
    p = tmp_path / "r.json"
    p.write_text("old")
    real_open = open

    class Full:
        def __init__(self, fh):
            self.fh = fh

        def __enter__(self):
            return self

        def __exit__(self, *a):
            self.fh.close()

        def write(self, data):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr("builtins.open", lambda name, mode="r", *a, **k: Full(
        real_open(name, mode, *a, **k)) if "w" in mode else real_open(name, mode, *a, **k))
    with pytest.raises(OutputError, match="No space left on device"):
        write_text(p, "new")
    monkeypatch.undo()
    assert p.read_text() == "old" and _temporaries(tmp_path) == []


def test_read_only_directory(tmp_path, monkeypatch):
    if os.geteuid() != 0:
        ro = tmp_path / "ro"
        ro.mkdir()
        os.chmod(ro, 0o555)
        try:
            with pytest.raises(OutputError, match="Permission denied"):
                write_text(ro / "x.csv", "x")
        finally:
            os.chmod(ro, 0o755)
    # root ignores directory modes: simulate a read-only file system
    def erofs(*a, **k):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS))

    monkeypatch.setattr(fileio.tempfile, "mkstemp", erofs)
    with pytest.raises(OutputError, match="Read-only file system"):
        write_text(tmp_path / "x.csv", "x")


def test_exception_without_strerror_is_reported():
    err = fileio.output_error("a b.csv", UnicodeEncodeError("ascii", "é", 0, 1, "bad"))
    assert str(err).startswith("cannot write 'a b.csv': ") and "\n" not in str(err)
    assert "Exception" in str(fileio.output_error("x", Exception()))
    assert "2 lines" in str(fileio.output_error("x\ny", OSError(5, "2\nlines")))


def test_directory_and_empty_name_refused(tmp_path):
    with pytest.raises(OutputError, match="Is a directory"):
        write_text(tmp_path, "x")
    with pytest.raises(OutputError, match="empty"):
        write_text("", "x")


def test_symlink_target_is_replaced_link_kept(tmp_path):
    real = tmp_path / "real.csv"
    real.write_text("old")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    write_text(link, "new")
    assert link.is_symlink() and real.read_text() == "new"


def test_figure_formats(tmp_path):
    with pytest.raises(ParameterError, match=r"\.png, \.svg or \.pdf"):
        save_figure(_figure(), tmp_path / "f.jpg")
    png = save_figure(_figure(), tmp_path / "f.png").read_bytes()
    assert png.startswith(b"\x89PNG")
    assert save_figure(_figure(), tmp_path / "f.pdf").read_bytes().startswith(b"%PDF")
    assert b"<svg" in save_figure(_figure(), tmp_path / "f.SVG").read_bytes()


def test_png_is_200_dpi(tmp_path):
    from PIL import Image

    with Image.open(save_figure(_figure(), tmp_path / "f.png")) as im:
        assert round(im.info["dpi"][0]) == 200


@pytest.mark.parametrize("fmt", ["svg", "png", "pdf"])
def test_figures_are_byte_identical_between_runs(tmp_path, fmt):
    a = save_figure(_figure(), tmp_path / f"a.{fmt}").read_bytes()
    b = save_figure(_figure(), tmp_path / f"b.{fmt}").read_bytes()
    assert a == b
    if fmt == "svg":
        assert b"<dc:date>" not in a


def test_style_is_not_global(tmp_path):
    import matplotlib

    before = {k: v for k, v in matplotlib.rcParams.items() if k != "backend"}
    import parapend.plotting  # noqa: F401  (importing must not change rcParams)

    save_figure(_figure(), tmp_path / "f.svg")
    parapend.plotting.plot_square_approximations(1.8, (0.1,))
    after = {k: v for k, v in matplotlib.rcParams.items() if k != "backend"}
    assert after == before


def test_cli_reports_unwritable_figure_in_one_line(capsys):
    from parapend.cli import main

    assert main(["figure", "8", "--plot", "/proc/x.png"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot write '/proc/x.png'" in err
