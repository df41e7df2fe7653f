"""Cryptomatte ids and manifests, in the standard form compositors read.

The Cryptomatte specification (Psyop, 2017; what Blender's compositor, Nuke
and Fusion read): a name's id is its MurmurHash3_32 (x86, seed 0) over the
UTF-8 bytes, stored in the image as a float32 whose bits are the hash with
the exponent kept away from 0 and 255 (no denormals, infinities or NaNs);
each RGBA pass holds two ranks (id, coverage, id, coverage), highest coverage
first; the EXR header carries, per layer, ``cryptomatte/<key>/name``,
``/hash`` ("MurmurHash3_32"), ``/conversion`` ("uint32_to_float32") and
``/manifest`` (JSON: name -> 8 hex digits of the hash), where ``<key>`` is
the first 7 hex digits of the hash of the layer name ("ViewLayer.CryptoObject").
Blender writes the header fields from the render result's metadata.
"""
from __future__ import annotations

import json
import struct

import numpy as np

__all__ = ["murmur3_32", "hash_to_float", "name_id", "manifest", "layer_metadata", "MAX_DEPTH",
           "passes_for_depth"]

MAX_DEPTH = 16      # ranks Blender offers (View Layer > Cryptomatte > Levels)
_C1, _C2 = 0xCC9E2D51, 0x1B873593
_M32 = 0xFFFFFFFF


def _rotl(x: int, r: int) -> int:
    return ((x << r) | (x >> (32 - r))) & _M32


def murmur3_32(data: bytes, seed: int = 0) -> int:
    """MurmurHash3, x86 32-bit variant (Austin Appleby's reference algorithm)."""
    h = seed & _M32
    n = len(data)
    tail_start = n - n % 4
    for (k,) in struct.iter_unpack("<I", data[:tail_start]):
        k = (k * _C1) & _M32
        k = _rotl(k, 15)
        k = (k * _C2) & _M32
        h ^= k
        h = _rotl(h, 13)
        h = (h * 5 + 0xE6546B64) & _M32
    k = 0
    tail = data[tail_start:]
    for i in reversed(range(len(tail))):
        k ^= tail[i] << (8 * i)
    if tail:
        k = (k * _C1) & _M32
        k = _rotl(k, 15)
        k = (k * _C2) & _M32
        h ^= k
    h ^= n
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & _M32
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & _M32
    h ^= h >> 16
    return h


def hash_to_float(h: int) -> float:
    """The float32 a hash is stored as: its bits, exponent clamped to [1, 254]."""
    exponent = min(max((h >> 23) & 0xFF, 1), 254)
    bits = (h & 0x80000000) | (exponent << 23) | (h & 0x7FFFFF)
    return float(np.array([bits], np.uint32).view(np.float32)[0])


def name_id(name: str) -> float:
    """The id of a name, as stored in the passes."""
    return hash_to_float(murmur3_32(name.encode("utf-8")))


def manifest(names) -> str:
    """JSON object name -> "%08x" hash, each name once, in the order given."""
    seen = {}
    for name in names:
        if name not in seen:
            seen[name] = f"{murmur3_32(name.encode('utf-8')):08x}"
    return json.dumps(seen, separators=(",", ":"), ensure_ascii=False)


def layer_metadata(layer: str, names) -> dict:
    """The metadata fields of one Cryptomatte layer (``layer``: "ViewLayer.CryptoObject")."""
    key = f"{murmur3_32(layer.encode('utf-8')):08x}"[:7]
    prefix = f"cryptomatte/{key}/"
    return {prefix + "name": layer, prefix + "hash": "MurmurHash3_32",
            prefix + "conversion": "uint32_to_float32", prefix + "manifest": manifest(names)}


def passes_for_depth(depth: int) -> int:
    """RGBA passes for ``depth`` ranks (two ranks per pass), as Blender lists them."""
    return (min(MAX_DEPTH, max(int(depth), 1)) + 1) // 2
