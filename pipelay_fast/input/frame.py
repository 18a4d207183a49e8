"""The vessel's frame (``lay.frame``): the lay geometry given as heights above
the seabed or as elevations about the still water level, and the note on a
vessel standing too high above the water (its check against the seabed:
:mod:`.surface`).

In the ``"waterline"`` frame ``lay.top``, ``lay.stinger.lower``/``upper``,
``lay.stinger.rollers`` and ``lay.trim_pivot`` give x as the elevation e [m]
above the still water level (negative below it), z unchanged. The engine sees heights above the
seabed, x = d + e with d = ``environment.water_depth``, so that the water
depth moves only the seabed: :func:`to_seabed` builds that seabed-frame
:class:`~pipelay_fast.input.lay.Lay` when the case is built
(:class:`~pipelay_fast.input.case.Case`), which keeps the given one for
``to_dict``.

The sum d + e is the decimal sum of the two numbers' shortest decimal forms
(``repr``), rounded once (:func:`raised`): a height written in the seabed
frame as the decimal sum of the depth and the elevation gives the same float
as the elevation written in the waterline frame, so a waterline case and its
seabed-frame twin solve to the same bits. (The float sum d + e can differ
from it by an ulp: 30.0 + (-25.3) is 4.699999999999999 in floats, the sum
of the rounded -25.3; here it is 4.7, the float of the decimal 4.7.)
"""

from __future__ import annotations

import dataclasses
from decimal import Context, Decimal

FRAMES = ("seabed", "waterline")

# Exact decimal arithmetic for two doubles' shortest forms: 17 digits each,
# exponents within 10^+-308 of each other, so the exact sum has fewer than
# 700 digits and the context never rounds it (the float conversion does, once).
_EXACT = Context(prec=700)


def raised(value: float, by: float) -> float:
    """``value + by`` [m]: the exact sum of their shortest decimal forms
    rounded once to the nearest float."""
    return float(_EXACT.add(Decimal(repr(float(value))), Decimal(repr(float(by)))))


def _point(point, depth: float) -> tuple[float, float]:
    """(x, z) of a waterline-frame ``point`` with x raised by ``depth``."""
    return (raised(point[0], depth), point[1])


def to_seabed(lay, depth: float):
    """The seabed-frame :class:`~pipelay_fast.input.lay.Lay` of ``lay``
    (``frame = "seabed"``, heights above the seabed) in ``depth`` [m] of water.

    A seabed-frame ``lay`` is returned as it is; a waterline one has its
    heights raised by ``depth`` (:func:`raised`); the case checks them
    against the seabed (:func:`.surface.check_vessel`).
    A roller path's rollers follow ``lay.top``; their ``height_step``
    rounds heights above the seabed (the elevations when ``depth`` is a
    multiple of the step)."""
    if lay.frame == "seabed":
        return lay
    st = lay.stinger
    changes = {"frame": "seabed", "top": _point(lay.top, depth)}
    if lay.trim_pivot is not None:
        changes["trim_pivot"] = _point(lay.trim_pivot, depth)
    if st is not None and lay.has_rollers:
        if st.rollers is not None:
            changes["stinger"] = dataclasses.replace(
                st, rollers=tuple(_point(r, depth) for r in st.rollers))
    elif st is not None:
        changes["stinger"] = dataclasses.replace(
            st, lower=_point(st.lower, depth), upper=_point(st.upper, depth))
    return dataclasses.replace(lay, **changes)


def vessel_note(given, lay, depth: float) -> str:
    """A note for the result's message when an S-lay vessel's end stands
    higher above the still water than its stinger's tip reaches below it;
    "" otherwise.

    ``given`` is the case's lay as given (its frame), ``lay`` the same in the
    seabed frame, ``depth`` [m] the water depth. A stinger hangs from the
    vessel's deck and carries the pipe into the water: its upper end stands
    the deck's freeboard above the surface, its tip below the hull. An upper
    end higher above the water than the tip is below it is most likely a
    stinger copied from a case of another depth (the S67 stinger in 45 m of
    water stands 27 m above it with its tip 3.5 m below), or one that does
    not reach the water. The bound is the case's own geometry, no constant.
    It is a note, not a refusal: the model solves such a lay as stated (the
    pipe in air weighs its dry weight), the freeboard that would decide
    whether a vessel can hold it is not in the case, and shallow stingers
    that enter the water just below a high deck are lays all the same (a
    third of the random S-lays of benchmarks/random_lay.py, drawn with the
    upper end 5 to 15 m above the water, have their tip less deep than
    that). J-lay has no stinger to compare with: its top is not checked."""
    if lay.method != "S":
        return ""
    above = lay.top[0] - depth
    tips = lay.roller_positions() if lay.has_rollers else (lay.stinger.lower,)
    below = depth - tips[-1][0]
    if above <= below:
        return ""
    if lay.curve is not None:
        key, value = "lay.stinger.upper", given.stinger.upper
        tip_key, tip = "lay.stinger.lower", list(given.stinger.lower)
    else:
        key, value = "lay.top", given.top
        tip_key, tip = "the last roller", [float(v) for v in tips[-1]]
        if given.frame != "seabed":
            tip[0] = tip[0] - depth
    return (f"{key} = {list(value)} stands {above:.4g} m above the still water (lay.frame = "
            f"{given.frame!r}, environment.water_depth = {depth!r} m) but the stinger's tip "
            f"({tip_key} = {tip}) is only {below:.4g} m below it: is the stinger copied from a "
            "case of another depth? (lay.frame = 'waterline' keeps it on the vessel)")
