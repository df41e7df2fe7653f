"""IES Texture nodes -> :class:`mcengine.ies.IESProfile`, their files read as Cycles reads them.

Blender's node holds the file in a Text data-block (mode Internal: Cycles joins its lines,
each ended by a newline) or names it by path (External: '//' is the folder of the .blend, or
of the library the node tree comes from; other paths as given).  A text Cycles cannot read
makes the node give 100 x Strength in every direction (``mcengine.ies.FAILED_PROFILE``):
:func:`read_profile` raises with the reason, for its callers to warn of.
"""
from __future__ import annotations

import functools
from pathlib import Path

import bpy

from mcengine.ies import IESError, IESProfile, parse_ies

__all__ = ["read_profile"]


def read_profile(node, library=None) -> IESProfile:
    """The node's profile; raises :class:`IESError` (or ``OSError``) with the reason where
    Cycles' loader fails.  ``library``: the data-block the node tree belongs to's library."""
    if node.mode == "EXTERNAL":
        if not node.filepath:
            raise IESError("no file given")
        text = Path(bpy.path.abspath(node.filepath, library=library)).read_bytes()
    elif node.ies is None:
        raise IESError("no text data-block given")
    else:
        text = "".join(line.body + "\n" for line in node.ies.lines).encode("utf-8")
    return _parsed(text)


@functools.lru_cache(maxsize=16)
def _parsed(text: bytes) -> IESProfile:
    """One profile per text: instances of a lamp share it (and its block in the kernels')."""
    return parse_ies(text)
