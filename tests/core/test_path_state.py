"""The wavefront's path state: compaction keeps every field of a surviving path."""
import numpy as np
import pytest

from mcengine.kernels.state import alloc_path_state, compact_paths

_OWN = ("root", "live")     # the classic integrators' order; compaction's scratch


def _random_state(n, alive, seed=7):
    st = alloc_path_state(n)
    rng = np.random.default_rng(seed)
    for array in st:
        array[...] = rng.integers(1, 100, size=array.shape).astype(array.dtype)
    st.alive[:] = alive
    return st


def test_compaction_moves_every_field_of_the_path_state():
    """Each live path moves to the front with all of its state, in order: a field left out
    hands the survivor another path's value (as the Filter Glossy pdf and the ray
    differentials once were).  ``root`` is the classic integrators' own."""
    alive = np.array([0, 1, 1, 0, 0, 1, 0, 1, 1, 0], np.uint8)
    st = _random_state(alive.size, alive)
    before = [array.copy() for array in st]
    m, first = compact_paths(st, alive.size)
    assert (m, first) == (5, 0)
    moved = [name for name, array, old in zip(st._fields, st, before)
             if np.array_equal(array[:m], old[alive == 1])]
    assert moved == [name for name in st._fields if name not in _OWN]
    assert np.array_equal(st.live[:m], np.flatnonzero(alive))


@pytest.mark.parametrize("alive", [[1, 1, 1, 1], [0, 0, 0], [1, 1, 0, 0]],
                         ids=["all-live", "none-live", "live-in-front"])
def test_compaction_leaves_paths_already_in_place(alive):
    """Where the live paths already lead, nothing moves (first = n: the pass buffers are
    left alone too) and the count is theirs."""
    alive = np.array(alive, np.uint8)
    st = _random_state(alive.size, alive)
    before = [array.copy() for array in st if array is not st.live]
    m, first = compact_paths(st, alive.size)
    assert m == alive.sum() and first >= m
    assert all(np.array_equal(a, b) for a, b in zip([x for x in st if x is not st.live], before))
