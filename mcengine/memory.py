"""Memory: what a render will need, and what the machine can give, decided before rendering.

A render that cannot fit should be refused at once with the figures, not fail
after minutes of work or be killed by the system.  The estimate counts what
grows with the scene and the image:

* the film: per pixel the sums of radiance and alpha and of squared radiance
  (float64) and a sample count, ``FILM_BYTES_PER_PIXEL``, plus the float32
  image handed out at each pass (``IMAGE_BYTES_PER_PIXEL``);
* the host's own buffers for the image (Blender's render result), which the
  caller states per pixel;
* the wavefront buffers of every worker thread (bounded by the batch size);
* the scene: triangle tables and Embree's BVH (``BYTES_PER_TRIANGLE``), lamps, and
  the texels of its images (``images.ImageTable``).

What the machine can give is the smallest of the kernel's available memory
(``MemAvailable``), the cgroup's limit minus its usage (containers), and the
address-space limit (``ulimit -v``) minus what the process already maps.
"""
from __future__ import annotations

import resource
from dataclasses import dataclass
from pathlib import Path

# Sums of RGBA (float64), of squared RGB (float64), the sample count (int32) and
# the index of pixels still sampling (int32).
FILM_BYTES_PER_PIXEL = 4 * 8 + 3 * 8 + 4 + 4
IMAGE_BYTES_PER_PIXEL = 4 * 4                  # float32 RGBA handed to the host at each pass
# Packed tables per triangle, an upper bound (vertices f32 and f64, indices, shading normals
# at most one per corner with their index, uvs, material and object indices: at most
# ~140 B) and Embree's BVH in robust mode (~130 B, measured with embreex).
BYTES_PER_TRIANGLE = 270
# Headroom for the interpreter's own growth while rendering.
SLACK_BYTES = 64 << 20

GIB = float(1 << 30)


@dataclass(frozen=True)
class MemoryEstimate:
    film: int
    host_image: int
    buffers: int
    scene: int
    textures: int = 0

    @property
    def total(self) -> int:
        return self.film + self.host_image + self.buffers + self.scene + self.textures + SLACK_BYTES

    def describe(self) -> str:
        return (f"about {self.total / GIB:.2f} GiB (film {self.film / GIB:.2f}, image "
                f"{self.host_image / GIB:.2f}, path buffers {self.buffers / GIB:.2f}, scene "
                f"{self.scene / GIB:.2f}, images {self.textures / GIB:.2f})")


def estimate(pixels: int, triangles: int, buffer_bytes: int, host_bytes_per_pixel: int = 0,
             pass_bytes_per_pixel: int = 0, texture_bytes: int = 0) -> MemoryEstimate:
    """Memory a render of ``pixels`` pixels and ``triangles`` triangles needs, in bytes
    (``pass_bytes_per_pixel``: the film's render-pass sums; ``texture_bytes``: its images'
    texels)."""
    return MemoryEstimate(
        film=pixels * (FILM_BYTES_PER_PIXEL + pass_bytes_per_pixel),
        host_image=pixels * (IMAGE_BYTES_PER_PIXEL + host_bytes_per_pixel),
        buffers=buffer_bytes,
        scene=triangles * BYTES_PER_TRIANGLE,
        textures=texture_bytes)


def available() -> int | None:
    """Bytes this process can still allocate, or None where that cannot be known."""
    limits = [_meminfo_available(), _cgroup_available(), _address_space_available()]
    known = [x for x in limits if x is not None]
    return min(known) if known else None


def _read_int(path: Path) -> int | None:
    try:
        text = path.read_text().strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None


def _meminfo_available() -> int | None:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def _cgroup_available() -> int | None:
    for limit_file, usage_file in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                                   ("/sys/fs/cgroup/memory/memory.limit_in_bytes",
                                    "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        limit, usage = _read_int(Path(limit_file)), _read_int(Path(usage_file))
        if limit is not None and usage is not None and limit < (1 << 60):
            return max(limit - usage, 0)
    return None


def _address_space_available() -> int | None:
    soft, _hard = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY:
        return None
    mapped = 0
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmSize:"):
                mapped = int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return max(soft - mapped, 0)
