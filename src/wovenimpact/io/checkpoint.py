"""Checkpoints: a State and the digest of the Model it belongs to, in one ``.npz`` file.

``directory/checkpoint_{step:09d}.npz`` holds every array of ``State.arrays()``
plus ``model_digest`` (a 0-d unicode array) and ``run_meta``, a JSON text of what the
run's side files held at that step (history rows, field frames, wall time; see
runs.run_spec), by which a restart checks them and resumes their numbering; nothing is
pickled, and loading uses ``allow_pickle=False``. Files are written atomically, so the
newest checkpoint is always complete; older ones beyond ``keep`` are deleted.
"""

from __future__ import annotations

import json
import re
import zipfile
from dataclasses import fields
from pathlib import Path

import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.io.atomic import atomic_path
from wovenimpact.state import State

DIGEST_KEY = "model_digest"
META_KEY = "run_meta"
_NAME = re.compile(r"checkpoint_(\d{9,})\.npz")


def checkpoint_name(step: int) -> str:
    """File name of the checkpoint after ``step`` steps."""
    return f"checkpoint_{step:09d}.npz"


def save_checkpoint(directory: str | Path, state: State, model_digest: str, keep: int = 2,
                    meta: dict | None = None) -> Path:
    """Write ``state`` to ``directory/checkpoint_{step:09d}.npz`` atomically, with
    ``meta`` (JSON-able; :func:`checkpoint_meta` reads it back).

    The directory is created if needed. Afterwards only the ``keep`` newest
    checkpoints up to this one remain (this one included); checkpoints with a
    higher step number, left by an earlier run, are not touched.
    """
    if isinstance(keep, bool) or not isinstance(keep, int) or keep < 1:
        raise InputError(f"keep = {keep!r}; valid: a whole number of checkpoints ≥ 1")
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    arrays = state.arrays()
    arrays[DIGEST_KEY] = np.array(str(model_digest))
    arrays[META_KEY] = np.array(json.dumps(meta or {}, sort_keys=True))
    path = directory / checkpoint_name(state.step)
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        np.savez(f, **arrays)
    _prune(directory, state.step, keep)
    return path


def _checkpoints(directory: Path) -> list[tuple[int, Path]]:
    """(step, path) of every checkpoint in ``directory``, by increasing step."""
    if not directory.is_dir():
        return []
    found = []
    for p in directory.iterdir():
        m = _NAME.fullmatch(p.name)
        if m and p.is_file():
            found.append((int(m.group(1)), p))
    return sorted(found)


def _prune(directory: Path, step: int, keep: int) -> None:
    older = [p for s, p in _checkpoints(directory) if s < step]
    for p in older[: max(0, len(older) - (keep - 1))]:
        p.unlink(missing_ok=True)


def latest_checkpoint(directory: str | Path) -> Path | None:
    """The checkpoint with the highest step in ``directory``, or None."""
    found = _checkpoints(Path(directory))
    return found[-1][1] if found else None


def load_checkpoint(path: str | Path, model_digest: str) -> State:
    """The State stored in ``path``, if it was written for the model ``model_digest``."""
    path = Path(path)
    data = _read_arrays(path)
    if DIGEST_KEY not in data:
        raise InputError(f"checkpoint {path} has no model digest; it is not a checkpoint "
                         "written by wovenimpact: delete it or run without --restart")
    if str(data[DIGEST_KEY][()]) != str(model_digest):
        raise InputError(
            f"checkpoint {path} was written for a different model (case file changed?); "
            "delete it or run without --restart"
        )
    missing = [f.name for f in fields(State) if f.name not in data]
    if missing:
        raise InputError(f"checkpoint {path} is incomplete (no {', '.join(missing)}); "
                         "delete it or run without --restart")
    return State.from_arrays(data)


def checkpoint_meta(path: str | Path) -> dict:
    """The ``meta`` saved with a checkpoint ({} for one written without)."""
    path = Path(path)
    data = _read_arrays(path)
    if META_KEY not in data:
        return {}
    try:
        meta = json.loads(str(data[META_KEY][()]))
    except ValueError:
        meta = None
    if not isinstance(meta, dict):
        raise InputError(f"checkpoint {path}: its run_meta is not a JSON object; delete it "
                         "or run without --restart")
    return meta


def _read_arrays(path: Path) -> dict[str, np.ndarray]:
    """Every array of an ``.npz`` file, read (and CRC-checked) now, never unpickled."""
    try:
        with np.load(path, allow_pickle=False) as npz:
            return {name: npz[name] for name in npz.files}
    except FileNotFoundError:
        raise InputError(f"checkpoint {path} not found") from None
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, AttributeError) as exc:
        raise InputError(
            f"checkpoint {path} is unreadable or corrupt ({type(exc).__name__}: {exc}); "
            "delete it or run without --restart"
        ) from None
