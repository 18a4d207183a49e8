"""A first compile in two processes: a helper process compiles, into numba's
on-disk cache, kernels that the process solving will call, while that process
compiles the others; each loads from the cache what the other has finished.

numba compiles a kernel's callees as it types the kernel's calls, one after
the other, one core busy; the cache (``cache=True``, :mod:`pipelay_fast.kernels._jit`) is read
again at each callee's compile, so a callee that another process has
compiled meanwhile is loaded, not compiled. The helper needs the exact
signatures of the callees, which exist only as numba types them:
:func:`typed_calls` types the kernel and all its callees without compiling
any of them (numba's front end and type inference, no lowering), and lists
each kernel compile the solving process would make, in the order it would
make them. The helper (:func:`build`) takes them from the end of that order
backwards, each one whose callees are ready (compiled by itself, or found in
the cache), while the solving process compiles from the start: they meet in
between. It stops when the kernel itself is in the cache (the solving process
has compiled it), or when the process that started it is gone.

:func:`start` runs the helper, ``python -c ...helper_main()``,
given the kernel (module, name, scene) and its arguments on stdin (pickled).
Nothing of the answer depends on it: the machine code is the same whichever
process compiles it, and when the helper fails or is absent the solving
process compiles everything itself.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import pickle
import subprocess
import sys
import time
from collections import namedtuple

import numba
from numba.core import compiler, typing
from numba.core.caching import NullCache
from numba.core.compiler_machinery import FunctionPass, register_pass
from numba.core.dispatcher import Dispatcher
from numba.core.registry import CPUDispatcher
from numba.core.typed_passes import NopythonTypeInference

from ..kernels._jit import _PACKAGE_DIR, kernels_cached
from ..kernels.scene import Scene, in_scene, tag

POLL_S = 0.1
"""How often [s] the helper looks for the callees the solving process is
compiling (a kernel's compile takes 0.1 to 10 s: a poll costs a few file
reads)."""

Call = namedtuple("Call", ["kernel", "args", "callees"])
Call.__doc__ = """One compile of a kernel: the dispatcher, its argument
types, and the indices (in :func:`typed_calls`' list) of the kernels it calls."""


@register_pass(mutates_CFG=False, analysis_only=True)
class _TypedOnly(FunctionPass):
    """Stop after type inference: the result is the return type."""

    _name = "pipelay_typed_only"

    def __init__(self):
        FunctionPass.__init__(self)

    def run_pass(self, state):
        state.cr = state.return_type
        return False


class _TypingPipeline(compiler.CompilerBase):
    """numba's nopython pipeline up to type inference (inlining and the dead
    branches of :mod:`pipelay_fast.kernels.scene`'s flags pruned as for a compile)."""

    def define_pipelines(self):
        pm = compiler.DefaultPassBuilder.define_untyped_pipeline(self.state)
        pm.add_pass(NopythonTypeInference, "nopython frontend")
        pm.add_pass(_TypedOnly, "typed only")
        pm.finalize()
        return [pm]


def _return_type(kernel, args):
    """The return type of ``kernel`` for argument types ``args`` (typed, not compiled)."""
    flags = compiler.Flags()
    kernel.targetdescr.options.parse_as_flags(flags, kernel.targetoptions)
    return compiler.compile_extra(kernel.targetdescr.typing_context,
                                  kernel.targetdescr.target_context, kernel.py_func,
                                  args=args, return_type=None, flags=flags, locals=kernel.locals,
                                  pipeline_class=_TypingPipeline)


def cached(kernel, args) -> bool:
    """Whether ``kernel`` has machine code for ``args`` in this process or in
    numba's cache (its index read, nothing loaded)."""
    args = tuple(args)
    if args in kernel.overloads:
        return True
    cache = kernel._cache
    if isinstance(cache, NullCache):
        return False
    key = cache._index_key(args, kernel.targetctx.codegen())
    return key in cache._cache_file._load_index()


def typed_calls(kernel, args) -> list[Call]:
    """Every kernel compile that calling ``kernel`` with argument types
    ``args`` makes in a process that holds none of them, in the order it makes
    them (a kernel after its callees; ``kernel`` last); none is compiled.
    A kernel already compiled or in the cache is not typed again (nor its
    callees: they are loaded with it)."""
    calls: list[Call] = []
    index: dict = {}
    stack: list[list] = [[]]
    typed: dict = {}  # dispatcher -> the signatures typed here

    def compile_typed(self, sig):
        args = tuple(sig)
        key = (self, args)
        if key in index:
            stack[-1].extend(index[key])
            return None
        if isinstance(self._cache, NullCache):  # (an overload's implementation, numba's
            # own): not cached, so compiled in each caller's process; its callees are
            # its caller's
            ret = _return_type(self, args)
            index[key] = []
        elif cached(self, args):  # loaded, with its callees
            Dispatcher.compile(self, args)
            ret = None
            index[key] = []
        else:
            stack.append([])
            ret = _return_type(self, args)
            calls.append(Call(self, args, sorted(set(stack.pop()))))
            index[key] = [len(calls) - 1]
        if ret is not None:
            typed.setdefault(self, []).append(typing.signature(ret, *args))
        stack[-1].extend(index[key])
        return None

    def nopython_signatures(self):
        return ([c.signature for c in self.overloads.values() if not c.objectmode]
                + typed.get(self, []))

    def get_overload(self, args):  # (typed, no machine code: None)
        cres = self.overloads.get(tuple(args))
        return None if cres is None else cres.entry_point

    with _patched(compile=compile_typed, nopython_signatures=property(nopython_signatures),
                  get_overload=get_overload):
        compile_typed(kernel, args)
    return calls


@contextlib.contextmanager
def _patched(**attributes):
    """numba's dispatchers (ours, its overloads') with ``attributes`` replaced, in the block."""
    saved = [(CPUDispatcher, name, CPUDispatcher.__dict__.get(name)) for name in attributes]
    for cls, name, _ in saved:
        setattr(cls, name, attributes[name])
    try:
        yield
    finally:
        for cls, name, old in saved:
            if old is None:
                delattr(cls, name)
            else:
                setattr(cls, name, old)


def build(calls: list[Call], alive=lambda: True) -> int:
    """Compile ``calls`` (:func:`typed_calls`) but the last (the kernel
    itself) from the end backwards, each once its callees are ready, until
    the kernel is cached or ``alive()`` is false. Returns how many it compiled."""
    if not calls:
        return 0
    root = calls[-1]
    pending = list(range(len(calls) - 1))[::-1]
    done = set()
    built = 0
    while pending and alive() and not cached(root.kernel, root.args):
        for i in pending:
            call = calls[i]
            if cached(call.kernel, call.args):
                done.add(i)
            elif all(c in done for c in call.callees):
                call.kernel.compile(call.args)
                done.add(i)
                built += 1
            else:
                continue
            pending.remove(i)
            break
        else:
            for i in pending:  # a callee the solving process compiles: ready once cached
                for c in calls[i].callees:
                    if c not in done and cached(calls[c].kernel, calls[c].args):
                        done.add(c)
            time.sleep(POLL_S)
    return built


def kernel_of(module: str, name: str, scene):
    """The kernel ``module.name`` compiled for ``scene`` (``kernels.scene.in_scene``)."""
    return in_scene(getattr(importlib.import_module(module), name), scene)


def start(module: str, name: str, scene, args) -> subprocess.Popen | None:
    """Start the helper for kernel ``module.name`` of family ``scene``, to be
    called with ``args`` (values, pickled to it); None when it cannot start
    (the caller then compiles everything, as without it)."""
    if numba.config.DISABLE_JIT:
        return None
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [os.path.dirname(_PACKAGE_DIR)] + [p for p in [env.get("PYTHONPATH")] if p])
    try:
        proc = subprocess.Popen([sys.executable, "-c", _HELPER], stdin=subprocess.PIPE,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
        pickle.dump((os.getpid(), module, name, tuple(scene), args), proc.stdin)
        proc.stdin.close()
    except (OSError, pickle.PicklingError, ValueError):
        return None
    return proc


_started: set = set()  # the kernels this process has started a helper for


@contextlib.contextmanager
def alongside(module: str, name: str, scene, args):
    """Around a call of kernel ``module.name`` of family ``scene`` with
    ``args``: the helper compiles with it when this is the kernel's first
    call in the process and numba's cache does not hold it; ended after."""
    kernel = kernel_of(module, name, scene)
    proc = None
    if (isinstance(kernel, CPUDispatcher) and kernel not in _started and not kernel.overloads
            and not kernels_cached(tag(scene))):
        _started.add(kernel)
        proc = start(module, name, scene, args)
    try:
        yield kernel
    finally:
        stop(proc)


_HELPER = f"import sys; from {__name__} import helper_main; sys.exit(helper_main())"


def stop(proc: subprocess.Popen | None) -> None:
    """End the helper (its cache writes are atomic: numba replaces whole files)."""
    if proc is not None and proc.poll() is None:
        proc.terminate()
        with contextlib.suppress(subprocess.TimeoutExpired):
            proc.wait(timeout=5)


def helper_main() -> int:
    """The helper process: its kernel and arguments from stdin (:func:`start`)."""
    parent, module, name, scene, args = pickle.load(sys.stdin.buffer)
    kernel = kernel_of(module, name, Scene(*scene))
    calls = typed_calls(kernel, tuple(numba.typeof(a) for a in args))
    build(calls, alive=lambda: os.getppid() == parent)
    return 0

