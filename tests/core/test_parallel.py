"""The host's thread pool for one-off work (mcengine.parallel)."""
import threading

import pytest

from mcengine.parallel import in_background, map_threads


def test_results_come_in_the_order_of_the_items_from_threads():
    names = []

    def square(x):
        names.append(threading.current_thread().name)
        return x * x

    assert map_threads(square, range(20)) == [x * x for x in range(20)]
    assert map_threads(square, [3]) == [9]
    assert names[-1] == threading.current_thread().name      # one item: this thread
    assert map_threads(square, []) == []


def test_an_exception_in_any_call_is_raised_to_the_caller():
    def fail_on_seven(x):
        if x == 7:
            raise ValueError("seven")
        return x

    with pytest.raises(ValueError, match="seven"):
        map_threads(fail_on_seven, range(10))


def test_a_background_job_runs_beside_the_caller_and_hands_back_its_result_or_error():
    started, release = threading.Event(), threading.Event()

    def job():
        started.set()
        assert release.wait(5.0)          # runs while the caller goes on
        return threading.current_thread().name

    future = in_background(job)
    assert started.wait(5.0) and not future.done()
    release.set()
    assert future.result(5.0) != threading.current_thread().name

    def fail():
        raise ValueError("bvh")

    with pytest.raises(ValueError, match="bvh"):
        in_background(fail).result(5.0)
