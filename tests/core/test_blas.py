"""mcengine.blas: numpy's OpenBLAS set to one thread (the reason is in the module)."""
from __future__ import annotations

import os

import numpy as np
import pytest

from mcengine import blas


@pytest.mark.skipif(not os.path.exists("/proc/self/maps"), reason="finds OpenBLAS on Linux only")
def test_every_openblas_in_the_process_uses_one_thread():
    np.linalg.inv(np.eye(4))            # numpy's OpenBLAS is loaded and has its pool
    counts = blas.thread_counts()
    assert counts, "numpy's OpenBLAS was not found among the loaded libraries"
    blas.use_one_thread()
    assert set(blas.thread_counts().values()) == {1}
