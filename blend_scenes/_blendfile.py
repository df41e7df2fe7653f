"""Make an uncompressed Blender 5.0 .blend byte-for-byte reproducible.

Saving the same scene twice gives files that differ in a few bytes that do not
describe the scene:

* ``FileGlobal.colorspace_scene_linear_name``: the name is copied without
  zero padding, so the bytes after its NUL are leftover memory.
* ``Mesh.face_sets_color_seed``: seeded from the clock when a mesh is created;
  it only picks the viewport colours of sculpt face sets.
* ``bNode.identifier``: a random positive int32 per node, seeded from the clock;
  it only has to be unique within its node tree.
* ``ScrEdge.v1``/``v2``: the two vertices of a UI screen edge, stored in the
  order of their run-time memory addresses.  The edge is undirected.
* ``Image.name`` (``filepath`` in Python): setting a shorter path (the relative ``//textures/...``)
  over the absolute one it was loaded from leaves the end of the old path after
  the NUL, so the file depended on the folder it was built in.

:func:`normalize` rewrites exactly these fields in place: the paddings and the
seed become 0, node identifiers become 1, 2, 3, ... in file order (unique
in the whole file, hence in each tree), and each screen edge lists its
vertices in the order of their (reproducible) file addresses.  Field offsets are read from the
file's own SDNA block, so nothing here hard-codes a struct layout.

File layout (``BLENDER17-01v0500``): a 17-byte header, then blocks, each a
32-byte header ``(code: 4s, sdna_index: i32, old_address: u64, length: i64,
count: i64)`` followed by ``length`` bytes holding ``count`` structs of type
``sdna_index``.  The ``DNA1`` block describes every struct; ``ENDB`` ends the
file.
"""
from __future__ import annotations

import re
import struct

BLEND_MAGIC = b"BLENDER17-01v0500"
_BHEAD = struct.Struct("<4siQqq")
_POINTER_SIZE = 8  # the "17" format is 64-bit only
# FileGlobal.fileflags bit that makes Blender compress the file on later saves
# (G_FILE_COMPRESS in BKE_global.hh; checked against a file saved with compress=True).
_G_FILE_COMPRESS = 1 << 1


def normalize(raw: bytearray, colorspace_name: str, mark_compressed: bool = False) -> None:
    """Zero or renumber the non-reproducible fields of ``raw`` in place.

    Parameters
    ----------
    raw : bytearray
        The whole uncompressed file.
    colorspace_name : str
        The working colour-space name expected in the file header, used as a
        check that the right bytes are being rewritten.
    mark_compressed : bool
        Also set the 'compress' file flag, for a file that the caller
        compresses itself: Blender then keeps it compressed when re-saving.

    Raises
    ------
    ValueError
        If the file is not an uncompressed Blender 5.0 file or a field is missing.
    """
    if not raw.startswith(BLEND_MAGIC):
        raise ValueError(f"not an uncompressed Blender 5.0 .blend: header {bytes(raw[:17])!r}")
    blocks = list(_blocks(raw))
    dna = next((data for code, _, data, _ in blocks if code == b"DNA1"), None)
    if dna is None:
        raise ValueError("the .blend has no DNA1 block")
    structs = _parse_sdna(raw[dna[0]:dna[1]])

    next_node_id = 1
    for code, sdna_index, (start, end), count in blocks:
        name, size, fields = structs[sdna_index] if sdna_index < len(structs) else (None, 0, {})
        if code == b"GLOB":
            _zero_string_padding(raw, start + fields["colorspace_scene_linear_name"][0],
                                 fields["colorspace_scene_linear_name"][1], colorspace_name)
            if mark_compressed:
                flags_at = start + fields["fileflags"][0]
                (flags,) = struct.unpack_from("<i", raw, flags_at)
                struct.pack_into("<i", raw, flags_at, flags | _G_FILE_COMPRESS)
        elif name == "Mesh" and code == b"ME\0\0":
            offset = fields["face_sets_color_seed"][0]
            struct.pack_into("<i", raw, start + offset, 0)
        elif name == "bNode" and code == b"DATA":
            offset = fields["identifier"][0]
            for i in range(count):
                struct.pack_into("<i", raw, start + i * size + offset, next_node_id)
                next_node_id += 1
        elif name == "Image" and code == b"IM\0\0":
            offset, length = fields["name"]       # DNA name of Image.filepath
            _zero_after_nul(raw, start + offset, length)
        elif name == "ScrEdge" and code == b"DATA":
            for i in range(count):
                _sort_pointer_pair(raw, start + i * size + fields["v1"][0],
                                   start + i * size + fields["v2"][0])


def _blocks(raw):
    """Yield (code, sdna_index, (data_start, data_end), count) for every block."""
    position = len(BLEND_MAGIC)
    while position + _BHEAD.size <= len(raw):
        code, sdna_index, _old, length, count = _BHEAD.unpack_from(raw, position)
        start = position + _BHEAD.size
        yield code, sdna_index, (start, start + length), count
        if code == b"ENDB":
            return
        position = start + length
    raise ValueError("the .blend ends without an ENDB block")


def _sort_pointer_pair(raw, first, second):
    (a,), (b,) = struct.unpack_from("<Q", raw, first), struct.unpack_from("<Q", raw, second)
    if a > b:
        struct.pack_into("<Q", raw, first, b)
        struct.pack_into("<Q", raw, second, a)


def _zero_string_padding(raw, start, size, expected):
    name = expected.encode()
    if not raw[start:start + size].startswith(name + b"\0"):
        raise ValueError(f"expected colour-space name {expected!r} in the file header")
    end_of_name = start + len(name) + 1
    raw[end_of_name:start + size] = bytes(start + size - end_of_name)


def _zero_after_nul(raw, start, size):
    end = raw.index(b"\0", start, start + size) + 1
    raw[end:start + size] = bytes(start + size - end)


def _parse_sdna(dna):
    """Struct table of a DNA1 block.

    Returns
    -------
    list of (struct_name, struct_size, {field_name: (offset, size)})
        Indexed by SDNA struct index; field names without '*' or array
        suffixes.  SDNA structs have no implicit padding, so offsets are the
        running sum of the field sizes.
    """
    position = 4  # "SDNA"
    names, position = _read_names(dna, position, b"NAME")
    types, position = _read_names(dna, position, b"TYPE")
    position = _expect(dna, position, b"TLEN")
    type_sizes = struct.unpack_from(f"<{len(types)}h", dna, position)
    position = _align4(position + 2 * len(types))
    position = _expect(dna, position, b"STRC")
    (struct_count,) = struct.unpack_from("<i", dna, position)
    position += 4
    structs = []
    for _ in range(struct_count):
        type_index, field_count = struct.unpack_from("<hh", dna, position)
        position += 4
        offset, fields = 0, {}
        for _ in range(field_count):
            field_type, field_name = struct.unpack_from("<hh", dna, position)
            position += 4
            name = names[field_name]
            size = _field_size(name, type_sizes[field_type])
            fields[re.match(r"[*(]*(\w+)", name).group(1)] = (offset, size)
            offset += size
        structs.append((types[type_index], type_sizes[type_index], fields))
    return structs


def _field_size(name, type_size):
    element = _POINTER_SIZE if name.startswith(("*", "(*")) else type_size
    for dimension in re.findall(r"\[(\d+)\]", name):
        element *= int(dimension)
    return element


def _read_names(dna, position, tag):
    position = _expect(dna, position, tag)
    (count,) = struct.unpack_from("<i", dna, position)
    position += 4
    names = []
    for _ in range(count):
        end = dna.index(b"\0", position)
        names.append(dna[position:end].decode("latin-1"))
        position = end + 1
    return names, _align4(position)


def _expect(dna, position, tag):
    if dna[position:position + 4] != tag:
        raise ValueError(f"malformed DNA1 block: expected {tag!r}")
    return position + 4


def _align4(position):
    return (position + 3) & ~3
