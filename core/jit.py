"""The project's single Numba decorator policy.

Every kernel in core is compiled with ``cache=True`` (the on-disk cache makes the
second start fast) and ``nogil=True`` (so Blender's UI thread keeps running while a
kernel works). Fast-math flags are off: NaN and Inf must behave as IEEE says, because the
renderer tests for them. No other module calls ``numba.njit`` directly; a test
enforces it.
"""
import hashlib
import os
import sys
import threading
from pathlib import Path


import numba
import numba.core.caching
import numba.core.config


def _host_cpu():
    """The CPU the kernels are compiled for (LLVM's name and feature string)."""
    try:
        from llvmlite import binding

        return binding.get_host_cpu_name() + binding.get_host_cpu_features().flatten()
    except Exception:  # noqa: BLE001 - an llvmlite without these: numba's index still checks the CPU
        return ""


def _source_key():
    """Hash of every source under ``core/`` (any of them can hold a kernel or a helper it
    inlines or calls), of numba's version and of the CPU.

    numba's cache notices edits to the file holding an entry kernel but not to callees
    in other files, so the cache folder is keyed by all of them. The same sources on the
    same CPU under the same import name share one folder, wherever that copy of the package
    lies: every checkout or pip install (``spectral_gi``) shares one, every install and
    reinstall of the Blender extension (``bl_ext.<repo>.spectral_gi``) another.
    """
    core = Path(__file__).resolve().parent
    h = hashlib.sha256(numba.__version__.encode())
    h.update(_host_cpu().encode())
    # the package's import name: numba's cached code refers to its modules by name, so a copy
    # imported under another name (the extension, bl_ext.<repo>.spectral_gi) cannot load them
    h.update(__name__.encode())
    sources = list(core.rglob("*.py"))
    for p in sorted(sources):
        h.update(p.relative_to(core).as_posix().encode())
        h.update(p.read_bytes())
    return h.hexdigest()[:16]


def _cache_base():
    """The user's cache folder for compiled kernels: ``$SPECTRAL_GI_CACHE_DIR`` or
    ``$NUMBA_CACHE_DIR`` when set, else the platform's per-user cache (``$XDG_CACHE_HOME``
    or ``~/.cache`` on Linux, ``~/Library/Caches`` on macOS, ``%LOCALAPPDATA%`` on Windows)."""
    base = os.environ.get("SPECTRAL_GI_CACHE_DIR") or os.environ.get("NUMBA_CACHE_DIR")
    if base:
        return Path(base)
    if sys.platform == "win32" and os.environ.get("LOCALAPPDATA"):
        return Path(os.environ["LOCALAPPDATA"]) / "spectral-gi" / "numba"
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Caches" / "spectral-gi" / "numba"
    xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(xdg) / "spectral-gi" / "numba"


CACHE_DIR = _cache_base() / _source_key()
# Read by numba when each cached kernel is decorated: set before any kernel module loads.
numba.core.config.CACHE_DIR = str(CACHE_DIR)
_CORE = Path(__file__).resolve().parent


class _CoreCacheLocator(numba.core.caching.UserProvidedCacheLocator):
    """Where numba caches a kernel of this package's ``core``: ``CACHE_DIR`` (keyed by the
    sources, numba, the CPU and the import name), then the module's folder relative to ``core``. numba's own
    locator names that folder by a hash of its absolute path, so each copy of the package
    (a checkout, an install of the extension, a reinstall) would compile everything
    again; with this one every copy with the same sources and import name shares the
    compiled kernels."""

    core = _CORE
    cache_dir = str(CACHE_DIR)

    def __init__(self, py_func, py_file):
        super().__init__(py_func, py_file)
        rel = Path(py_file).resolve().parent.relative_to(self.core)
        self._cache_path = os.path.join(self.cache_dir, *rel.parts, "__kernels__")

    @classmethod
    def from_function(cls, py_func, py_file):
        try:
            Path(py_file).resolve().relative_to(cls.core)
        except ValueError:  # not this copy's core (another copy's locator, or numba's, takes it)
            return None
        return super().from_function(py_func, py_file)


def _install_locator():
    """Put this copy's locator first in numba's list (once per copy of the package)."""
    classes = numba.core.caching.CacheImpl._locator_classes
    if not any(getattr(c, "core", None) == _CORE for c in classes):
        classes.insert(0, _CoreCacheLocator)


_install_locator()

def _process_lock(name="_spectral_gi_kernel_lock"):
    """A lock of this process, shared by every copy of this package that is loaded.

    Blender may hold two copies (an installed extension and a development checkout); they
    share numba, so the locks live on the numba module.
    """
    import numba

    lock = getattr(numba, name, None)
    if lock is None:
        lock = threading.Lock()
        setattr(numba, name, lock)
    return lock


# Held by every launch of a parallel (prange) kernel: numba's threading layers abort the
# process when two threads launch parallel kernels at once, which would take Blender down with them.
KERNEL_LOCK = _process_lock()
# Held by a cold start from the first kernel compile (or cache load) to the end of the path
# kernel's: a second render (or the add-on's background compile) started meanwhile waits for
# it, then finds the kernels loaded, instead of compiling them a second time (and starting a
# second compile process of its own). Not KERNEL_LOCK: the BVH builder takes that one inside
# the compile.
COMPILE_LOCK = _process_lock("_spectral_gi_compile_lock")


_POLICY = dict(cache=True, nogil=True, error_model="numpy")


def kernel(fn=None, *, parallel=False, refcount=True):
    """Compile ``fn`` with the project policy. ``parallel=True`` for prange kernels.

    ``refcount=False`` for a kernel that allocates nothing (its caller passes every scratch
    array): numba's reference counting is left out, as in ``function`` (see there)."""

    def wrap(f):
        if refcount:
            return numba.njit(parallel=parallel, **_POLICY)(f)
        return numba.njit(parallel=parallel, _nrt=False, **_POLICY)(f)

    if fn is not None:
        return wrap(fn)
    return wrap


def inline(fn):
    """Small scalar helper: compiled once per argument types as a function of its own,
    with LLVM's ``alwaysinline`` attribute (numba's ``forceinline`` option), so LLVM
    inlines it into every caller and hot helpers such as the RNG or a table lookup cost
    nothing. Same arithmetic, so the same bits as code written in place.

    Not numba's IR-level inlining (``inline="always"``): that re-types and re-lowers the
    helper's IR at every call site, and the path kernel's first compile spent 40 % of its
    time on the copies. Without reference counting, as ``function`` (see there). Keep it
    for small functions: LLVM optimises every inlined copy."""
    return numba.njit(forceinline=True, _nrt=False, **_POLICY)(fn)


def fragment(fn):
    """A large piece of a kernel's body written as a function of its own (the path
    integrator's camera sample, surface NEE, BSDF step ...), called from one place: numba
    inlines its IR into the caller (``inline="always"``), so it is typed, lowered and
    optimised once, as part of the kernel, and never compiled by itself. The same
    arithmetic as code written in place, so the same bits and speed. Each inlined call
    costs the kernel's compile a fixed amount (numba copies the fragment's IR twice and
    runs its untyped passes) and adds variables to the kernel's SSA pass, so small pieces
    are ``inline`` helpers instead: compiled by themselves in a fraction of a second,
    possibly by the warm-up's second process, and inlined by LLVM. A large fragment
    compiled as an ``inline`` helper would be optimised and code-generated twice, by
    itself and in the kernel (docs/design/numba.md gives the figures). Not for functions
    called from many places (numba's IR inlining types and lowers a copy at every call
    site)."""
    return numba.njit(inline="always", _nrt=False, **_POLICY)(fn)


def function(fn):
    """A large helper called from kernels, compiled as a function of its own.

    For boundaries such as the BSDF dispatch: inlining every model into the path kernel
    made it take over ten minutes to compile; called as a function it compiles once, in
    seconds, for the price of one call per use.

    These helpers allocate nothing, so they are compiled without numba's reference
    counting (the internal option ``_nrt=False``): with it, every array a helper receives
    or an inlined helper binds costs an atomic increment and decrement, and a profile of
    the path tracer found a quarter of its time in NRT_incref/NRT_decref. The caller
    keeps its arrays alive. A helper that allocated would fail to compile.
    """
    return numba.njit(_nrt=False, **_POLICY)(fn)


def set_threads(n):
    """Set the number of threads used by parallel kernels (None: all cores)."""
    if n is None or n <= 0:
        n = numba.config.NUMBA_NUM_THREADS
    n = max(1, min(int(n), numba.config.NUMBA_NUM_THREADS))
    numba.set_num_threads(n)
    return n


def cache_dir():
    """The folder holding this build's compiled kernels."""
    return CACHE_DIR
