"""The lay table of a sweep's results: one row per case, ordered by lay method
and water depth, with the answers a lay is chosen by (``pipelay-fast table``).

Values stay SI in :func:`lay_table`; :func:`format_lay_table` prints kN,
degrees and per cent.
"""

from __future__ import annotations

import math
import os

import pandas as pd

from .dataset import read_summary

__all__ = ["LAY_TABLE_COLUMNS", "format_lay_table", "lay_table"]

# summary column -> (heading, SI-to-display factor, format)
LAY_TABLE_COLUMNS = {
    "water_depth": ("depth m", 1.0, ".1f"),
    "a": ("a 1/m", 1.0, ".6f"),
    "top_tension": ("top kN", 1e-3, ".1f"),
    "layback": ("layback m", 1.0, ".1f"),
    "tdp_tension": ("TDP kN", 1e-3, ".1f"),
    "departure_angle_deg": ("depart deg", 1.0, ".2f"),
    "tip_clearance": ("tip m", 1.0, ".3f"),
    "overbend_max_strain": ("OB strain %", 100.0, ".3f"),
    "sagbend_max_strain": ("SB strain %", 100.0, ".3f"),
    "overbend_strain_utilisation": ("OB util", 1.0, ".3f"),
    "sagbend_lcc_utilisation": ("SB LCC", 1.0, ".3f"),
    "max_utilisation": ("max util", 1.0, ".3f"),
}
_KEYS = ("scene", "method", "dimension")


def lay_table(root: str | os.PathLike) -> pd.DataFrame:
    """The lay table of the results directory ``root`` (SI units): scene,
    method, dimension, the columns of ``LAY_TABLE_COLUMNS``, status, target
    and message; S-lay first, then J-lay, each by depth then top tension.
    Raises ValueError when ``root`` has no summary table."""
    summary = read_summary(root)
    if summary.empty:
        raise ValueError(f"{root}: no summary table (run a sweep into it first)")
    columns = [*_KEYS, *LAY_TABLE_COLUMNS, "status", "target", "message"]
    table = summary.reindex(columns=columns)
    table["target"] = table["target"].fillna("")
    order = table["method"].map({"S": 0, "J": 1}).fillna(2)
    return (table.assign(_order=order)
            .sort_values(["_order", "water_depth", "top_tension", "scene"], kind="stable")
            .drop(columns="_order").reset_index(drop=True))


def format_lay_table(table: pd.DataFrame) -> str:
    """The lay table as aligned text (display units; n/a for NaN); a failed
    case prints its message instead of numbers; the targets (column, goal and
    key, without their brackets) are listed after."""
    headings = ["scene", "lay", *(h for h, _, _ in LAY_TABLE_COLUMNS.values())]
    rows = []
    for _, r in table.iterrows():
        head = [str(r["scene"]), f"{r['method']} {r['dimension']}".strip()]
        if r["status"] != "ok":
            rows.append((head, f"failed: {r['message']}"))
            continue
        rows.append((head + [_cell(r[c], f, spec) for c, (_, f, spec)
                             in LAY_TABLE_COLUMNS.items()], None))
    widths = [max([len(h)] + [len(cells[i]) for cells, note in rows if note is None]
                  + [len(cells[i]) for cells, note in rows if note is not None and i < 2])
              for i, h in enumerate(headings)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(headings, widths, strict=True))]
    for cells, note in rows:
        if note is None:
            lines.append("  ".join(c.rjust(w) for c, w in zip(cells, widths, strict=True)))
        else:
            lines.append("  ".join(c.rjust(w) for c, w in zip(cells, widths[:2], strict=True))
                         + "  " + note)
    targets = sorted({t.split(" in [")[0] for t in table["target"] if t})
    if targets:
        lines += ["", "targets:"] + [f"  {t}" for t in targets]
    return "\n".join(lines)


def _cell(value, factor: float, spec: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return format(float(value) * factor, spec)
