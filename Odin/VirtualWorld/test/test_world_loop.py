"""The running loop without ROS: calls run between steps on the loop thread, timing rules."""
import threading
import time

import pytest

from virtual_world.core.loop import LoopStopped, RealTimeFactor, WorldLoop
from virtual_world.core.step_values import StepValues


class Recorder:
    """A stand-in for the Core's advance that records which thread stepped and when."""

    def __init__(self, step_cost: float = 0.0):
        self.sim_time = 0.0
        self.threads = set()
        self.inside_step = False
        self.step_cost = step_cost
        self.publications = []

    def advance(self, step, count):
        self.inside_step = True
        self.threads.add(threading.get_ident())
        time.sleep(self.step_cost)
        self.sim_time += step * count
        self.inside_step = False
        return self.sim_time

    def publish(self, report):
        self.publications.append(report)


@pytest.fixture
def running():
    loops = []

    def start(recorder, **kwargs):
        loop = WorldLoop(recorder.advance, recorder.publish, **kwargs)
        thread = threading.Thread(target=loop.run, daemon=True)
        thread.start()
        loops.append((loop, thread))
        return loop

    yield start
    for loop, thread in loops:
        loop.stop()
        thread.join(5)
        assert not thread.is_alive()


def test_calls_run_on_the_loop_thread_never_inside_a_step(running):
    recorder = Recorder(step_cost=0.002)
    loop = running(recorder, step_values=StepValues(0.001, 10, 200.0), simulate=True)
    seen = []
    for _ in range(50):
        seen.append(loop.call(lambda: (threading.get_ident(), recorder.inside_step)))
    assert {ident for ident, _ in seen} == recorder.threads
    assert not any(inside for _, inside in seen)


def test_a_paused_loop_answers_calls_at_once_and_does_not_step(running):
    recorder = Recorder()
    loop = running(recorder, step_values=StepValues(rate=2.0))  # 0.5 s period
    started = time.monotonic()
    assert loop.call(lambda: 42) == 42
    assert time.monotonic() - started < 0.2
    time.sleep(0.6)
    assert recorder.sim_time == 0.0
    assert recorder.publications and not any(p.stepped for p in recorder.publications)


def test_errors_reach_the_caller_and_the_loop_goes_on(running):
    loop = running(Recorder())
    with pytest.raises(ZeroDivisionError):
        loop.call(lambda: 1 / 0)
    assert loop.call(lambda: "alive") == "alive"


def test_cycles_follow_the_rate_on_the_wall_clock(running):
    recorder = Recorder()
    running(recorder, step_values=StepValues(0.001, 40, 50.0), simulate=True)
    time.sleep(1.0)
    # 50 Hz for one second: allow a loaded machine some slack, but not double speed
    assert 30 <= len(recorder.publications) <= 55
    assert recorder.sim_time == pytest.approx(len([p for p in recorder.publications
                                                   if p.stepped]) * 0.04, rel=0.1)


def test_free_run_steps_back_to_back_and_publishes_at_the_rate(running):
    recorder = Recorder()
    running(recorder, step_values=StepValues(0.001, 1, 10.0), simulate=True, free_run=True)
    time.sleep(0.5)
    due = [p for p in recorder.publications if p.publish_due]
    assert len(recorder.publications) > 10 * len(due)   # many more cycles than publications
    assert 3 <= len(due) <= 8                           # about 10 Hz over 0.5 s


def test_advance_cycle_steps_exactly_one_cycle(running):
    recorder = Recorder()
    loop = running(recorder, step_values=StepValues(0.002, 5, 25.0))
    loop.call(loop.advance_cycle)
    assert recorder.sim_time == pytest.approx(0.01)


def test_calls_after_stop_fail_cleanly():
    recorder = Recorder()
    loop = WorldLoop(recorder.advance, recorder.publish)
    thread = threading.Thread(target=loop.run)
    thread.start()
    loop.stop()
    thread.join(5)
    with pytest.raises(LoopStopped):
        loop.call(lambda: None)


def test_real_time_factor_over_a_window():
    rtf = RealTimeFactor(window=1.0)
    value = 0.0
    for i in range(30):
        value = rtf.add(wall_time=i * 0.1, sim_time=i * 0.05)
    assert value == pytest.approx(0.5)
