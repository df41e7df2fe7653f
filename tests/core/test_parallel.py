"""The host's thread pool for one-off work (mcengine.parallel)."""
import threading

import numpy as np
import pytest

from mcengine import parallel
from mcengine.parallel import in_background, map_threads, take


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


@pytest.mark.parametrize("shape", [(0,), (5,), (1000,), (333, 3)])
def test_take_in_blocks_is_numpys_take(monkeypatch, shape):
    """Blocks of any size (here 7 indices, so several blocks on threads, and the last one
    short) give np.take's rows, into a new array or the one given."""
    monkeypatch.setattr(parallel, "_TAKE_BLOCK", 7)
    rng = np.random.default_rng(3)
    values = rng.random((50, 3)).astype(np.float32)
    indices = rng.integers(0, 50, shape).astype(np.int32)
    expected = np.take(values, indices, axis=0)
    got = take(values, indices)
    assert got.shape == expected.shape and got.dtype == np.float32
    np.testing.assert_array_equal(got, expected)
    out = np.full(expected.shape, -1.0, np.float32)
    assert take(values, indices, out=out) is out
    np.testing.assert_array_equal(out, expected)
    with pytest.raises(IndexError):
        take(values, np.array([0, 50]))
    with pytest.raises(ValueError, match="C-contiguous"):
        take(values[:, 0], np.arange(4), out=np.empty(8)[::2])
