"""numba compilation settings shared by every kernel of the core.

* ``cache=True``: compiled machine code is stored on disk, so a second
  process loads it in a fraction of a second instead of recompiling.  numba
  keys its cache on the file of each function only (and not on the jit
  options), so a kernel would keep the stale code of a helper it inlined
  from another file; the cache therefore lives in a folder named after a
  hash of every source that compiled code comes from (this file,
  ``numba_patches``, the ``kernels`` package and its data tables, which numba freezes into the
  code: ``__pycache__/numba-<hash>`` next to them, or
  ``~/.cache/mcengine`` if that is not writable; ``NUMBA_CACHE_DIR`` still
  wins).
* ``error_model="numpy"``: float division by zero gives inf/NaN instead of
  raising, which removes a branch from every division; the integrator checks
  the values it uses (``clamp_light`` drops non-finite contributions).
* ``nogil=True`` on stage kernels: two Python worker threads run them in
  parallel (no OpenMP pool whose spinning workers would steal the core that
  Embree runs on).
* ``inline="always"`` on device functions (everything a kernel calls): a
  call numba does not inline costs 15-40 ns (its calling convention passes
  every array as a struct and checks an error status), which summed over the
  dozen helpers of a shading step made it several times slower.  Kernels
  compile more slowly; the cache keeps that a one-off, and ``numba_patches``
  makes three of numba's compile steps faster on such large functions.
* ``builder``: host-side code that builds and returns arrays once per render
  (the motion-blur BVH); it keeps numba's reference counting.
* ``function``: the few large steps (running a shader, evaluating or
  sampling a closure list) are called, not inlined: they cost far more than a
  call, and inlining them into every caller made compilation take many
  minutes.
* ``by_ref`` / ``deref``: numba passes a tuple argument by value, every field
  of it (a ``ShadingData`` is 31 machine words, a ``TextureData`` of eight
  arrays 68), which a caller stores anew for every call; a function called
  many times with the same large tuple takes its address instead (one word).
  ``benchmarks/bench_call_cost.py``: a node-like function called in a loop
  took 43.8 ns per call with both tuples by value, 24.0 ns by reference,
  18.6 ns inlined (no call).  ``field_ref`` is the address of one field of
  such a tuple (the texture data inside the shader evaluator's ``ShaderScene``).
* ``_nrt=False``: no reference counting of arrays.  With it, numba wraps
  every array it takes out of a tuple or hands to a helper in atomic
  increments and decrements, which measured 28 % of the render time.  The
  kernels never allocate or return arrays; the caller's references keep
  every array they touch alive.
"""
import hashlib
import os
import shutil
from pathlib import Path

from numba import njit, types
from numba.core import cgutils, config, errors
from numba.extending import intrinsic

from . import numba_patches


def _cache_dir() -> str | None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    here = Path(__file__).resolve().parent
    digest = hashlib.sha256()
    kernels = here / "kernels"
    sources = sorted([*kernels.rglob("*.py"), *kernels.rglob("*.npy")])
    for source in [Path(__file__).resolve(), here / "numba_patches.py", *sources]:
        digest.update(str(source.relative_to(here)).encode())
        digest.update(source.read_bytes())
    base = here / "__pycache__"
    if not os.access(here, os.W_OK):
        base = Path.home() / ".cache" / "mcengine"
    current = base / f"numba-{digest.hexdigest()[:16]}"
    for old in base.glob("numba-*"):      # caches of earlier versions of the sources
        if old != current:
            shutil.rmtree(old, ignore_errors=True)
    return str(current)


_CACHE_DIR = _cache_dir()
_READY = "kernels-compiled"     # marker file: mcengine.warmup compiled every kernel here


def cache_folder() -> Path:
    """The folder numba's cache of these sources is in."""
    return Path(_CACHE_DIR or config.CACHE_DIR)


def cache_is_ready() -> bool:
    """True once ``mcengine.warmup`` has compiled the kernels of these sources."""
    return (cache_folder() / _READY).exists()


def mark_cache_ready() -> None:
    folder = cache_folder()
    folder.mkdir(parents=True, exist_ok=True)
    (folder / _READY).touch()


def _cached(decorator):
    """Apply a numba decorator with the cache folder above (set only meanwhile:
    numba's setting is process-wide and other packages keep theirs)."""
    def apply(fn):
        if _CACHE_DIR is None:
            return decorator(fn)
        previous = config.CACHE_DIR
        config.CACHE_DIR = _CACHE_DIR
        try:
            return decorator(fn)
        finally:
            config.CACHE_DIR = previous
    return apply


numba_patches.apply()

device = _cached(njit(cache=True, error_model="numpy", inline="always", _nrt=False))
# Host-side builders that allocate their results (acceleration structures), run once per render.
builder = _cached(njit(cache=True, error_model="numpy"))
function = _cached(njit(cache=True, error_model="numpy", _nrt=False))
kernel = _cached(njit(cache=True, nogil=True, error_model="numpy", _nrt=False))


@intrinsic
def by_ref(typingctx, value):
    """The address of a copy of ``value`` (a tuple) in the caller's stack frame, to pass to a
    ``function`` instead of the value (``deref`` reads it there).  Valid until the caller
    returns: never return it or store it in an array.  A call in a loop should get it made
    once, before the loop: the copy is made where ``by_ref`` is."""
    def codegen(context, builder, signature, args):
        model = context.data_model_manager[signature.args[0]]
        address = cgutils.alloca_once(builder, model.get_data_type())
        builder.store(model.as_data(builder, args[0]), address)
        return address
    return types.CPointer(value)(value), codegen


@intrinsic
def deref(typingctx, ref):
    """The value whose address ``by_ref`` gave (only the fields used are read)."""
    def codegen(context, builder, signature, args):
        model = context.data_model_manager[signature.return_type]
        value = model.from_data(builder, builder.load(args[0]))
        if context.enable_nrt:          # a new reference, as numba counts them
            context.nrt.incref(builder, signature.return_type, value)
        return value
    return ref.dtype(ref), codegen


@intrinsic
def field_ref(typingctx, ref, index):
    """The address of field ``index`` (a constant) of the tuple whose address ``by_ref``
    gave: a reference to part of it, without a copy."""
    if not isinstance(index, types.IntegerLiteral):
        raise errors.RequireLiteralValue(index)
    i = index.literal_value
    field = ref.dtype.types[i]

    def codegen(context, builder, signature, args):
        zero = context.get_constant(types.int32, 0)
        return builder.gep(args[0], [zero, context.get_constant(types.int32, i)])
    return types.CPointer(field)(ref, index), codegen
