"""The compile notice: a new environment's first solve compiles the kernels,
and the user is told so once per process.

Numba compiles the kernels on their first call and caches the machine code
(:mod:`pipelay_fast.kernels._jit`); when the cache does not hold them
(:func:`pipelay_fast.kernels._jit.kernels_cached`), the first solve of a
process takes far longer than the next ones (``benchmarks/bench_compile.py``
measures how much). :func:`pipelay_fast.solve` logs :data:`COMPILE_NOTICE` on
the logger ``"pipelay_fast"`` at level WARNING, which Python prints on stderr
without any logging set up (``logging.getLogger("pipelay_fast").setLevel(logging.ERROR)``
silences it); the command line prints it itself (:func:`compile_notice`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from ..engine.model import scene_of
from ..kernels import _jit
from ..kernels.scene import tag

__all__ = ["COMPILE_NOTICE", "LOGGER", "announce_compile", "compile_notice", "notice_given",
           "case_cached", "scenes_cached"]

LOGGER = logging.getLogger("pipelay_fast")

COMPILE_NOTICE = ("compiling the numerical kernels: the first solve in a new environment takes "
                  "tens of seconds more (minutes on a busy 2-core machine), once per process "
                  "(each sweep worker compiles once); later runs load them from numba's cache")

_given = False  # this process has decided on the notice


def compile_notice(kernels_cached: Callable[[], bool] | None = None) -> str | None:
    """:data:`COMPILE_NOTICE` the first time it is asked for in this process
    when ``kernels_cached()`` (default :func:`pipelay_fast.kernels._jit.kernels_cached`)
    is false, numba's cache not holding the kernels; None otherwise, and on
    every later call: the caller gives it (the command line prints it), once
    per process."""
    global _given
    if _given:
        return None
    _given = True
    return None if (kernels_cached or _jit.kernels_cached)() else COMPILE_NOTICE


def scenes_cached(*scenes) -> Callable[[], bool]:
    """A test for :func:`compile_notice`: whether numba's cache holds the
    Newton kernel of every one of ``scenes`` (:class:`..kernels.scene.Scene`,
    the families :func:`pipelay_fast.engine.model.scene_of` picks), the
    kernels a solve or a sweep of them runs. Another family's cache does not
    count: it would not be loaded."""
    return lambda: all(_jit.kernels_cached(tag(scene)) for scene in scenes)


def case_cached(case) -> Callable[[], bool]:
    """:func:`scenes_cached` of ``case``'s family (:func:`pipelay_fast.engine.model.scene_of`)."""
    return scenes_cached(scene_of(case))


def notice_given() -> None:
    """Mark the notice given in this process without giving it (a sweep's
    worker: the process that started the sweep gave it)."""
    global _given
    _given = True


def announce_compile(kernels_cached: Callable[[], bool] | None = None) -> None:
    """Log :func:`compile_notice` (level WARNING) when it is due."""
    notice = compile_notice(kernels_cached)
    if notice is not None:
        LOGGER.warning(notice)
