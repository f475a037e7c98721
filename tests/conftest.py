"""What every test process shares: numba's boxing module imported whole before any test runs, and
a Ctrl-C that ends the session even when a test's library keeps it to itself.

numba imports `numba.core.boxing` lazily, the first time a process compiles a kernel's Python
wrapper. CI fills the kernel cache before its two test workers start, so a worker's first compile
comes late, in whichever test needs a kernel the cache lacks; once, a worker's import of it was
left half done and every later compile in that worker failed with "duplicate registration for
Boolean". Imported here it is whole from the start.

Ctrl-C raises KeyboardInterrupt in the test under way, which ends the session, unless it is
dropped or caught there: Python drops it where it cannot be raised (a finalizer, a ctypes
callback: numba's compiler runs both), and a library may catch it (a browser driver's event
callback, a retry loop's bare `except:`). So a KeyboardInterrupt Python drops is raised again a
moment later, out of there (`sys.unraisablehook`), and Python's own SIGINT handler is wrapped: a
Ctrl-C it raises is also remembered, and the session stops once that test is over, caught or not
(docs/command-line.md, "Progress and Ctrl-C"). A session started with SIGINT ignored (a script's
background job) is left as it is.
"""

import _thread
import functools
import signal
import sys
import threading

import numba.core.boxing  # noqa: F401
import pytest

RETRY_S = 0.01  # seconds after a dropped KeyboardInterrupt that it is raised again
_ctrl_c = {"heard": False}


def _heard(signum, frame):
    _ctrl_c["heard"] = True
    signal.default_int_handler(signum, frame)


def _unraisable(unraisable, then):
    if issubclass(unraisable.exc_type, KeyboardInterrupt):  # a Ctrl-C Python dropped: again
        threading.Timer(RETRY_S, _thread.interrupt_main).start()
    then(unraisable)


@pytest.hookimpl(trylast=True)  # after pytest's own unraisablehook, which this one calls
def pytest_configure(config):
    if threading.current_thread() is not threading.main_thread():
        return
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _heard)
    sys.unraisablehook = functools.partial(_unraisable, then=sys.unraisablehook)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    yield
    if _ctrl_c["heard"]:
        item.session.shouldstop = "Ctrl-C (a test kept the KeyboardInterrupt to itself)"
