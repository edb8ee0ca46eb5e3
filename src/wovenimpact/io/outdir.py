"""Output paths checked before any work starts (issue 12): a run that computes for an
hour and then cannot write its results has wasted the hour.

:func:`prepare_output_dir` creates the directory and writes (and removes) a probe file
in it; :func:`check_output_file` does the same for a file's directory and refuses a
directory in the file's place. Both raise :class:`~wovenimpact.errors.InputError`
naming the flag, the path and the reason. :func:`write_failure` words an ``OSError``
met while writing later (a full disk) as one line for the CLI.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from wovenimpact.errors import InputError


def prepare_output_dir(path: str | Path, flag: str = "--out") -> Path:
    """``path`` as a directory that exists and can be written in (created if missing)."""
    path = Path(path)
    where = f"{flag} {str(path)!r}"
    if path.exists() and not path.is_dir():
        raise InputError(f"{where}: is an existing file, not a directory (valid: a "
                         "directory, created if missing)")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise InputError(f"{where}: cannot create the directory ({err.strerror}; valid: a "
                         "directory you can write in)") from None
    try:
        with tempfile.NamedTemporaryFile(dir=path, prefix=".write-check-"):
            pass
    except OSError as err:
        raise InputError(f"{where}: cannot write in the directory ({err.strerror}; valid: a "
                         "directory you can write in)") from None
    return path


def check_output_file(path: str | Path, flag: str) -> Path:
    """``path`` as a file that can be written: its directory prepared, no directory there."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{flag} {str(path)!r}: is a directory (valid: a file path)")
    prepare_output_dir(path.parent, flag=f"{flag} {str(path)!r}: its directory")
    return path


def write_failure(err: OSError, what: str = "the outputs") -> str:
    """One line for an ``OSError`` met while writing ``what`` (full disk, removed
    directory): the file, the system's reason."""
    name = f" {err.filename}" if err.filename else ""
    return f"cannot write {what}{name}: {err.strerror or err}"
