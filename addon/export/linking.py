"""Light linking: which lights light which objects (Object > Shading > Light Linking).

A light or an emissive object with a Receiver Collection lights only some objects: those the
collection includes (any object of it whose link state is Include), or every object but those
it excludes (state Exclude) when it includes none.  Blender's depsgraph reduces the links to
light sets, and Cycles renders those (source/blender/depsgraph/intern/
depsgraph_light_linking.cc, Cycles' kernel/light/light.h): every receiver belongs to one
light set, 0 for objects no collection names, and every emitter lights a mask of light sets.
This module computes the same sets from the same data, for the core's scene model
(``Light.light_sets``, ``Geometry.object_receiver_set`` and ``object_light_sets``).

The link state of an object reached through a child collection is that of the child
collection's entry in the receiver collection (its first level), as in Blender; an object
reached twice takes the state met last.  Blender numbers at most 64 receiver collections and
63 light sets besides the default one; the rest are left unlinked with a warning, as
Blender prints one.
"""
from __future__ import annotations

from mcengine.kernels.lights import LIGHT_SETS_ALL, MAX_LIGHT_SETS


def _objects_in_order(collection):
    """The objects of ``collection`` and its children, children first (Blender's order)."""
    for child in collection.children:
        yield from _objects_in_order(child)
    yield from collection.objects


def collection_links(collection):
    """(link state, object) of every object the collection reaches: its child collections'
    objects with the child's state, then its own objects with theirs."""
    for child, entry in zip(collection.children, collection.collection_children):
        state = entry.light_linking.link_state
        for ob in _objects_in_order(child):
            yield state, ob
    for ob, entry in zip(collection.objects, collection.collection_objects):
        yield entry.light_linking.link_state, ob


def _key(ob):
    return ob.original.as_pointer()


class LightLinks:
    """The light sets of a depsgraph's objects: ``receiver_set(ob)`` and ``light_sets(ob)``.

    ``warnings``: what could not be linked (one line each)."""

    def __init__(self, objects):
        collections = {}           # receiver collection (original) -> its bit
        self._emitter_bit = {}     # emitter -> bit of its collection
        self.warnings = []
        overflow = []
        for ob in objects:
            linking = getattr(ob.original, "light_linking", None)
            collection = getattr(linking, "receiver_collection", None)
            if collection is None or _key(ob) in self._emitter_bit:
                continue
            collection = collection.original
            if collection.as_pointer() not in collections:
                collections[collection.as_pointer()] = (len(collections), collection)
            bit, _ = collections[collection.as_pointer()]
            if bit >= MAX_LIGHT_SETS:
                overflow.append(ob.name)
                continue
            self._emitter_bit[_key(ob)] = bit
        if overflow:
            self.warnings.append(f"light linking: more than {MAX_LIGHT_SETS} receiver "
                                 f"collections; {', '.join(overflow)} light every object")
        # Each receiver's include and exclude masks over the collections' bits.
        masks = {}
        for bit, collection in collections.values():
            if bit >= MAX_LIGHT_SETS:
                continue
            for state, ob in collection_links(collection):
                include, exclude = masks.get(_key(ob), (0, 0))
                if state == "INCLUDE":
                    include, exclude = include | (1 << bit), exclude & ~(1 << bit)
                else:
                    include, exclude = include & ~(1 << bit), exclude | (1 << bit)
                masks[_key(ob)] = (include, exclude)
        # Light sets: one per distinct pair of masks, numbered from 1 (0 is the default set).
        ids = {}
        self._receiver = {}
        for key, pair in masks.items():
            if pair not in ids:
                ids[pair] = len(ids) + 1
                if ids[pair] == MAX_LIGHT_SETS:
                    self.warnings.append(f"light linking: more than {MAX_LIGHT_SETS - 1} light "
                                         f"sets; the objects beyond them are lit as unlinked objects")
            if ids[pair] < MAX_LIGHT_SETS:
                self._receiver[key] = ids[pair]
        included, excluded = {}, {}
        bits = set(self._emitter_bit.values())
        for (include, exclude), set_id in ids.items():
            if set_id >= MAX_LIGHT_SETS:
                continue
            for bit in bits:
                if include >> bit & 1:
                    included[bit] = included.get(bit, 0) | (1 << set_id)
                if exclude >> bit & 1:
                    excluded[bit] = excluded.get(bit, 0) | (1 << set_id)
        self._membership = {bit: (included.get(bit) or LIGHT_SETS_ALL) & ~excluded.get(bit, 0)
                            for bit in bits}

    def receiver_set(self, ob) -> int:
        """The light set object ``ob`` receives (0: the default set)."""
        return self._receiver.get(_key(ob), 0)

    def light_sets(self, ob) -> int:
        """The light sets emitter ``ob`` lights (all of them when it has no links)."""
        bit = self._emitter_bit.get(_key(ob))
        return LIGHT_SETS_ALL if bit is None else self._membership[bit]
