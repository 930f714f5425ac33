"""Compiling the kernels in the background as soon as the add-on is enabled.

``start()`` (called on register unless the preference is off) runs ``core.warm_up`` on a
thread of its own: it compiles the kernels a render of the Cornell box needs, or loads
them when the user's cache holds them, so the first F12 usually finds them ready. The
thread never touches bpy; it reports through ``STATE``, which the add-on's preferences
and the render panel show (``status_text``). A render started meanwhile waits for it
(core's compile lock: it says so, and Esc still cancels it) instead of compiling the
kernels a second time. Any exception ends in the ``failed`` phase with its reason; the
first render then compiles the kernels itself, as it would without this.

The compile cannot be interrupted: disabling the add-on meanwhile lets the thread finish
(what it compiles is kept in the cache) and nothing it does touches Blender.
"""
import threading
import time

IDLE, COMPILING, READY, FAILED, OFF = "idle", "compiling", "ready", "failed", "off"


class CompileState:
    """Where the background compile stands. Written by its thread, read by the UI."""

    def __init__(self):
        self.phase = IDLE
        self.detail = ""  # core's last status message during the compile
        self.error = ""  # "Type: message" of a failure
        self.seconds = 0.0  # how long the compile (or load) took
        self.compiled = False  # True when it compiled or loaded kernels; False when they were loaded already
        self.started = 0.0
        self.thread = None
        self.abandoned = False  # the add-on was disabled meanwhile


STATE = CompileState()
_LOCK = threading.Lock()
# False where nobody waits at a UI for the first render (the command line's headless
# driver sets it before it registers the add-on: its render compiles what it needs)
AUTOSTART = True


def status_text(state=None):
    """One line for the preferences and the render panel."""
    state = state or STATE
    if state.phase == COMPILING:
        if state.detail.startswith("Loading"):
            return "Loading compiled kernels…"
        if state.detail.startswith("Waiting"):
            return "Compiling kernels… (waiting for another render's compile)"
        return "Compiling kernels…"
    if state.phase == READY:
        return f"Kernels ready ({state.seconds:.0f} s)" if state.compiled else "Kernels ready"
    if state.phase == FAILED:
        return f"Kernel compile failed: {state.error}"
    if state.phase == OFF:
        return "Background compile off: the first render compiles the kernels"
    return "Kernels not compiled yet"


def status_icon(state=None):
    state = state or STATE
    return {COMPILING: "TIME", READY: "CHECKMARK", FAILED: "ERROR"}.get(state.phase, "INFO")


def running(state=None):
    state = state or STATE
    t = state.thread
    return t is not None and t.is_alive()


def start(state=None, warm_up=None):
    """Start the background compile unless it runs or has finished. ``warm_up``: the function
    that compiles (default: ``core.warm_up``; tests pass their own). Returns True if started."""
    state = state or STATE
    with _LOCK:
        if running(state) or state.phase == READY:
            state.abandoned = False  # enabled again while it runs: it is wanted again
            return False
        state.phase = COMPILING
        state.detail = ""
        state.error = ""
        state.abandoned = False
        state.started = time.monotonic()
        state.thread = threading.Thread(target=_run, args=(state, warm_up), name="spectral-gi-compile", daemon=True)
        state.thread.start()
        return True


def switched_off(state=None):
    """The preference is off: show it, unless a compile is running or done."""
    state = state or STATE
    with _LOCK:
        if not running(state) and state.phase in (IDLE, FAILED):
            state.phase = OFF


def abandon(state=None):
    """The add-on is being disabled: a waiting compile stops waiting; a running one finishes by itself."""
    (state or STATE).abandoned = True


def _say(state, text):
    state.detail = str(text)


def _core_warm_up(status, should_cancel):
    from ..core import kernels_compiled, warm_up

    compiled = warm_up(status=status, should_cancel=should_cancel)
    if not kernels_compiled():  # it waited for another render's compile and was cancelled
        raise RuntimeError("stopped before the kernels were compiled (the add-on was disabled)")
    return compiled


def _run(state, warm_up):
    try:
        compiled = (warm_up or _core_warm_up)(status=lambda text: _say(state, text),
                                              should_cancel=lambda: state.abandoned)
        state.compiled = bool(compiled)
        state.seconds = time.monotonic() - state.started
        state.phase = READY
    except Exception as exc:  # noqa: BLE001 - reported as the status, never raised into Blender
        text = " ".join(str(exc).split()) or type(exc).__name__
        state.error = f"{type(exc).__name__}: {text}"[:300]
        state.seconds = time.monotonic() - state.started
        state.phase = FAILED
