"""The host's thread pool for one-off work (mcengine.parallel)."""
import threading

import pytest

from mcengine.parallel import map_threads


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
