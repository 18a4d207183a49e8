"""The one JIT policy of pipelay_fast.

Every kernel is compiled with :func:`jit`, never with a bare ``numba.njit``:

* ``cache=True`` so that worker processes and later sessions load machine code
  from numba's cache instead of recompiling (``benchmarks/bench_compile.py``
  measures a first solve in a fresh cache and a cached start);
* each kernel compiled once for its callers' plain argument types, and the
  element chain once per dimension (:func:`plain_calls`, ``by_dimension``);
* ``nopython`` (``njit``): no object mode, no Python objects inside kernels;
* ``error_model="numpy"``: a division by zero gives inf/nan instead of raising,
  so kernels need no exception handling; kernels report failure through status
  codes that the Python layer turns into :class:`pipelay_fast.SolveError`;
* ``fastmath`` stays off: the 2D and 3D kernels must agree to round-off and the
  finite-difference tangent tests compare to ~1e-7;
* no calling wrappers but where they are used: numba builds each function a
  CPython wrapper (Python's call: unboxing every argument) and a C wrapper (a
  function pointer), and optimises and compiles both again in every caller's
  module. Only the kernels the Python layer calls, ``jit(entry=True)``, keep
  the CPython wrapper; none keeps the C wrapper (the first compile,
  ``bench_compile.py``). A call from Python of any other kernel (tests,
  benchmarks) goes to a copy compiled with the wrapper (:class:`Kernel`).

Numba checks a cached kernel against its own source file only, not against the
callees and constants it took from other modules. So, when this module is
imported (before any kernel is compiled or loaded), :func:`expire_stale_cache`
hashes the sources of every module that defines kernels (:func:`kernel_sources`)
with numba's version, compares the digest with the stamp file
:data:`STAMP_NAME` in the cache directory numba will use for them, and on a
difference deletes those modules' cache files (``*.nbi``, ``*.nbc``) and writes
the new stamp. An edited kernel module therefore never runs stale machine code;
the cost is one recompilation after each edit, and about a millisecond per
import otherwise. Failures (a read-only install, a file another process has
just removed) are ignored: the import never fails because of the cache.
"""

from __future__ import annotations

import collections
import gc
import hashlib
import inspect
import os
import sys
import tempfile
import types as pytypes

import numba
from numba.core import types
from numba.core.caching import NullCache
from numba.core.compiler_lock import global_compiler_lock
from numba.core.registry import CPUDispatcher

KERNEL_DIR = os.path.dirname(os.path.abspath(__file__))
_PACKAGE_DIR = os.path.dirname(KERNEL_DIR)
STAMP_NAME = "pipelay_fast-kernels.sha256"


def jit(func=None, *, by_dimension=False, entry=False, **overrides):
    """Decorate a kernel with the project's numba policy (see module docstring).

    ``by_dimension``: the kernel is compiled for its callers' dimension, its
    argument ``nd`` a literal 2 or 3 (:func:`plain_calls`), so that its loops
    over components have constant bounds and a dimension's choice between
    kernels is made when it is typed (:func:`.assembly.element_forces`:
    a planar solve never compiles the spatial element). The Newton kernel's
    entries :func:`.newton.newton_2d` and ``newton_3d`` give it.

    ``entry``: the Python layer calls the kernel, which is compiled with
    numba's CPython wrapper; the others are :class:`Kernel`.

    ``_nrt`` (numba's reference counting) is required but for a phase: True
    when the kernel, or a phase inlined into it, creates an array; False
    when it does not (its arrays' counts then cost nothing). numba compiles
    a kernel that does not set it with its first caller's setting, so an
    allocating kernel first reached from one without counting would fail to
    compile (``tests/test_jit_cache.py``: :func:`.system._system`, first
    reached from ``system_2d``)."""
    options = {"nopython": True, "boundscheck": None, "cache": True, "nogil": True,
               "error_model": "numpy",
               "no_cfunc_wrapper": True, "no_cpython_wrapper": not entry}
    options.update(overrides)
    if "_nrt" not in options and "inline" not in options:
        raise TypeError("a kernel says whether it allocates: jit(_nrt=True) if it (or a phase "
                        "inlined into it) creates an array, jit(_nrt=False) if not (numba "
                        "compiles a kernel without its own setting with its first caller's)")
    keep = ("nd",) if by_dimension else ()

    def compiled(f):
        if numba.config.DISABLE_JIT:  # as numba's own decorators: the Python function
            return f
        return plain_calls(_dispatcher(Entry if entry else Kernel, f, options), keep)

    return compiled if func is None else compiled(func)


def _dispatcher(kind, f, options):
    """numba's dispatcher of class ``kind`` for ``f``, its target options
    ``options`` but ``cache`` (which enables numba's on-disk cache)."""
    targetoptions = {k: v for k, v in options.items() if k != "cache"}
    dispatcher = kind(py_func=f, locals={}, targetoptions=targetoptions)
    if options.get("cache"):
        dispatcher.enable_caching()
    return dispatcher


CALLS_FROM_PYTHON: collections.Counter = collections.Counter()
"""How many times Python called each :class:`Kernel` (by qualified name): none
in a solve (``tests/test_jit_cache.py``)."""


class Entry(CPUDispatcher):
    """A kernel the Python layer calls (``jit(entry=True)``). While it is
    compiled, with every kernel it calls, the objects that existed before
    are out of reach of Python's cyclic garbage collector (``gc.freeze``),
    and back when it returns: numba's compiler allocates enough to run some
    20 full collections over a first solve, each a pass over every live
    object, the interpreter's, numpy's and numba's own included (some 7 % of
    a first solve's CPU time); frozen, a collection passes over what the
    compiler made since. Not when the program has frozen objects of its own
    (``gc.get_freeze_count``), which are left as they are."""

    def compile(self, sig):
        with global_compiler_lock:  # (reentrant) one compile at a time freezes
            if gc.get_freeze_count():
                return super().compile(sig)
            gc.freeze()
            try:
                return super().compile(sig)
            finally:
                gc.unfreeze()


class Kernel(CPUDispatcher):
    """A kernel called by other kernels only, compiled without numba's CPython
    wrapper (the module docstring). numba's own call of such a function from
    Python would crash; here Python's call goes to a copy of the kernel
    compiled with the wrapper, under a name of its own so that its cache files
    are its own (numba's cache index does not tell the two apart). Tests call
    kernels that way; the Python layer calls only ``jit(entry=True)``
    kernels."""

    def __call__(self, *args, **kws):
        CALLS_FROM_PYTHON[self.py_func.__qualname__] += 1
        return self.from_python()(*args, **kws)

    def from_python(self) -> CPUDispatcher:
        """The copy of this kernel that Python calls (made on first use)."""
        twin = self.__dict__.get("_from_python")
        if twin is None:
            f = self.py_func
            copy = pytypes.FunctionType(f.__code__, f.__globals__, f.__name__, f.__defaults__,
                                        f.__closure__)
            copy.__kwdefaults__ = f.__kwdefaults__
            copy.__module__ = f.__module__
            copy.__qualname__ = f.__qualname__ + "__from_python"
            twin = _dispatcher(CPUDispatcher, copy, {
                **self.targetoptions, "no_cpython_wrapper": False,
                "cache": not isinstance(self._cache, NullCache)})
            self.__dict__["_from_python"] = twin
        return twin


def plain_calls(dispatcher, keep=()):
    """Compile ``dispatcher`` for its callers' plain argument types, never for
    a literal value (but for the arguments named in ``keep``): numba types a
    constant argument (``want_tangent=False``, ``nd`` written as 2) as a
    literal and compiles one more specialisation of the callee, and of
    everything it calls, for each: the element kernels, called with literal
    flags from several places, would be compiled several times over."""
    get = dispatcher.get_call_template
    kept = [name in keep for name in inspect.signature(dispatcher.py_func).parameters]

    def get_call_template(args, kws):
        return get(tuple(a if i < len(kept) and kept[i] else types.unliteral(a)
                         for i, a in enumerate(args)),
                   {k: v if k in keep else types.unliteral(v) for k, v in kws.items()})

    dispatcher.get_call_template = get_call_template
    return dispatcher


def phase(func):
    """Decorate one phase of a kernel: :func:`jit`, inlined into its caller at
    numba's IR level (``inline="always"``), so it compiles as part of the
    kernel instead of as a library of its own. Each compiled kernel costs
    numba a fixed share of compile time (its own LLVM module, optimised
    again with every callee linked in), so the Newton kernel's small phases
    are not kernels of their own (``benchmarks/bench_compile.py``). Inlining
    has a cost of its own: numba deep-copies each of the inlined function's
    blocks with the function's whole scope, a cost that grows as blocks
    times variables, and LLVM optimises the caller as one function of the
    size of all its phases. So a phase is to be small, and a large function
    is a kernel even with one caller (the Newton kernel's nodal frames,
    constraint set, border, test, condensed solve, step's start, line search
    and free residual, ``jit(by_dimension=True)``;
    :func:`.newton._newton_kernel` makes the Newton kernel a closure)."""
    return jit(func, inline="always")


def kernel_sources() -> list[str]:
    """The modules of ``kernels/``, this one included: all the sources the kernels compile from."""
    names = sorted(n for n in os.listdir(KERNEL_DIR) if n.endswith(".py"))
    return [os.path.join(KERNEL_DIR, n) for n in names]


def sources_digest(paths) -> str:
    """sha256 over numba's version and each file's name (from the package) and bytes."""
    digest = hashlib.sha256(numba.__version__.encode())
    for path in paths:
        digest.update(os.path.relpath(path, _PACKAGE_DIR).encode() + b"\0")
        with open(path, "rb") as f:
            digest.update(f.read())
    return digest.hexdigest()


def _user_cache_dir() -> str:
    """numba's user-wide cache directory (``appdirs.user_cache_dir("numba")``)."""
    if sys.platform == "win32":
        return os.path.join(os.environ.get("LOCALAPPDATA", ""), "numba", "Cache")
    if sys.platform == "darwin":
        return os.path.expanduser("~/Library/Caches/numba")
    return os.path.join(os.getenv("XDG_CACHE_HOME", os.path.expanduser("~/.cache")), "numba")


def cache_dirs(source_dir: str) -> list[str]:
    """Where numba may cache the kernels of ``source_dir``, in the order it tries them.

    As numba's cache locators: ``NUMBA_CACHE_DIR`` (``numba.config.CACHE_DIR``) if
    set, else ``__pycache__`` beside the sources, else (not writable) the user-wide
    cache; the two outside the tree mirror ``source_dir`` as ``<name>_<sha1 of path>``.
    """
    mirror = "_".join([os.path.basename(source_dir), hashlib.sha1(source_dir.encode()).hexdigest()])
    if numba.config.CACHE_DIR:
        return [os.path.join(numba.config.CACHE_DIR, mirror)]
    return [os.path.join(source_dir, "__pycache__"), os.path.join(_user_cache_dir(), mirror)]


NEWTON_CACHE_PREFIX = "newton._newton_kernel"  # numba's index file of the Newton kernel


def kernels_cached() -> bool:
    """Whether numba's cache holds the Newton kernel's machine code for these
    sources (stale files are gone at import, :func:`expire_stale_cache`): when
    it does not, the first solve compiles the kernels (for how long:
    ``benchmarks/bench_compile.py``), and the command line says so."""
    for cache_dir in cache_dirs(KERNEL_DIR):
        try:
            names = os.listdir(cache_dir)
        except OSError:
            continue
        if any(n.startswith(NEWTON_CACHE_PREFIX) and n.endswith(".nbi") for n in names):
            return True
    return False


def _writable(path: str) -> bool:
    """numba's test of a cache directory: it can be created and written to."""
    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except OSError:
        return False
    return True


def expire(cache_dir: str, digest: str, modules) -> bool:
    """Delete the cache files of ``modules`` (file stems) in ``cache_dir`` unless its
    stamp equals ``digest``, then stamp it. False when that could not be done."""
    stamp = os.path.join(cache_dir, STAMP_NAME)
    try:
        with open(stamp) as f:
            if f.read() == digest:
                return True
    except OSError:
        pass
    try:
        names = os.listdir(cache_dir)
    except FileNotFoundError:
        names = []
    except OSError:
        return False
    for name in names:
        if name.endswith((".nbi", ".nbc")) and name.split(".", 1)[0] in modules:
            try:
                os.remove(os.path.join(cache_dir, name))
            except FileNotFoundError:
                pass  # another process has just removed it
            except OSError:
                return False
    try:
        os.makedirs(cache_dir, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=cache_dir, prefix=f".{STAMP_NAME}.")
        with os.fdopen(fd, "w") as f:
            f.write(digest)
        os.replace(tmp, stamp)  # concurrent importers each write a whole stamp
    except OSError:
        return False
    return True


def expire_stale_cache() -> None:
    """Drop the kernels' cached machine code if any kernel source has changed (see above)."""
    try:
        sources = kernel_sources()
        digest = sources_digest(sources)
    except OSError:  # sources unreadable (e.g. a zip or frozen install): nothing to compare
        return
    modules = {os.path.splitext(os.path.basename(path))[0] for path in sources
               if os.path.dirname(path) == KERNEL_DIR}  # numba names cache files by module
    for cache_dir in cache_dirs(KERNEL_DIR):
        if _writable(cache_dir):  # the directory numba will use
            expire(cache_dir, digest, modules)
            return


expire_stale_cache()
