"""The wavefront's path state: compaction keeps every field of a surviving path."""
import numpy as np

from mcengine.kernels.state import alloc_path_state, move_path


def test_compaction_moves_every_field_of_the_path_state():
    """A path moved to another slot takes all of its state with it: a field left out hands
    the survivor another path's value (as the Filter Glossy pdf and the ray differentials
    once were).  ``root`` is the classic integrators' own."""
    st = alloc_path_state(4)
    rng = np.random.default_rng(7)
    for array in st:
        array[...] = rng.integers(1, 100, size=array.shape).astype(array.dtype)
    before = [array.copy() for array in st]
    move_path(st, 3, 1)
    moved = [name for name, array, old in zip(st._fields, st, before)
             if np.array_equal(array[1], old[3])]
    assert moved == [name for name in st._fields if name != "root"]
