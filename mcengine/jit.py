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
* ``_nrt=False``: no reference counting of arrays.  With it, numba wraps
  every array it takes out of a tuple or hands to a helper in atomic
  increments and decrements, which measured 28 % of the render time.  The
  kernels never allocate or return arrays; the caller's references keep
  every array they touch alive.
"""
from numba import njit

device = njit(cache=True, error_model="numpy", inline="always", _nrt=False)
kernel = njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
