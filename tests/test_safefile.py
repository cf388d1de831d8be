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
