"""Light linking export: Blender's Receiver Collections as light sets (``export.linking``).

Each case states which objects each light reaches; the test reads that back from the exported
scene (an emitter reaches a receiver when its light sets hold the receiver's set), so it holds
for any numbering of the sets."""
import bpy
import numpy as np
import pytest

from mcengine.kernels.lights import LIGHT_SETS_ALL

from .helpers import export_scene, new_mesh_object
from .test_export_lights import lamp

TRI = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]


def reach(desc) -> dict:
    """{light or emissive object name: sorted names of the mesh objects it lights}."""
    g = desc.geometry
    receivers = dict(zip(g.object_names, g.receiver_sets().tolist()))
    emitters = {li.name: li.light_sets for li in desc.lights}
    emitters.update((name, int(m)) for name, m in zip(g.object_names, g.light_sets().tolist())
                    if name.startswith("Glow"))
    return {e: sorted(r for r, s in receivers.items() if mask >> s & 1)
            for e, mask in emitters.items()}


def receivers(names, collection=None):
    return [new_mesh_object(n, TRI, [(0, 1, 2)], collection=collection) for n in names]


def link(collection, ob, state):
    collection.objects.link(ob)
    collection.collection_objects[len(collection.objects) - 1].light_linking.link_state = state


def test_no_links_every_light_reaches_every_object(scene, fake_session):
    receivers(["A", "B"])
    lamp(scene, "POINT", name="Key")
    desc = export_scene(fake_session)
    assert desc.lights[0].light_sets == LIGHT_SETS_ALL
    assert desc.geometry.object_receiver_set is None and desc.geometry.object_light_sets is None
    assert not [w for w in desc.warnings if "linking" in w]


def test_include_and_exclude(scene, fake_session):
    """Include: the light reaches only the included objects; exclude: every object but the
    excluded; a light without a collection reaches all."""
    a, b, c = receivers(["A", "B", "C"])
    only = bpy.data.collections.new("OnlyA")
    link(only, a, "INCLUDE")
    but = bpy.data.collections.new("AllButB")
    link(but, b, "EXCLUDE")
    lamp(scene, "POINT", name="Key").light_linking.receiver_collection = only
    lamp(scene, "SPOT", name="Rim").light_linking.receiver_collection = but
    lamp(scene, "SUN", name="Fill")
    desc = export_scene(fake_session)
    assert reach(desc) == {"Key": ["A"], "Rim": ["A", "C"], "Fill": ["A", "B", "C"]}
    assert not [w for w in desc.warnings if "light linking" in w]


def test_shared_collection_child_collections_and_emissive_objects(scene, fake_session):
    """Two lights sharing a collection light the same objects; an object reached through a
    child collection takes the child entry's state; an emissive object links as a lamp."""
    a, b, c, d = receivers(["A", "B", "C", "D"])
    group = bpy.data.collections.new("Group")
    child = bpy.data.collections.new("Child")
    group.children.link(child)
    group.collection_children[0].light_linking.link_state = "EXCLUDE"
    child.objects.link(c)                                        # its own entry says INCLUDE
    link(group, a, "INCLUDE")
    link(group, b, "INCLUDE")
    lamp(scene, "POINT", name="Key").light_linking.receiver_collection = group
    lamp(scene, "AREA", name="Key2").light_linking.receiver_collection = group
    glow = new_mesh_object("Glow", TRI, [(0, 1, 2)])
    excl = bpy.data.collections.new("NotD")
    link(excl, d, "EXCLUDE")
    glow.light_linking.receiver_collection = excl
    desc = export_scene(fake_session)
    assert reach(desc) == {"Key": ["A", "B"], "Key2": ["A", "B"],
                           "Glow": ["A", "B", "C", "Glow"]}


def test_object_linked_by_several_collections(scene, fake_session):
    """A receiver excluded by one light and included by another lands in a set of its own."""
    a, b = receivers(["A", "B"])
    one, two = bpy.data.collections.new("One"), bpy.data.collections.new("Two")
    link(one, a, "EXCLUDE")
    link(two, a, "INCLUDE")
    link(two, b, "INCLUDE")
    lamp(scene, "POINT", name="First").light_linking.receiver_collection = one
    lamp(scene, "POINT", name="Second").light_linking.receiver_collection = two
    desc = export_scene(fake_session)
    assert reach(desc) == {"First": ["B"], "Second": ["A", "B"]}
    sets = desc.geometry.receiver_sets()
    assert len(set(sets.tolist())) == 2 and 0 not in sets


def test_shadow_linking_is_warned(scene, fake_session):
    """Shadow linking (a light's blocker collection) is not rendered: named with the lights
    that use it and the fallback."""
    receivers(["A"])
    blockers = bpy.data.collections.new("Blockers")
    lamp(scene, "SPOT", name="Rim").light_linking.blocker_collection = blockers
    lamp(scene, "SUN", name="Plain")
    warnings = export_scene(fake_session).warnings
    assert "shadow linking not supported yet ('Rim'); every object casts their shadows" in warnings
    assert not [w for w in warnings if "Plain" in w or "light linking" in w]


@pytest.mark.parametrize("kind", ["POINT", "SUN"])
def test_saved_scene_keeps_the_links(scene, fake_session, tmp_path, kind):
    from mcengine.scene import SceneDescription
    a, _ = receivers(["A", "B"])
    only = bpy.data.collections.new("OnlyA")
    link(only, a, "INCLUDE")
    lamp(scene, kind, name="Key").light_linking.receiver_collection = only
    desc = export_scene(fake_session)
    desc.save(tmp_path / "s.npz")
    back = SceneDescription.load(tmp_path / "s.npz")
    assert reach(back) == reach(desc) == {"Key": ["A"]}
    np.testing.assert_array_equal(back.geometry.receiver_sets(), desc.geometry.receiver_sets())
