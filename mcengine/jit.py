"""numba compilation settings shared by every kernel of the core.

* ``cache=True``: compiled machine code is stored next to the sources, so a
  second process loads it in a fraction of a second instead of recompiling.
* ``error_model="numpy"``: float division by zero gives inf/NaN instead of
  raising, which removes a branch from every division; the integrator checks
  the values it uses (``_clamp`` drops non-finite contributions).
* ``nogil=True`` on stage kernels: two Python worker threads run them in
  parallel (no OpenMP pool whose spinning workers would steal the core that
  Embree runs on).
* ``inline="always"`` on device functions (everything a kernel calls): a
  call numba does not inline costs 15-40 ns (its calling convention passes
  every array as a struct and checks an error status), which summed over the
  dozen helpers of a shading step made it several times slower.  Kernels
  compile more slowly; the cache keeps that a one-off.
"""
from numba import njit

device = njit(cache=True, error_model="numpy", inline="always")
kernel = njit(cache=True, nogil=True, error_model="numpy")
