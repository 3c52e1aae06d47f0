"""Runs one measurement in a forked child process and returns its result (a dict).

rospy.init_node works once per process, and every measurement that talks to nodes starts a
roscore of its own: each runs in a child of its own.
"""
from __future__ import annotations

import multiprocessing
import queue as queues

TIMEOUT_S = 1800.0


def in_child(function, *args) -> dict:
    """``function(*args)`` in a forked process; its exception, or the child's death before it
    answered, raises RuntimeError here."""
    context = multiprocessing.get_context("fork")
    results = context.Queue()

    def target():
        try:
            results.put(function(*args))
        except BaseException as error:
            results.put({"error": repr(error)})
            raise

    process = context.Process(target=target)
    process.start()
    waited = 0.0
    while True:
        try:
            result = results.get(timeout=1.0)
            break
        except queues.Empty:
            waited += 1.0
            if not process.is_alive() and results.empty():
                raise RuntimeError(f"{function.__name__}: the child process ended with "
                                   f"{process.exitcode} before answering") from None
            if waited > TIMEOUT_S:
                process.kill()
                raise RuntimeError(f"{function.__name__}: no answer in {TIMEOUT_S} s") from None
    process.join(60)
    if "error" in result:
        raise RuntimeError(f"{function.__name__}: {result['error']}")
    return result
