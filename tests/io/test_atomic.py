"""io/atomic.py: a file is either the old one or the complete new one."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap

import pytest

from wovenimpact.io.atomic import atomic_path, atomic_write_bytes, atomic_write_text


def test_write_bytes_and_text(tmp_path):
    p = tmp_path / "a.bin"
    atomic_write_bytes(p, b"\x00\x01")
    assert p.read_bytes() == b"\x00\x01"
    atomic_write_text(p, "héllo\n")
    assert p.read_text(encoding="utf-8") == "héllo\n"
    assert os.listdir(tmp_path) == ["a.bin"]


def test_atomic_path_is_a_sibling_with_the_same_suffix(tmp_path):
    target = tmp_path / "out.vtu"
    with atomic_path(target) as tmp:
        assert tmp.parent == tmp_path and tmp.suffix == ".vtu" and tmp != target
        assert tmp.exists() and not target.exists()
        tmp.write_text("new")
    assert target.read_text() == "new" and not tmp.exists()


def test_failure_keeps_the_old_file_and_removes_the_temporary(tmp_path):
    target = tmp_path / "keep.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("writer failed")
    assert target.read_text() == "old"
    assert os.listdir(tmp_path) == ["keep.txt"]


def test_mode_follows_the_umask(tmp_path):
    p = tmp_path / "m.txt"
    atomic_write_text(p, "x")
    umask = os.umask(0)
    os.umask(umask)
    assert p.stat().st_mode & 0o777 == 0o666 & ~umask


@pytest.mark.skipif(sys.platform == "win32", reason="SIGKILL")
def test_a_killed_writer_leaves_the_old_file(tmp_path):
    target = tmp_path / "data.txt"
    target.write_text("old complete")
    code = textwrap.dedent(f"""
        import os, signal
        from wovenimpact.io.atomic import atomic_path
        with atomic_path({str(target)!r}) as tmp:
            with open(tmp, "w") as f:
                f.write("partial")
                f.flush()
            os.kill(os.getpid(), signal.SIGKILL)
    """)
    r = subprocess.run([sys.executable, "-c", code], check=False)
    assert r.returncode == -signal.SIGKILL
    assert target.read_text() == "old complete"
