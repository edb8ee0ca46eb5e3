"""Provenance of a result: digests of what made it, so that nothing stale is reused.

Every summary.json carries ``provenance`` (:func:`provenance`):

- ``case_digest``: SHA-256 of the case as resolved (the validated spec, every quantity
  in SI, as JSON) — a unit spelt differently is the same case, a changed value is not;
- ``files``: SHA-256 of each file the case reads (material files, an Abaqus mesh), by
  the path the case gives;
- ``code_version``: the package version, and ``source_digest``, a SHA-256 of every
  ``.py`` file of the installed package (an edit to any module is a new code version);
- ``digest``: one SHA-256 of all of the above. A sweep, ``validate`` and a ``design``
  search reuse a finished run only when its ``digest`` equals the one the case would
  have now; anything else runs again, and the reason is said.

:func:`restart_parts` are the same with ``run.end_time``, ``run.threads``, the output
intervals, ``run.energy_tolerance``, ``run.stop_when_decided`` and
``run.max_added_mass_fraction`` left out (a restart may run a case further or shorter,
stop it on another rule or added-mass limit, on other threads, with other output
intervals or verdict: none changes the steps it replays, and the checkpoint counts the
rows and frames already written); a
checkpoint stores them and their digest, and
``--restart`` refuses a checkpoint written for another case, material, mesh or code,
naming which.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from wovenimpact.errors import InputError
from wovenimpact.jit import source_digest

# [run] keys a restart may change: none changes the steps it replays (when to stop, on
# how many threads, what to write, the verdict)
RESTART_FREE = ("end_time", "threads", "field_interval", "history_interval",
                "checkpoint_interval", "energy_tolerance", "stop_when_decided",
                "max_added_mass_fraction")


def code_version() -> dict[str, str]:
    """The package version and :func:`~wovenimpact.jit.source_digest`."""
    from wovenimpact import __version__

    return {"code_version": __version__, "source_digest": source_digest()}


def input_files(spec) -> list[str]:
    """The paths (as the case writes them) of the files a case reads: material files
    and an Abaqus mesh."""
    files = [ref if isinstance(ref, str) else ref.file for ref in spec.materials.values()]
    mesh_file = getattr(spec.mesh, "file", None)
    if mesh_file:
        files.append(mesh_file)
    return sorted(set(files))


def file_digest(path: Path) -> str:
    """SHA-256 (16 hex digits) of a file's bytes."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()[:16]
    except OSError as exc:
        raise InputError(f"{path}: cannot be read ({exc.strerror})") from None


def _spec_json(spec, drop_run=()) -> str:
    doc = spec.model_dump(mode="json")
    for key in drop_run:
        doc["run"].pop(key, None)
    return json.dumps(doc, sort_keys=True)


def digest_of(parts: dict) -> str:
    """SHA-256 (16 hex digits) of a dict of digests (JSON, keys sorted)."""
    return hashlib.sha256(json.dumps(parts, sort_keys=True).encode()).hexdigest()[:16]


def provenance(spec, base: str | Path) -> dict:
    """Digests of a case (``spec``, its relative paths relative to ``base``), the files
    it reads and the code (module docstring); ``digest`` combines them all."""
    base = Path(base)
    parts = {
        "case_digest": hashlib.sha256(_spec_json(spec).encode()).hexdigest()[:16],
        "files": {name: file_digest(base / name) for name in input_files(spec)},
        **code_version(),
    }
    return {**parts, "digest": digest_of(parts)}


def restart_parts(spec, base: str | Path) -> dict:
    """What a checkpoint must have been written for to be resumed: :func:`provenance`'s
    parts without the ``[run]`` keys of :data:`RESTART_FREE` (``case``,
    ``files``, ``code_version``, ``source_digest``; a refused restart says which one
    changed)."""
    base = Path(base)
    return {
        "case": hashlib.sha256(_spec_json(spec, drop_run=RESTART_FREE).encode()).hexdigest()[:16],
        "files": {name: file_digest(base / name) for name in input_files(spec)},
        **code_version(),
    }


CODE_PARTS = ("code_version", "source_digest")


def stale_reason(summary: dict, expected: dict, older_code: bool = False) -> str | None:
    """Why a finished run's ``summary`` cannot stand for the case of ``expected``
    (:func:`provenance`), or None if its digest matches. With ``older_code`` a run made
    by other code stands if its case and files are the same (``sweep
    --keep-older-code``)."""
    old = summary.get("provenance")
    if not isinstance(old, dict) or "digest" not in old:
        return "its summary has no provenance digest (written by an older wovenimpact)"
    if old["digest"] == expected["digest"]:
        return None
    if older_code and all(old.get(k) == v for k, v in expected.items()
                          if k not in CODE_PARTS and k != "digest"):
        return None
    return "changed since it ran: " + changed_parts(old, expected)


NAMES = {"case_digest": "the case", "case": "the case", "files": "a material or mesh file",
         "code_version": "the code version", "source_digest": "the code"}


def changed_parts(old: dict, new: dict) -> str:
    """What differs between two sets of digest parts, in words ("the case, the code")."""
    changed = [NAMES[k] for k in NAMES if k in new and old.get(k) != new.get(k)]
    return ", ".join(dict.fromkeys(changed)) or "the case"
