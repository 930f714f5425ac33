"""Background jobs of the add-on: the state the UI shows, a worker thread with progress, cancel,
error capture and hand-over to the main thread, and the modal-operator steps that drive one.

A job (:class:`BackgroundJob`) computes in :meth:`~BackgroundJob._run` on a worker thread (or
on the calling thread in the background) and never touches bpy there; it reports through its
slot's :class:`JobState`. The main thread polls it from a timer and, once it has finished,
concludes it: the subclass hands over its result (an image, stored values) and the state says
how it ended. :class:`ModalJobOperator` is the operator side: a timer, Esc to cancel, the status
bar, and the job's end reported.
"""
import threading
import time
import traceback

TIMER_STEP = 0.2  # seconds between UI updates while a job runs


class JobState:
    """What the UI shows about the current (or last) job. Written by callbacks, read by the UI."""

    def __init__(self):
        self.running = False
        self.phase = ""
        self.done = 0
        self.total = 0
        self.rate = 0.0  # samples (camera paths) per second
        self.started = 0.0
        self.cancelling = False
        self.message = ""  # outcome of the last job
        self.illuminance = None  # core IlluminanceStats.as_dict() of the last sensor render (Em, Emin, …, lux)

    def begin(self, total):
        self.running = True
        self.phase = "Starting"
        self.done = 0
        self.total = int(total)
        self.rate = 0.0
        self.started = time.monotonic()
        self.cancelling = False
        self.message = ""


def status_line(state):
    """One line for the status bar: phase, samples done/total, speed, cancel hint."""
    parts = [f"Spectral GI: {state.phase or 'Rendering'}"]
    if state.total:
        parts.append(f"{state.done}/{state.total} samples")
    if state.rate > 0.0:
        parts.append(f"{state.rate / 1e6:.2f} M samples/s")
    if state.running:
        parts.append("Cancelling…" if state.cancelling else "Esc to cancel")
    return " | ".join(parts)


SLOTS = []  # every JobSlot: while a job runs in any of them, no other job starts


class JobSlot:
    """One kind of job at a time: its UI state and the job in progress (or the last one)."""

    def __init__(self):
        self.state = JobState()
        self.job = None
        SLOTS.append(self)

    def current(self):
        return self.job

    def busy(self):
        """True while a job runs (worker thread alive or a synchronous job in progress)."""
        job = self.job
        if job is None or job.concluded:
            return False
        if job.thread is not None:
            return job.thread.is_alive()
        return self.state.running

    def cancel(self, wait=0.0):
        """Ask a running job to stop (used when the add-on is unregistered); optionally wait for its thread."""
        job = self.job
        if job is None:
            return
        job.request_cancel()
        if wait and job.thread is not None:
            job.thread.join(timeout=wait)


class BackgroundJob:
    """A computation on a worker thread (:meth:`start`, then :meth:`poll` from the main thread until it
    returns True) or on the calling thread (:meth:`run_sync`).

    Subclasses set ``slot`` and ``thread_name`` and write :meth:`_run` (the worker: the computation
    wrapped in :meth:`_capture`'s error capture, ``finished`` set at its end), :meth:`_total` (the
    samples the state counts), :meth:`_hand_over` (main thread: the result into Blender) and
    :meth:`summary` (the line that says how it ended).
    """

    slot = None  # the JobSlot this kind of job runs in
    thread_name = "spectral-gi-job"

    def __init__(self):
        self.cancel_requested = self.finished = self.concluded = False
        self.error = self.traceback = None  # the error's one line and its traceback (the worker's exception)
        self.thread = None
        self.warning = None  # the export's warning, reported as the job starts

    @property
    def state(self):
        return self.slot.state

    # ------------------------------------------------------------------ callbacks (any thread)

    def should_cancel(self):
        return self.cancel_requested

    def request_cancel(self):
        self.cancel_requested = True
        self.state.cancelling = True

    def _capture(self, exc):
        """Keep an exception as the job's error (reported by the operator on the main thread)."""
        self.error = f"{type(exc).__name__}: {exc}"
        self.traceback = traceback.format_exc()

    def _run(self, *args):
        raise NotImplementedError

    def _worker_args(self):
        return ()

    # ------------------------------------------------------------------ main thread

    def _total(self):
        raise NotImplementedError

    def _begin(self):
        self.slot.job = self
        self.state.begin(self._total())

    def start(self):
        """Run on a worker thread; call :meth:`poll` from the main thread until it returns True."""
        self._begin()
        self.thread = threading.Thread(target=self._run, args=self._worker_args(), name=self.thread_name,
                                       daemon=True)
        self.thread.start()

    def _while_running(self):
        """Main thread, at each poll before the job has finished (a progressive display)."""

    def poll(self):
        """Main thread, from a timer: True once the job has finished and concluded."""
        if not self.finished:
            self._while_running()
            return False
        if self.thread is not None:
            self.thread.join(timeout=1.0)
        self.conclude()
        return True

    def _hand_over(self):
        """Main thread, once: the result into Blender. Returns what :meth:`conclude` returns."""
        return None

    def _concluded(self):
        """What :meth:`conclude` returns when called again."""
        return None

    def end_phase(self):
        """The state's phase once the job has ended."""
        if self.error is not None:
            return "Failed"
        return "Cancelled" if self.cancelled else "Finished"

    def conclude(self):
        """Hand the result over and update the UI state. Idempotent."""
        if self.concluded:
            return self._concluded()
        self.concluded = True
        result = None
        try:
            result = self._hand_over()
        except Exception as exc:
            if self.error is None:
                self._capture(exc)
        finally:
            st = self.state
            st.running = False
            st.cancelling = False
            st.message = self.message()
            st.phase = self.end_phase()
        return result

    @property
    def cancelled(self):
        return self.cancel_requested and self.error is None

    def summary(self):
        raise NotImplementedError

    def message(self):
        """What the panel says about the job once it has ended."""
        return self.summary()

    def status_line(self):
        return status_line(self.state)


# ----------------------------------------------------------------------------- the operator side


def redraw(window_manager, types=("PROPERTIES", "IMAGE_EDITOR")):
    """Tag the areas of ``types`` in every window for a redraw."""
    for window in getattr(window_manager, "windows", ()):
        if window.screen is None:
            continue
        for area in window.screen.areas:
            if area.type in types:
                area.tag_redraw()


def set_status(context, text):
    """The workspace's status-bar text (None clears it); a context without one is left alone."""
    ws = getattr(context, "workspace", None)
    if ws is not None:
        try:
            ws.status_text_set(text)
        except (AttributeError, RuntimeError, TypeError):
            pass


def any_busy():
    """True while a job runs in any slot (a render, an illuminance calculation)."""
    return any(slot.busy() for slot in SLOTS)


class ModalJobOperator:
    """The steps of an operator that runs a job: modal with a worker thread when there is a window (a
    timer polls the job, Esc cancels it, the status bar shows its progress), else on the calling
    thread (scripts, background mode).

    A subclass writes ``_prepare(context)`` (the job, not started, or None after reporting why) and
    ``_conclude(context, job)`` (report the end; returns the operator's result); the job's ``warning``
    (the export's) is reported before it runs. A job is a
    :class:`BackgroundJob`, or anything with ``poll``, ``request_cancel`` and ``status_line`` whose
    operator writes ``_start`` (begin it), ``_abandon`` (stop it) and ``execute``.
    """

    _timer = None
    _job = None
    progress_bar = False  # the window manager's progress bar while the job runs
    redraw_areas = ("PROPERTIES", "IMAGE_EDITOR")

    @classmethod
    def poll(cls, context):
        return context.scene is not None and not any_busy()

    def _prepare(self, context):
        raise NotImplementedError

    def _conclude(self, context, job):
        raise NotImplementedError

    def _start(self, context):
        """The job, started on its worker thread; None (after reporting why) if there is none."""
        job = self._prepare(context)
        if job is not None:
            job.start()
        return job

    def _abandon(self, job):
        """Blender ends the modal operator (new file, quit): stop the job."""
        job.request_cancel()

    def _redraw(self, context):
        redraw(context.window_manager, self.redraw_areas)

    def _warn(self, job):
        """Report the job's export warning (if any); returns the job."""
        if job is not None and getattr(job, "warning", None):
            self.report({"WARNING"}, f"Spectral GI: {job.warning}")
        return job

    def execute(self, context):
        job = self._warn(self._prepare(context))
        if job is None:
            return {"CANCELLED"}
        job.run_sync()
        return self._conclude(context, job)

    def invoke(self, context, event):
        import bpy

        if bpy.app.background or context.window is None:
            return self.execute(context)  # no event loop (no timer events): on the calling thread
        job = self._warn(self._start(context))
        if job is None:
            return {"CANCELLED"}
        self._job = job
        wm = context.window_manager
        self._timer = wm.event_timer_add(TIMER_STEP, window=context.window)
        wm.modal_handler_add(self)
        if self.progress_bar:
            wm.progress_begin(0, 1)
        set_status(context, job.status_line())
        self._redraw(context)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = self._job
        if event.type == "ESC" and event.value == "PRESS":
            job.request_cancel()
            set_status(context, job.status_line())
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        try:
            done = job.poll()
        except Exception as exc:  # an update on the main thread failed: stop cleanly, keep Blender alive
            job.request_cancel()
            job.error = job.error or f"{type(exc).__name__}: {exc}"
            done = job.finished
            if done:
                job.conclude()
        if not done:
            if self.progress_bar:
                st = job.state
                context.window_manager.progress_update(st.done / max(st.total, 1))
            set_status(context, job.status_line())
            self._redraw(context)
            return {"PASS_THROUGH"}
        self._cleanup(context)
        return self._conclude(context, job)

    def cancel(self, context):
        if self._job is not None:
            self._abandon(self._job)
        self._cleanup(context)

    def _cleanup(self, context):
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
            if self.progress_bar:
                wm.progress_end()
        set_status(context, None)
