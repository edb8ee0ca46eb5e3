"""io/checkpoint.py: bitwise round trip, model digest check, corrupt files, keep policy."""

from __future__ import annotations

import zipfile

import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.io.checkpoint import latest_checkpoint, load_checkpoint, save_checkpoint
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.state import N_ENERGY, State

DIGEST = "a" * 64


def make_state(step: int = 7, seed: int = 0, n: int = 5, ne: int = 3) -> State:
    rng = np.random.default_rng(seed)
    return State(
        t=1.25e-6 * step + 1e-17, step=step, dt=np.nextafter(1e-7, 1.0),
        x=rng.standard_normal((n, 3)), v=rng.standard_normal((n, 3)),
        omega=rng.standard_normal((n, 3)), elem=rng.standard_normal((ne, SL.N_ELEM_STATE)),
        mat=np.array([[np.nan, -0.0, np.inf]] * ne), f_int=rng.standard_normal((n, 6)),
        f_ext=rng.standard_normal((n, 6)), node_active=np.array([1, 0, 1, 1, 1], np.int8),
        energy=rng.standard_normal(N_ENERGY),
    )


def test_round_trip_is_bitwise(tmp_path):
    s = make_state()
    path = save_checkpoint(tmp_path / "ck", s, DIGEST)
    assert path == tmp_path / "ck" / "checkpoint_000000007.npz"
    back = load_checkpoint(path, DIGEST)
    assert back.equals(s)
    assert isinstance(back.step, int) and isinstance(back.t, float)
    assert back.node_active.dtype == np.int8


def test_digest_is_stored_as_a_string_not_a_pickle(tmp_path):
    path = save_checkpoint(tmp_path, make_state(), DIGEST)
    with np.load(path, allow_pickle=False) as npz:
        d = npz["model_digest"]
    assert d.shape == () and d.dtype.kind == "U" and str(d) == DIGEST


def test_other_model_is_refused(tmp_path):
    path = save_checkpoint(tmp_path, make_state(), DIGEST)
    with pytest.raises(InputError) as err:
        load_checkpoint(path, "b" * 64)
    msg = str(err.value)
    assert str(path) in msg and "different model" in msg and "--restart" in msg


@pytest.mark.parametrize("damage", ["truncate", "garbage", "empty", "flip"])
def test_corrupt_file_is_named(tmp_path, damage):
    path = save_checkpoint(tmp_path, make_state(), DIGEST)
    data = path.read_bytes()
    if damage == "truncate":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "garbage":
        path.write_bytes(b"not a checkpoint at all")
    elif damage == "empty":
        path.write_bytes(b"")
    else:  # one byte of an array changed: the zip CRC check catches it
        with zipfile.ZipFile(path) as z:
            info = z.getinfo("x.npy")
        pos = info.header_offset + 30 + len(info.filename) + info.file_size - 1
        path.write_bytes(data[:pos] + bytes([data[pos] ^ 0xFF]) + data[pos + 1:])
    with pytest.raises(InputError) as err:
        load_checkpoint(path, DIGEST)
    assert str(path) in str(err.value)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="not found"):
        load_checkpoint(tmp_path / "checkpoint_000000001.npz", DIGEST)


def test_keep_policy_and_latest(tmp_path):
    assert latest_checkpoint(tmp_path) is None
    assert latest_checkpoint(tmp_path / "absent") is None
    for step in (10, 20, 30, 40):
        save_checkpoint(tmp_path, make_state(step), DIGEST, keep=2)
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["checkpoint_000000030.npz", "checkpoint_000000040.npz"]
    assert latest_checkpoint(tmp_path).name == "checkpoint_000000040.npz"
    save_checkpoint(tmp_path, make_state(50), DIGEST, keep=1)
    assert [p.name for p in tmp_path.iterdir()] == ["checkpoint_000000050.npz"]


def test_later_checkpoints_are_not_deleted(tmp_path):
    save_checkpoint(tmp_path, make_state(90), DIGEST)
    save_checkpoint(tmp_path, make_state(10), DIGEST, keep=1)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "checkpoint_000000010.npz", "checkpoint_000000090.npz"]


def test_other_files_are_ignored(tmp_path):
    (tmp_path / "checkpoint_notes.npz").write_text("x")
    (tmp_path / ".checkpoint_000000099-abc.tmp.npz").write_text("x")
    save_checkpoint(tmp_path, make_state(5), DIGEST)
    assert latest_checkpoint(tmp_path).name == "checkpoint_000000005.npz"


@pytest.mark.parametrize("keep", [0, -1, 1.5, True])
def test_keep_must_be_positive(tmp_path, keep):
    with pytest.raises(InputError, match="keep"):
        save_checkpoint(tmp_path, make_state(), DIGEST, keep=keep)


def test_a_checkpoint_without_a_later_array_is_refused_but_its_arrays_still_load(tmp_path):
    """A file written before ``contact_work`` existed: ``--restart`` refuses it (its code
    digest differs anyway, and the file says what it lacks), while ``State.from_arrays``
    (diagnostics reading old runs) gives that array its empty default (``Workspace.
    for_model`` sizes it)."""
    s = make_state()
    s.contact_work = np.arange(5.0)
    path = save_checkpoint(tmp_path / "ck", s, DIGEST)
    with np.load(path) as npz:
        data = {k: npz[k] for k in npz.files if k != "contact_work"}
    np.savez(path, **data)
    with pytest.raises(InputError, match="incomplete.*contact_work"):
        load_checkpoint(path, DIGEST)
    back = State.from_arrays(data)
    assert back.contact_work.size == 0
    assert np.array_equal(back.x, s.x) and back.step == s.step
