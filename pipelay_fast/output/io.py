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

__all__ = ["read_result", "read_units", "write_result", "write_table"]


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
    ``out_dir``, ``rollers.parquet`` (one row per roller) for a roller
    stinger, and ``functional.parquet`` (the profile of the case without its
    current) when its code check splits the current off.

    ``out_dir`` is created if missing. Each file's schema metadata holds the
    case (key ``case``, the JSON of :meth:`pipelay_fast.Case.to_dict`), so that
    :func:`read_result` gives the result back. Returns the paths written
    (summary, profile, then rollers and functional).
    """
    from .._version import __version__

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    metadata = {
        "case_name": result.case.name,
        "case_id": str(result.summary["case_id"]),
        "pipelay_fast_version": __version__,
        "case": json.dumps(result.case.to_dict()),
    }
    row = pd.DataFrame([result.summary]).astype({"last_roller_in_contact": "Int64"})
    paths = [write_table(row, out / "summary.parquet", SUMMARY_UNITS, metadata),
             write_table(result.profile, out / "profile.parquet", PROFILE_UNITS, metadata)]
    if result.rollers is not None:
        paths.append(write_table(result.rollers, out / "rollers.parquet", ROLLER_UNITS,
                                 metadata))
    if result.functional is not None:
        paths.append(write_table(pd.DataFrame(result.functional), out / "functional.parquet",
                                 PROFILE_UNITS, metadata))
    return tuple(paths)


def read_result(out_dir: str | os.PathLike) -> Result:
    """The result :func:`write_result` wrote into ``out_dir`` (``pipelay-fast
    solve --out``), without its solver state (it cannot warm-start a solve).

    Raises
    ------
    ValueError
        When ``out_dir`` holds no ``profile.parquet`` and ``summary.parquet``,
        or they hold no case (written before the case was stored).
    """
    from ..input.case import load_case

    out = Path(out_dir)
    if not (out / "profile.parquet").is_file() or not (out / "summary.parquet").is_file():
        raise ValueError(f"{out}: no profile.parquet and summary.parquet (pipelay-fast solve "
                         "CASE.toml --out DIR writes them)")
    metadata = pq.read_schema(out / "profile.parquet").metadata or {}
    if b"case" not in metadata:
        raise ValueError(f"{out}: profile.parquet does not hold its case (written by an older "
                         "pipelay-fast): solve it again with --out")
    case = load_case(json.loads(metadata[b"case"]))

    def columns(name):
        path = out / name
        if not path.is_file():
            return None
        return {k: v.to_numpy() for k, v in pd.read_parquet(path).items()}

    summary = pd.read_parquet(out / "summary.parquet").iloc[0].to_dict()
    return Result(case, summary, columns("profile.parquet"),
                  roller_columns=columns("rollers.parquet"),
                  functional=columns("functional.parquet"))
