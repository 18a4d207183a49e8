"""The results directory of a sweep: a Parquet dataset, hive-partitioned by scene.

Layout of ``OUT/``::

    sweep.json                           the sweep's scenes (base cases, axes)
    summary/scene=<name>/<chunk>.parquet  one row per case
    profiles/scene=<name>/<chunk>.parquet one row per node per case (column case_id)
    rollers/scene=<name>/<chunk>.parquet  one row per roller per case of a roller stinger
    spans/scene=<name>/<chunk>.parquet    one row per free span per case (elastic seabed)
    selection.parquet                    written by ``pipelay-fast select``

Every file carries the unit of each column in its schema metadata, as
:func:`pipelay_fast.output.io.write_table` writes it. A worker encodes each chunk (a
task's cases) to Parquet bytes; the parent, the only writer, writes them
atomically (temporary name, then rename), profiles, rollers and spans first and
summary last, under the same file name in every table: the summary file is
the chunk's commit mark. On opening, leftovers of an interrupted run
(temporary files, profile, roller and span chunks without their summary) are
removed, so a rerun sees exactly the committed cases and recomputes the rest.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import hashlib
import json
import math
import os
import uuid
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from ..output.results import PROFILE_UNITS, ROLLER_UNITS, SUMMARY_UNITS
from ..output.spans import SPAN_UNITS
from .sweep import INPUT_UNITS, TARGET_UNITS, Sweep

__all__ = ["Chunk", "Dataset", "PROFILE_COLUMNS", "ROLLER_COLUMNS", "SPAN_COLUMNS",
           "SUMMARY_COLUMNS", "encode_chunk", "read_profiles", "read_rollers", "read_spans",
           "read_summary"]

# bookkeeping columns of the summary: the chain and place of a case, whether
# it was given the previous solution of its chain to start from
RUN_UNITS = {"chain": "", "chain_position": "", "warm_started": ""}
SUMMARY_COLUMNS = {**SUMMARY_UNITS, **INPUT_UNITS, **TARGET_UNITS, **RUN_UNITS}
PROFILE_COLUMNS = {"case_id": "", "node": "", **PROFILE_UNITS}
ROLLER_COLUMNS = {"case_id": "", **ROLLER_UNITS}
SPAN_COLUMNS = {"case_id": "", **SPAN_UNITS}
_INTEGER = ("n_elements", "n_iterations", "n_current_steps", "max_current_step_iterations",
            "n_meshes", "chain_position", "last_roller_in_contact")
_BOOLEAN = ("warm_started",)
_FLAGS = ("yielded", "bears_on_tip")  # an answer's flags: missing (None) on a failed row


class Dataset:
    """A sweep's results directory ``root``, locked for writing while open.

    Use as a context manager: ``with Dataset(out, sweep) as ds: ...``.
    Entering creates the directory, takes its ``.lock`` (RuntimeError while
    another live process holds it), removes an interrupted run's leftovers
    and stores ``sweep``'s scenes in ``sweep.json`` (ValueError for a scene
    name that already holds another base case); leaving releases the lock.
    """

    def __init__(self, root: str | os.PathLike, sweep: Sweep | None = None):
        self.root = Path(root)
        self.sweep = sweep
        self._lock = self.root / ".lock"

    def __enter__(self) -> Dataset:
        self.root.mkdir(parents=True, exist_ok=True)
        self._acquire()
        try:
            self._clean()
            if self.sweep is not None:
                self._write_spec(self.sweep)
        except BaseException:
            self._lock.unlink(missing_ok=True)
            raise
        return self

    def __exit__(self, *exc):
        self._lock.unlink(missing_ok=True)

    # ------------------------------------------------------------------ state

    def _acquire(self):
        """Create ``.lock`` holding our pid; take over a lock whose process is gone."""
        for _ in range(2):
            try:
                fd = os.open(self._lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
            except FileExistsError:
                try:
                    pid = int(self._lock.read_text() or 0)
                except (OSError, ValueError):
                    pid = 0
                if pid and _alive(pid):
                    raise RuntimeError(f"{self.root} is being written by process {pid} "
                                       f"(remove {self._lock} if that is wrong)") from None
                self._lock.unlink(missing_ok=True)
                continue
            with os.fdopen(fd, "w") as stream:
                stream.write(str(os.getpid()))
            return
        raise RuntimeError(f"cannot lock {self.root}")

    def _clean(self):
        """Remove temporary files, and profile, roller and span chunks
        without their summary chunk (an interrupted run's)."""
        for tmp in self.root.glob("*/scene=*/.*.tmp"):
            tmp.unlink(missing_ok=True)
        for table in ("profiles", "rollers", "spans"):
            for chunk in self.root.glob(f"{table}/scene=*/*.parquet"):
                if not (self.root / "summary" / chunk.parent.name / chunk.name).exists():
                    chunk.unlink()

    def _write_spec(self, sweep: Sweep):
        """Store the scenes in ``sweep.json``; refuse a scene redefined under
        an old name, and other sensitivities' keys than the directory's."""
        path = self.root / "sweep.json"
        new = sweep.to_spec()
        if path.exists():
            old = json.loads(path.read_text())
            if old.get("sensitivities", []) != new["sensitivities"]:
                raise ValueError(
                    f"{self.root} holds results with sensitivities "
                    f"{old.get('sensitivities', [])}, this sweep asks for "
                    f"{new['sensitivities']}: write it to a new directory")
            old_scenes = {s["name"]: s for s in old["scenes"]}
            for scene in new["scenes"]:
                before = old_scenes.get(scene["name"])
                if before is not None and before["case"] != scene["case"]:
                    raise ValueError(
                        f"{self.root} holds a scene {scene['name']!r} with another base case; "
                        "write this sweep to a new directory or rename the scene")
                old_scenes[scene["name"]] = scene
            new["scenes"] = list(old_scenes.values())
        tmp = path.with_name(f".sweep.json.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(new, indent=1, default=_json_default))
        os.replace(tmp, path)

    def case_ids(self) -> set[str]:
        """Ids of the cases already written (committed summary chunks)."""
        ids: set[str] = set()
        for chunk in self.root.glob("summary/scene=*/*.parquet"):
            ids.update(pq.read_table(chunk, columns=["case_id"]).column(0).to_pylist())
        return ids

    # ------------------------------------------------------------------ writing

    def write_chunk(self, chunk: Chunk) -> None:
        """Write an encoded chunk: its profiles, rollers and spans, then its
        summary (the commit)."""
        part = f"scene={chunk.scene}"
        tables = [("profiles", chunk.profiles), ("rollers", chunk.rollers),
                  ("spans", chunk.spans), ("summary", chunk.summary)]
        for table, data in tables:
            if data is None:
                continue
            folder = self.root / table / part
            folder.mkdir(parents=True, exist_ok=True)
            _write_bytes(folder / chunk.name, data)


@dataclass
class Chunk:
    """The Parquet files of one chunk, encoded (by a worker) and ready to write.

    ``summary``, ``profiles``, ``rollers`` and ``spans`` are Parquet file
    contents (all but ``summary`` None when there are no such rows); ``rows`` and
    ``failed`` count the cases.
    """

    scene: str
    name: str
    summary: bytes
    profiles: bytes | None
    rows: int
    failed: int
    rollers: bytes | None = None
    spans: bytes | None = None


def encode_chunk(sweep: str, scene: str, rows: list[dict], profile: dict | None,
                 rollers: dict | None = None, extra: Mapping | None = None,
                 spans: dict | None = None) -> Chunk:
    """Encode the summary rows of one scene (and their profile, roller and
    span columns) as a chunk; ``extra``: {column: unit} of the float columns the
    summary has besides SUMMARY_COLUMNS (the sweep's sensitivities,
    :func:`pipelay_fast.study.sensitivity.sensitivity_columns`, text where the unit is "").

    The file name hashes the chunk's case ids, the same in every table.
    """
    ids = "".join(sorted(r["case_id"] for r in rows))
    name = f"chunk-{hashlib.sha1(ids.encode()).hexdigest()[:16]}.parquet"
    meta = {"sweep": sweep, "scene": scene}
    profiles = None
    if profile is not None:
        profiles = encode_arrays(profile, PROFILE_COLUMNS, meta)
    roller_rows = None
    if rollers is not None:
        roller_rows = encode_arrays(rollers, ROLLER_COLUMNS, meta)
    span_rows = None
    if spans is not None:
        span_rows = encode_arrays(spans, SPAN_COLUMNS, meta)
    extra = dict(extra or {})
    summary = _encode(summary_table(rows, extra), {**SUMMARY_COLUMNS, **extra}, meta)
    failed = sum(r["status"] != "ok" for r in rows)
    return Chunk(scene, name, summary, profiles, len(rows), failed, roller_rows, span_rows)


def encode_arrays(columns: dict, units: dict, metadata: dict) -> bytes:
    """The columns ``units`` names, from the arrays of ``columns`` (no
    DataFrame between: the profiles of a chunk are some 40 solves' arrays),
    as :func:`_encode` lays them out: strings of the Arrow type pandas
    gives them, NaN as null (``from_pandas``); a column already an Arrow
    array (:func:`repeated_text`) is taken as it is."""
    arrays = [columns[k] if isinstance(columns[k], pa.Array)
              else pa.array(columns[k], type=_pandas_string_type(), from_pandas=True)
              if np.asarray(columns[k]).dtype.kind in "OUS"
              else pa.array(columns[k], from_pandas=True)
              for k in units]
    return _encode(pa.Table.from_arrays(arrays, names=list(units)), units, metadata)


def repeated_text(values: list[str], counts) -> pa.Array:
    """A text column of the dataset's type: ``values[i]`` ``counts[i]``
    times, in order (a chunk's case ids, one per profile node): the distinct
    values converted once and taken by index, cheaper than converting a
    NumPy array of repeated text (the encoding is part of the sweep layer's
    overhead, benchmarks/bench_sweep.py)."""
    index = np.repeat(np.arange(len(values), dtype=np.int64), np.asarray(counts, dtype=np.int64))
    return pa.array(values, type=_pandas_string_type()).take(pa.array(index))


@functools.cache
def _pandas_string_type() -> pa.DataType:
    """The Arrow type pandas writes a column of text as (large_string with
    pandas 3's str dtype, string with pandas 2's object columns)."""
    return pa.Table.from_pandas(pd.DataFrame({"s": np.array(["x"])})).schema.field("s").type


def _encode(table: pa.Table, units: dict, metadata: dict) -> bytes:
    """``table`` as the bytes of a Parquet file carrying the unit of every
    column, laid out as :func:`pipelay_fast.output.io.write_table` does (field
    metadata ``unit``, schema metadata ``units``); dictionary encoding for
    strings only."""
    fields = [f.with_metadata({b"unit": units[f.name].encode()}) for f in table.schema]
    schema_metadata = {
        **(table.schema.metadata or {}),
        **{str(k).encode(): str(v).encode() for k, v in metadata.items()},
        b"units": json.dumps({column: units[column] for column in table.column_names}).encode(),
    }
    table = table.cast(pa.schema(fields, metadata=schema_metadata))
    strings = [f.name for f in table.schema if not pa.types.is_floating(f.type)]
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink, use_dictionary=strings)
    return sink.getvalue().to_pybytes()


def _write_bytes(path: Path, data: bytes):
    """Write ``data`` to ``path`` atomically: a temporary name, then a rename."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{uuid.uuid4().hex}.tmp")
    try:
        tmp.write_bytes(data)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def _summary_columns(rows: list[dict], extra: Mapping):
    """Each summary column's values from ``rows`` (SUMMARY_COLUMNS, then
    ``extra``, {column: unit}), in the dataset's fixed
    types: (name, values, kind), kind "int" (None where missing), "bool",
    "flag" (a bool, None where missing), "str" ("" where missing) or "float"
    (NaN where missing)."""
    for column, unit in {**SUMMARY_COLUMNS, **extra}.items():
        values = [row.get(column) for row in rows]
        if column in _INTEGER:
            yield column, [None if _missing(v) else _integer(column, v) for v in values], "int"
        elif column in _BOOLEAN:
            yield column, [bool(v) for v in values], "bool"
        elif column in _FLAGS:
            yield column, [None if _missing(v) else bool(v) for v in values], "flag"
        elif unit == "":
            yield column, ["" if _missing(v) else str(v) for v in values], "str"
        else:
            yield column, [math.nan if _missing(v) else float(v) for v in values], "float"


def _integer(column: str, value) -> int:
    """``value`` as an integer, refused when it is not a whole number."""
    if float(value) != int(value):
        raise ValueError(f"summary column {column} = {value!r} is not an integer")
    return int(value)


def summary_frame(rows: list[dict], extra: Mapping | None = None) -> pd.DataFrame:
    """Summary rows as a DataFrame with the dataset's fixed column types
    (integers Int64, bookkeeping flags bool, an answer's flags boolean
    (missing on a failed row), text str, the rest float64); ``extra`` as
    for :func:`encode_chunk`."""
    pandas_types = {"int": "Int64", "bool": bool, "flag": "boolean", "str": str,
                    "float": np.float64}
    return pd.DataFrame({column: pd.array(values, dtype=pandas_types[kind])
                         for column, values, kind in _summary_columns(rows, extra or {})})


_ARROW_TYPES = {"int": pa.int64(), "bool": pa.bool_(), "flag": pa.bool_(),
                "float": pa.float64()}
_summary_schemas: dict = {}  # {the extra columns, (name, unit) pairs: the schema}


def summary_table(rows: list[dict], extra: Mapping | None = None) -> pa.Table:
    """Summary rows as the Arrow table :func:`summary_frame` would give
    (built from the rows' values; the pandas metadata, which tells pandas to
    read the integers back as Int64, taken once per set of ``extra``
    columns from a one-row frame)."""
    extra = dict(extra or {})
    key = tuple(extra.items())
    if key not in _summary_schemas:
        _summary_schemas[key] = pa.Table.from_pandas(summary_frame(rows[:1], extra),
                                                     preserve_index=False).schema
    arrays = [pa.array(values, type=_ARROW_TYPES.get(kind) or _pandas_string_type(),
                       from_pandas=True)  # NaN as null
              for _column, values, kind in _summary_columns(rows, extra)]
    return pa.Table.from_arrays(arrays, schema=_summary_schemas[key])


def _missing(value) -> bool:
    return value is None or value is pd.NA or (isinstance(value, float) and math.isnan(value))


def read_summary(root: str | os.PathLike, filters=None) -> pd.DataFrame:
    """The summary table of a results directory (``scene`` a column), sorted by
    scene, chain and position; ``filters`` as for :func:`pandas.read_parquet`."""
    frame = _read(Path(root) / "summary", filters)
    if frame.empty:
        return frame
    return frame.sort_values(["scene", "chain", "chain_position"], kind="stable",
                             ignore_index=True)


def read_profiles(root: str | os.PathLike, filters=None) -> pd.DataFrame:
    """The profiles table of a results directory (``scene`` a column)."""
    return _read(Path(root) / "profiles", filters)


def read_rollers(root: str | os.PathLike, filters=None) -> pd.DataFrame:
    """The rollers table of a results directory (``scene`` a column): one row
    per roller per case of a roller stinger, columns ``case_id`` and those of
    ``pipelay_fast.output.results.ROLLER_UNITS``."""
    return _read(Path(root) / "rollers", filters)


def read_spans(root: str | os.PathLike, filters=None) -> pd.DataFrame:
    """The spans table of a results directory (``scene`` a column): one row
    per free span per case (an elastic seabed's), columns ``case_id`` and
    those of ``pipelay_fast.output.spans.SPAN_UNITS``; empty without spans."""
    return _read(Path(root) / "spans", filters)


def _read(folder: Path, filters) -> pd.DataFrame:
    """The hive-partitioned table under ``folder`` (empty when it has no chunk)."""
    if not any(folder.glob("scene=*/*.parquet")):
        return pd.DataFrame()
    frame = pd.read_parquet(folder, filters=filters)
    frame["scene"] = frame["scene"].astype(str)
    return frame


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists and is not a zombie."""
    try:
        os.kill(pid, 0)
    except OSError as err:
        return err.errno == errno.EPERM
    with contextlib.suppress(OSError):  # a zombie child of ours counts as gone
        with open(f"/proc/{pid}/stat") as stat:
            if stat.read().split(")")[-1].split()[0] == "Z":
                return False
    return True


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON-able: {value!r}")
