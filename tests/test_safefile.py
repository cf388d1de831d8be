"""Files inside an output folder are never opened through a link (tslip._safefile)."""

from __future__ import annotations

import os

import pytest

from tslip._safefile import UnsafePath, folder, open_below

APPEND = os.O_WRONLY | os.O_APPEND | os.O_CREAT
PRECIOUS = b"# the user's shell profile\nexport A=1\nno newline at the end"


def _target(tmp_path):
    t = tmp_path / "elsewhere" / "profile"
    t.parent.mkdir()
    t.write_bytes(PRECIOUS)
    return t


def test_a_plain_file_and_its_missing_folders_are_created(tmp_path):
    out = tmp_path / "out"
    fd = open_below(out, out / "cache" / "sub" / "f.jsonl", APPEND)
    os.write(fd, b"x\n")
    os.close(fd)
    assert (out / "cache" / "sub" / "f.jsonl").read_bytes() == b"x\n"
    assert folder(out, out / "cache") == out / "cache"


def test_the_output_folder_itself_may_be_a_link(tmp_path):
    (tmp_path / "real").mkdir()
    (tmp_path / "out").symlink_to(tmp_path / "real")
    os.close(open_below(tmp_path / "out", tmp_path / "out" / "a" / "f", APPEND))
    assert (tmp_path / "real" / "a" / "f").is_file()


@pytest.mark.parametrize("flags", [APPEND, os.O_RDWR | os.O_CREAT, os.O_RDWR, os.O_RDONLY])
def test_a_file_that_is_a_link_is_refused_and_its_target_untouched(tmp_path, flags):
    target = _target(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    (out / "f").symlink_to(target)
    with pytest.raises(UnsafePath, match=r"^refusing to write through .*out/f: it is a symbolic "
                                         r"link; remove it or choose another output folder$"):
        open_below(out, out / "f", flags)
    assert target.read_bytes() == PRECIOUS


def test_a_dangling_link_is_refused_and_nothing_is_created(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "f").symlink_to(tmp_path / "nowhere")
    with pytest.raises(UnsafePath, match="symbolic link"):
        open_below(out, out / "f", APPEND)
    assert not (tmp_path / "nowhere").exists()


@pytest.mark.parametrize("depth", [1, 2])
def test_a_folder_below_the_output_folder_that_is_a_link_is_refused(tmp_path, depth):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "out"
    above = out / "a" if depth == 2 else out
    above.mkdir(parents=True)
    (above / "cache").symlink_to(elsewhere)
    with pytest.raises(UnsafePath, match=r"cache: it is a symbolic link"):
        open_below(out, above / "cache" / "f.jsonl", APPEND)
    with pytest.raises(UnsafePath, match=r"cache: it is a symbolic link"):
        folder(out, above / "cache")
    assert list(elsewhere.iterdir()) == []


def test_a_fifo_and_a_hard_link_are_refused_without_blocking(tmp_path):
    target = _target(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    os.mkfifo(out / "fifo")
    with pytest.raises(UnsafePath, match="not a regular file"):
        open_below(out, out / "fifo", APPEND)  # would block for a reader if opened plainly
    os.link(target, out / "hard")
    with pytest.raises(UnsafePath, match="hard link"):
        open_below(out, out / "hard", os.O_RDWR)
    assert target.read_bytes() == PRECIOUS


def test_a_path_outside_the_output_folder_is_refused(tmp_path):
    with pytest.raises(ValueError, match="not inside the output folder"):
        open_below(tmp_path / "out", tmp_path / "other" / "f", APPEND)
    with pytest.raises(ValueError, match="is the output folder"):
        open_below(tmp_path, tmp_path, APPEND)


def test_a_missing_file_without_create_is_file_not_found_and_creates_nothing(tmp_path):
    with pytest.raises(FileNotFoundError):
        open_below(tmp_path, tmp_path / "cache" / "f", os.O_RDONLY)
    assert not (tmp_path / "cache").exists()


@pytest.mark.parametrize("write", ["figure", "text"])
def test_a_figure_or_text_written_where_a_link_is_replaces_the_link(tmp_path, write):
    """save_figure and write_text (every CLI figure and the biped's multipliers.csv):
    a link at the path is replaced by a fresh file, its target keeps its bytes."""
    import matplotlib.pyplot as plt

    from tslip._io import save_figure, write_text

    target = tmp_path / "home" / ".profile"
    target.parent.mkdir()
    target.write_bytes(b"precious")
    path = tmp_path / "out" / ("fig.png" if write == "figure" else "multipliers.csv")
    path.parent.mkdir()
    path.symlink_to(target)
    if write == "figure":
        fig = plt.figure()
        save_figure(fig, path, dpi=20)
        plt.close(fig)
        assert path.read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    else:
        write_text(path, "index,abs\n0,0.5\n")
        assert path.read_text() == "index,abs\n0,0.5\n"
    assert not path.is_symlink() and target.read_bytes() == b"precious"
    assert sorted(os.listdir(path.parent)) == [path.name]  # no temporary file left


def test_the_commands_write_files_only_through_the_atomic_writers():
    """No command writes a figure or a text file directly (that follows a link at the
    path): every write in ``tslip/cli`` goes through :mod:`tslip._io`."""
    from pathlib import Path

    import tslip.cli

    direct = [f"{p.name}:{i}" for p in sorted(Path(tslip.cli.__file__).parent.glob("*.py"))
              for i, line in enumerate(p.read_text().splitlines(), 1)
              if ".savefig(" in line or ".write_text(" in line or ".write_bytes(" in line]
    assert not direct, direct
