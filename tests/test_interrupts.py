"""Signals that wait: what fishgen's handlers raise comes at once, or when a held step is over."""
from __future__ import annotations

import threading

import pytest

from fishgen.interrupts import deliver, held


class Stop(BaseException):
    pass


def test_an_interrupt_outside_a_held_step_raises_at_once():
    with pytest.raises(Stop):
        deliver(Stop())


def test_an_interrupt_inside_waits_for_the_outermost_held_step():
    done = []
    with pytest.raises(Stop):
        with held():
            with held():
                deliver(Stop())
                done.append("inner")
            done.append("outer")  # still held: the outer block ends first
    assert done == ["inner", "outer"]
    deliver_after = []
    with held():
        deliver_after.append(1)  # nothing pending any more
    assert deliver_after == [1]


def test_a_held_step_that_fails_still_raises_the_interrupt():
    with pytest.raises(Stop):
        with held():
            deliver(Stop())
            raise OSError("disk full")


def test_another_thread_does_not_hold_the_main_thread_s_signals():
    entered, release = threading.Event(), threading.Event()

    def hold():
        with held():
            entered.set()
            release.wait(5)

    worker = threading.Thread(target=hold)
    worker.start()
    entered.wait(5)
    try:
        with pytest.raises(Stop):
            deliver(Stop())
    finally:
        release.set()
        worker.join()
