"""Parquet output: tables with their units, written atomically.

Every column's unit is stored twice: in the schema-level metadata (key
``b"units"``, a JSON object ``{column: unit}``) for readers that look at the
file as a whole, and in each field's metadata (key ``b"unit"``) for readers
that look at one column. Values stay in SI.
"""

from __future__ import annotations

import json
import os
import uuid
from collections.abc import Mapping
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from .results import PROFILE_UNITS, ROLLER_UNITS, SUMMARY_UNITS, Result

__all__ = ["read_units", "write_result", "write_table"]


def write_table(
    df: pd.DataFrame,
    path: str | os.PathLike,
    units: Mapping[str, str],
    metadata: Mapping[str, str] | None = None,
) -> Path:
    """Write ``df`` to the Parquet file ``path`` with the unit of every column.

    The file is written to a temporary name in the same directory and moved
    into place with :func:`os.replace`, so a reader never sees half a file.

    Parameters
    ----------
    df : pandas.DataFrame
        The table; its index is not written.
    path : path-like
        The Parquet file to create or replace.
    units : mapping
        Unit of every column of ``df`` ("" for dimensionless labels).
    metadata : mapping, optional
        Further schema-level key-value pairs (str to str), e.g. the version.

    Raises
    ------
    ValueError
        When a column of ``df`` has no unit in ``units``.
    """
    missing = [column for column in df.columns if column not in units]
    if missing:
        raise ValueError(f"no unit given for column(s) {', '.join(map(str, missing))}")
    table = pa.Table.from_pandas(df, preserve_index=False)
    fields = [field.with_metadata({b"unit": units[field.name].encode()}) for field in table.schema]
    extra = {str(key).encode(): str(value).encode() for key, value in (metadata or {}).items()}
    column_units = {column: units[column] for column in df.columns}
    schema_metadata = {
        **(table.schema.metadata or {}),
        **extra,
        b"units": json.dumps(column_units).encode(),
    }
    table = table.cast(pa.schema(fields, metadata=schema_metadata))

    path = Path(path)
    # a fresh name beside the target (same file system, so os.replace is atomic);
    # pyarrow creates it, so it gets the usual permissions rather than mkstemp's 0600
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{uuid.uuid4().hex}.tmp")
    try:
        pq.write_table(table, tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def read_units(path: str | os.PathLike) -> dict[str, str]:
    """The ``{column: unit}`` map stored in a Parquet file by :func:`write_table`;
    ValueError when the file has none."""
    metadata = pq.read_schema(path).metadata or {}
    if b"units" not in metadata:
        raise ValueError(f"{path}: no units in the Parquet schema metadata")
    return json.loads(metadata[b"units"])


def write_result(result: Result, out_dir: str | os.PathLike) -> tuple[Path, ...]:
    """Write ``summary.parquet`` (one row) and ``profile.parquet`` into
    ``out_dir``, and ``rollers.parquet`` (one row per roller) for a roller
    stinger.

    ``out_dir`` is created if missing. Returns the paths written (summary,
    profile, then rollers).
    """
    from .._version import __version__

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    metadata = {
        "case_name": result.case.name,
        "case_id": str(result.summary["case_id"]),
        "pipelay_fast_version": __version__,
    }
    row = pd.DataFrame([result.summary]).astype({"last_roller_in_contact": "Int64"})
    summary = write_table(row, out / "summary.parquet", SUMMARY_UNITS, metadata)
    profile = write_table(result.profile, out / "profile.parquet", PROFILE_UNITS, metadata)
    if result.rollers is None:
        return summary, profile
    return summary, profile, write_table(result.rollers, out / "rollers.parquet", ROLLER_UNITS,
                                         metadata)
