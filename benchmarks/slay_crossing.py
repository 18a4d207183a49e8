"""S67 (2D, no current): overbend and sagbend von Mises peaks against stinger `a`.

Prints the table over the paper's range and the values of `a` where the two
peaks are equal (the paper picks a = -0.0012).

    python benchmarks/slay_crossing.py
"""

from __future__ import annotations

from pathlib import Path

from scipy.optimize import brentq

import pipelay_fast as pf

CASE = Path(pf.__file__).resolve().parent / "examples" / "s67.toml"
A_VALUES = (-0.0009, -0.00105, -0.0012, -0.0013, -0.00145, -0.0016, -0.00175, -0.0019, -0.0021)


def summary(base, a):
    return pf.solve(base.with_changes({"lay.stinger.a": a})).summary


def main():
    base = pf.load_case(CASE).with_changes({"environment.current.speed": 0.0})
    print("| a [1/m] | overbend max VM [MPa] | sagbend max VM [MPa] | tip reaction [kN] "
          "| lift-off z [m] | touchdown z [m] |")
    print("|---|---|---|---|---|---|")
    rows = []
    for a in A_VALUES:
        sm = summary(base, a)
        rows.append((a, sm["overbend_max_von_mises"] - sm["sagbend_max_von_mises"]))
        print(f"| {a:+.5f} | {sm['overbend_max_von_mises'] / 1e6:.2f} | "
              f"{sm['sagbend_max_von_mises'] / 1e6:.2f} | {sm['tip_reaction'] / 1e3:.1f} | "
              f"{sm['liftoff_z']:.2f} | {sm['tdp_z']:.2f} |")

    def gap(a):
        sm = summary(base, a)
        return sm["overbend_max_von_mises"] - sm["sagbend_max_von_mises"]

    for (a0, g0), (a1, g1) in zip(rows[:-1], rows[1:], strict=True):
        if g0 * g1 < 0.0:
            print(f"peaks equal at a = {brentq(gap, a1, a0, xtol=1e-8):.6f} 1/m")


if __name__ == "__main__":
    main()
