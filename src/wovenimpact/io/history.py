"""Time histories: one row of scalars per output time, written as CSV.

Column names carry their unit (``time_s``, ``kinetic_energy_J``, ``reaction_z_N``);
a name without a unit is a count (``step``). Every History has a ``time_s``
column. Floats are written with
``repr`` (shortest exact form) and integers as integers, so a CSV round trip is
exact and keeps each column's type.
"""

from __future__ import annotations

import io
import numbers
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.io.atomic import atomic_write_text

TIME = "time_s"
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
_INT = re.compile(r"[+-]?\d+")


class History:
    """Rows of named scalars in memory, with a fixed set of columns.

    Args:
        columns: column names, unique identifiers ending in their unit; must
            include ``time_s``.
    """

    def __init__(self, columns: Sequence[str]) -> None:
        self.columns = tuple(_check_columns(columns))
        self._rows: list[tuple[float | int, ...]] = []

    def __len__(self) -> int:
        return len(self._rows)

    def append(self, row: dict) -> None:
        """Add a row; its keys must be exactly the columns (values: numbers)."""
        keys = set(row)
        if keys != set(self.columns):
            missing = [c for c in self.columns if c not in keys]
            extra = sorted(keys - set(self.columns))
            raise InputError(f"history row: missing columns {missing}, unknown columns {extra}; "
                             f"valid: {list(self.columns)}")
        self._rows.append(tuple(_scalar(c, row[c]) for c in self.columns))

    def arrays(self, columns: Sequence[str] | None = None) -> dict[str, np.ndarray]:
        """Each column (or only ``columns``) as an array (int64 if all its values are
        integers, else float64)."""
        return {c: _column_array([r[i] for r in self._rows]) for i, c in enumerate(self.columns)
                if columns is None or c in columns}

    def keep_first(self, n: int) -> None:
        """Keep the first ``n`` rows (a restart keeps those its checkpoint counted)."""
        self._rows = self._rows[:n]

    def to_csv_text(self) -> str:
        buf = io.StringIO()
        buf.write(",".join(self.columns) + "\n")
        for r in self._rows:
            buf.write(",".join(repr(v) for v in r) + "\n")
        return buf.getvalue()

    def write_csv(self, path: str | Path) -> None:
        """Write all rows to ``path`` atomically (header line, then one line a row)."""
        atomic_write_text(path, self.to_csv_text())

    @classmethod
    def from_csv(cls, path: str | Path) -> History:
        """A History holding the columns and rows of a CSV written by :meth:`write_csv`."""
        columns, rows = _parse_csv(Path(path))
        h = cls(columns)
        h._rows = rows
        return h


def read_csv(path: str | Path) -> dict[str, np.ndarray]:
    """The columns of a history CSV as arrays (int64 for integer columns, else float64)."""
    return History.from_csv(path).arrays()


def _check_columns(columns: Sequence[str]) -> list[str]:
    cols = list(columns)
    bad = [c for c in cols if not isinstance(c, str) or not _NAME.fullmatch(c)]
    if bad:
        raise InputError(f"history columns {bad}: valid names are identifiers (letters, digits, "
                         "'_') ending in their unit, e.g. 'kinetic_energy_J'")
    if len(set(cols)) != len(cols):
        raise InputError(f"history columns {cols} repeat a name; each must be unique")
    if TIME not in cols:
        raise InputError(f"history columns {cols} lack {TIME!r}, which every history needs")
    return cols


def _scalar(column: str, value) -> float | int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise InputError(f"history column {column!r}: value {value!r} is not a number")
    return int(value) if isinstance(value, numbers.Integral) else float(value)


def _column_array(values: list) -> np.ndarray:
    if values and all(isinstance(v, int) for v in values):
        return np.array(values, dtype=np.int64)
    return np.array(values, dtype=float)


def _parse_csv(path: Path) -> tuple[list[str], list[tuple[float | int, ...]]]:
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as exc:
        raise InputError(f"history file {path} cannot be read ({exc.strerror})") from None
    if not lines:
        raise InputError(f"history file {path} is empty; expected a header line")
    columns = [c.strip() for c in lines[0].split(",")]
    rows = []
    for lineno, line in enumerate(lines[1:], 2):
        if not line.strip():
            continue
        fields_ = line.split(",")
        if len(fields_) != len(columns):
            raise InputError(f"{path}:{lineno}: {len(fields_)} values, the header has "
                             f"{len(columns)} columns")
        rows.append(tuple(_parse_value(path, lineno, f.strip()) for f in fields_))
    return columns, rows


def _parse_value(path: Path, lineno: int, text: str) -> float | int:
    if _INT.fullmatch(text):
        return int(text)
    try:
        return float(text)
    except ValueError:
        raise InputError(f"{path}:{lineno}: {text!r} is not a number") from None
