"""Content digests of arrays (the keys of the BVH and world-map caches)."""
import numpy as np
import pytest

from mcengine import digest as digest_module
from mcengine.digest import digest


@pytest.mark.parametrize("split", [False, True])
def test_a_change_of_any_byte_type_or_shape_changes_the_digest(monkeypatch, split):
    """Every part of a large array counts: one byte changed anywhere (in each of the parts it
    is hashed in, with ``split``) gives another digest; equal bytes give equal digests."""
    if split:
        monkeypatch.setattr(digest_module, "SPLIT_BYTES", 64)
    a = np.arange(1000, dtype=np.float32)
    key = digest([a, np.arange(3)])
    assert digest([a.copy(), np.arange(3)]) == key
    for i in range(0, a.size, 37):
        b = a.copy()
        b.view(np.uint8)[4 * i + 1] ^= 1
        assert digest([b, np.arange(3)]) != key, i
    assert digest([a.view(np.int32), np.arange(3)]) != key
    assert digest([a.reshape(10, 100), np.arange(3)]) != key
    assert digest([a, np.arange(3), np.zeros(0)]) != key
    assert digest([a[:-1], np.arange(3)]) != key
