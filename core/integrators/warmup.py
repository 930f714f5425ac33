"""The first compile on a cold cache, spread over two processes.

The path kernel (``integrators.path.render_rows``, with its fragments inlined) calls some
forty helpers that numba compiles as functions of their own (the BSDF dispatch, the
sampler, media, lights, the film splat). numba compiles in one thread per process, but its
on-disk cache is shared: a helper compiled and saved by another process is loaded, not
compiled, when the kernel's type inference reaches its call. So on a cold cache ``render``
starts a second Python process that compiles the helpers of ``HELPER_GROUP`` while this one
builds the BVH (compiling its builder) and compiles the other helpers; this one then waits for the
second to finish (``finish``), so that no helper is compiled twice, and compiles the
kernel's own body.
On a machine with one core, with ``SPECTRAL_GI_PARALLEL_COMPILE=0``, or when anything
about the second process fails, everything is compiled here as before: the second
process only ever saves work.

Compiling a helper ahead needs its exact argument types, which come from the kernel's
type inference. They are recorded in ``compile_plan.py`` by

    python benchmarks/compile_bench.py --record

(run after changing a helper's arguments or the arrays ``prepare`` hands the kernel;
tests/test_warmup.py fails when the record and the kernel disagree).
"""
from __future__ import annotations

import glob
import importlib
import os
import subprocess
import sys

# compiled by the second process: the BSDF dispatch (every model's eval and sample), the
# emitter sampling, the film add (with its splat) and the sampler's draws; this process
# builds the BVH (compiling its builder) and compiles the rest of the helpers meanwhile.
# The plan is the Cornell box's kernel (no media, no image textures: core/integrators/path.py
# render_rows), so neither the scattering in media nor the textures are in it
HELPER_GROUP = frozenset({"bsdf_eval", "bsdf_sample", "_emitter_sample", "_film_add", "rnd_f", "rnd2"})

_PKG = __name__.rsplit(".core.", 1)[0]
_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# run by the second process: import this package under its own name (Blender loads it as
# bl_ext.<repository>.spectral_gi) without running its __init__ (which imports bpy code),
# then compile the helper group
_BOOT = """
import importlib, sys, types
pkg, root = sys.argv[1], sys.argv[2]
parts = pkg.split(".")
for i in range(1, len(parts) + 1):
    name = ".".join(parts[:i])
    if name not in sys.modules:
        m = types.ModuleType(name)
        m.__path__ = [root] if i == len(parts) else []
        sys.modules[name] = m
print(importlib.import_module(pkg + ".core.integrators.warmup").compile_group(True))
"""


def _types_namespace():
    from numba.core import types

    ns = dict(vars(types))
    ns["bool"] = types.boolean
    ns["Record"] = _record_type
    ns["literal"] = types.literal
    return ns


def _record_type(mod, name, field_types):
    """The numba type of a record (a NamedTuple class ``name`` of module ``mod`` under core)
    with fields of ``field_types``, as numba types an instance of it."""
    from numba.core import types

    cls = getattr(importlib.import_module(f"{_PKG}.core.{mod}"), name)
    return types.BaseTuple.from_types(tuple(field_types), cls)


def _type_repr(ty):
    """numba's repr of a type, which ``plan`` evaluates back, but for records (named tuples):
    ``Record(module under core, class name, (field types,))``, tuples holding them, and
    literals (a flag the kernel's branch pruning left constant): ``literal(value)``."""
    from numba.core import types

    if isinstance(ty, types.BaseNamedTuple):
        cls = ty.instance_class
        fields = "".join(_type_repr(t) + ", " for t in ty.types)
        return f"Record({cls.__module__.split('.core.', 1)[1]!r}, {cls.__name__!r}, ({fields.rstrip()}))"
    if isinstance(ty, types.Literal):
        return f"literal({ty.literal_value!r})"
    if isinstance(ty, types.Tuple) and any(isinstance(t, types.Literal) for t in ty.types):
        return "Tuple((" + "".join(_type_repr(t) + ", " for t in ty.types).rstrip(", ") + "))"
    return repr(ty)


def _signature_repr(args):
    """The repr of a tuple of argument types (as ``repr(tuple(args))``, records by ``_type_repr``)."""
    reprs = [_type_repr(a) for a in args]
    return "(" + ", ".join(reprs) + ("," if len(reprs) == 1 else "") + ")"


def plan():
    """[(module under core, function name, numba argument types)] of the recorded helpers."""
    from .compile_plan import PLAN

    ns = _types_namespace()
    return [(mod, name, tuple(eval(sig, ns))) for mod, name, sig in PLAN]


def _dispatcher(mod, name):
    return getattr(importlib.import_module(f"{_PKG}.core.{mod}"), name)


def compile_group(helper):
    """Compile (or load from the cache) the recorded helpers of the second process's group
    (``helper`` True) or of this process's. A helper whose record no longer matches is
    still compiled for the recorded types (wasted, not wrong: the kernel compiles what
    it needs when it needs it). Returns the number of helpers handled."""
    import numba.core.config  # noqa: F401  (jit sets the cache folder on import)

    from .. import jit  # noqa: F401

    try:
        entries = plan()
    except Exception:  # noqa: BLE001 - no record (or an unreadable one): nothing to do ahead
        return 0
    n = 0
    for mod, name, sig in entries:
        if (name in HELPER_GROUP) != helper:
            continue
        try:
            _dispatcher(mod, name).compile(sig)
            n += 1
        except Exception:  # noqa: BLE001 - best effort: the kernel's own compile follows
            pass
    return n


def kernels_compiled():
    """True if the path kernel is already compiled in this process."""
    from .path import render_rows
    return bool(render_rows.signatures)


def kernel_cached():
    """True if numba's cache folder already holds the path kernel (a warm start)."""
    from .path import render_rows

    try:
        index = render_rows._cache._cache_file._index_path
    except AttributeError:  # a numba without these internals: assume warm, do nothing
        return True
    return os.path.exists(index) or bool(glob.glob(os.path.join(os.path.dirname(index), "path.render_rows-*.nbi")))


WAIT_MESSAGE = "Waiting for the kernels being compiled in the background"


def hold_compile(say=None, should_cancel=None, poll=0.1):
    """Take ``jit.COMPILE_LOCK`` for a cold start. When another thread of this process holds
    it (a render or the add-on's background compile is compiling the kernels), say
    ``WAIT_MESSAGE`` and wait, asking ``should_cancel()`` every ``poll`` seconds. Returns True
    once held (the caller releases it), False when cancelled while waiting."""
    from ..jit import COMPILE_LOCK

    if COMPILE_LOCK.acquire(blocking=False):
        return True
    if say is not None:
        say(WAIT_MESSAGE)
    while True:
        if should_cancel is not None and should_cancel():
            return False
        if COMPILE_LOCK.acquire(timeout=poll):
            return True


def release_compile():
    from ..jit import COMPILE_LOCK

    COMPILE_LOCK.release()


def command():
    """The second process's command line and environment, or None when this interpreter
    cannot start one. Only a Python executable is started (in Blender, sys.executable is
    the bundled Python since 2.91; an older Blender binary given ``-c`` would do something
    else entirely), and it gets this process's module search path: Blender adds the
    extension's wheels (numba among them) to sys.path at run time, which a bare interpreter
    would not see."""
    exe = sys.executable or ""
    if not os.path.basename(exe).lower().startswith("python") or not os.path.isfile(exe):
        return None
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p and os.path.isdir(p))
    return [exe, "-c", _BOOT, _PKG, _ROOT], env


def start():
    """Start the second process if the kernel is not compiled yet, in this process or in the
    cache, and this machine has a second core. Returns the Popen or None."""
    if os.environ.get("SPECTRAL_GI_PARALLEL_COMPILE", "1") == "0" or (os.cpu_count() or 1) < 2:
        return None
    try:
        cmd = command()
        if cmd is None or kernels_compiled() or kernel_cached():
            return None
        argv, env = cmd
        return subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL, env=env)
    except Exception:  # noqa: BLE001 - no second process: compile everything here
        return None


def finish(proc, grace=0.0):
    """Let the second process end on its own for at most ``grace`` seconds, then stop it.

    Called before the kernel's own compile with the time this process has worked as the
    grace: the second process has then saved its group, so the kernel's type inference
    loads those helpers from the cache instead of compiling them a second time here; one
    still running after that is stuck or far behind, and what it has not saved is compiled
    here. ``render`` calls it again (grace 0) whatever happens, so no process outlives it."""
    if proc is None:
        return
    try:
        proc.wait(timeout=max(0.0, grace))
    except subprocess.TimeoutExpired:  # still running: stopped below
        pass
    try:
        if proc.poll() is None:
            proc.kill()
        proc.wait(timeout=10)
    except Exception:  # noqa: BLE001
        pass


# ------------------------------------------------------------------ recording the plan

def record():
    """The helpers the path kernel calls and their argument types, from numba's type
    inference of the kernel for the argument types of a compile or cache load in this
    process (render something first): those of a scene without media and textures (the
    Cornell box: its media and texture records None) when there is one, else the last.
    [(module under core, name, types repr)]."""
    from numba.core import compiler, types
    from numba.core.compiler import CompilerBase, DefaultPassBuilder
    from numba.core.registry import cpu_target
    from numba.core.typed_passes import NopythonTypeInference

    from .path import render_rows

    if not render_rows.signatures:
        raise RuntimeError("record(): render something first (the kernel's argument types are taken from it)")

    class _TypeOnly(CompilerBase):
        def define_pipelines(self):
            pm = DefaultPassBuilder.define_untyped_pipeline(self.state)
            pm.add_pass(NopythonTypeInference, "nopython frontend")
            pm.finalize()
            return [pm]

    flags = compiler.Flags()
    flags.nrt = True
    flags.error_model = "numpy"
    tctx = cpu_target.typing_context
    cctx = cpu_target.target_context
    tctx.refresh()
    cctx.refresh()
    sigs = [s for s in render_rows.signatures
            if all(isinstance(s[k], types.NoneType) for k in (8, 9, 14))]  # no media, textures, visibility
    c = _TypeOnly(tctx, cctx, None, (sigs or render_rows.signatures)[-1], None, flags, {})
    try:
        c.compile_extra(render_rows.py_func)
    except AttributeError:  # no lowering in this pipeline: no compile result to return
        pass
    st = c.state
    found = set()
    for expr, sig in st.calltypes.items():
        if getattr(expr, "op", None) != "call":
            continue
        fnty = st.typemap[expr.func.name]
        if isinstance(fnty, types.Dispatcher):
            f = fnty.dispatcher.py_func
            found.add((f.__module__.split(".core.", 1)[1], f.__name__, _signature_repr(sig.args)))
    return sorted(found)


def write_plan(entries, path=None):
    """Write ``compile_plan.py`` (atomically)."""
    from ..io.atomic import write_text

    lines = ['"""The path kernel\'s separately compiled helpers and their argument types (numba type',
             'reprs), recorded by `python benchmarks/compile_bench.py --record`; see core/warmup.py."""',
             "PLAN = ["]
    for mod, name, sig in entries:
        lines.append(f"    ({mod!r}, {name!r},")
        lines.append(f"     {sig!r}),")
    lines.append("]")
    write_text(path or os.path.join(os.path.dirname(os.path.abspath(__file__)), "compile_plan.py"),
               "\n".join(lines) + "\n")

