"""The scene's features as compile-time flags: the Newton kernel is
compiled per family of scenes, and the code of a feature the scene lacks is
not compiled.

The flags, module constants that the kernels import (True here: every
feature, the kernels as Python and the tests call them):

* ``FRICTION``: the seabed's friction springs (:mod:`.contact`'s
  ``friction_*``), in a scene whose friction coefficients may act (the
  axial one, and in 3D the lateral one, above 0);
* ``STINGER``: the stinger's supports: its curve, whose contacts are held
  in curve coordinates, the rigid points (its tip, the rollers), the
  lateral hold, and the boundaries above touchdown (lift-off, the points'
  nodes) with the transport of the mesh along the pipe they move (S-lay).

A kernel reads a flag as ``if FRICTION:``. numba removes a branch on a
global constant before typing (its dead-branch pruning, also in a phase
after it is inlined), so the feature's code is neither typed nor lowered,
and the kernels only it calls are not compiled. :func:`in_scene` gives a
kernel compiled for a :class:`Scene`: a copy of its function whose globals
bind the flags to the scene's values and every callee that depends on them
(phases included) to that callee's copy, under a name of its own, so that
numba caches each family apart (the cache's key does not hold a function's
globals). A kernel that reads no flag, directly or through its callees (the
element chain, the banded solver), is shared by every family. The engine
picks the family from the problem (:attr:`pipelay_fast.engine.state.Problem.scene`).
"""

from __future__ import annotations

import types as pytypes
from collections import namedtuple

import numba
from numba.core.registry import CPUDispatcher

from ._jit import recompiled

Scene = namedtuple("Scene", ["friction", "stinger"])
Scene.__doc__ = """The features a scene's Newton kernel is compiled with (module docstring)."""

ALL = Scene(True, True)
"""Every feature: the kernels as defined (the flags' values below)."""

FRICTION = ALL.friction
STINGER = ALL.stinger

_FLAGS = {"FRICTION": "friction", "STINGER": "stinger"}  # global name -> Scene field

_depends: dict = {}  # dispatcher -> whether it reads a flag, itself or through a callee
_copies: dict = {}  # (dispatcher, scene) -> its copy for the scene


def union(a: Scene, b: Scene) -> Scene:
    """The scene with the features of ``a`` or ``b``."""
    return Scene(*(x or y for x, y in zip(a, b, strict=True)))


def tag(scene: Scene) -> str:
    """The suffix of a family's kernel names (numba's cache files): the
    features it is compiled without, "" for :data:`ALL`."""
    absent = [name for name, present in zip(Scene._fields, scene, strict=True) if not present]
    return "without_" + "_".join(absent) if absent else ""


def _names(code) -> set:
    """The global (and attribute) names a code object and those nested in it read."""
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, pytypes.CodeType):
            names |= _names(const)
    return names


def depends_on_scene(dispatcher) -> bool:
    """Whether the kernel (or phase) reads a flag, itself or through a kernel it calls."""
    if dispatcher not in _depends:
        _depends[dispatcher] = False  # (kernels do not recurse)
        glob = dispatcher.py_func.__globals__
        _depends[dispatcher] = any(
            name in _FLAGS or (isinstance(glob.get(name), CPUDispatcher)
                               and depends_on_scene(glob[name]))
            for name in _names(dispatcher.py_func.__code__))
    return _depends[dispatcher]


def in_scene(kernel, scene: Scene):
    """``kernel`` compiled for ``scene`` (module docstring): the kernel itself
    for :data:`ALL`, for a kernel that depends on no flag, and under
    ``NUMBA_DISABLE_JIT`` (a Python function, every feature present)."""
    if (scene == ALL or numba.config.DISABLE_JIT or not isinstance(kernel, CPUDispatcher)
            or not depends_on_scene(kernel)):
        return kernel
    key = (kernel, scene)
    if key not in _copies:
        f = kernel.py_func
        glob = dict(f.__globals__)
        for name in _names(f.__code__):
            if name in _FLAGS:
                glob[name] = getattr(scene, _FLAGS[name])
            elif isinstance(glob.get(name), CPUDispatcher):
                glob[name] = in_scene(glob[name], scene)
        copy = pytypes.FunctionType(f.__code__, glob, f.__name__, f.__defaults__, f.__closure__)
        copy.__kwdefaults__ = f.__kwdefaults__
        copy.__module__ = f.__module__
        copy.__qualname__ = f"{f.__qualname__}__{tag(scene)}"
        _copies[key] = recompiled(kernel, copy)
    return _copies[key]
