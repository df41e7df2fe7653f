"""Registration: the engine, its panels and the reuse of Blender's and Cycles' panels."""
from types import SimpleNamespace

import bpy
import pytest

from .helpers import load_addon_from_folder


def _engine_items():
    """The engines Blender offers, read from the error for an unknown value (the enum is dynamic)."""
    with pytest.raises(TypeError) as err:
        bpy.context.scene.render.engine = "NO_SUCH_ENGINE"
    return str(err.value)


def test_engine_is_offered_in_the_render_engine_menu(scene):
    assert "'MCENGINE'" in _engine_items()
    assert bpy.types.RenderEngine.bl_rna_get_subclass_py("MCENGINE").bl_label == "MC Engine"
    assert scene.render.engine == "MCENGINE"


def test_register_and_unregister_twice_are_safe(scene, addon):
    addon.register()
    addon.register()
    assert addon.engine.MCEngine.is_registered
    assert hasattr(scene, "mcengine")
    addon.unregister()
    addon.unregister()
    assert not addon.engine.MCEngine.is_registered
    assert not hasattr(bpy.types.Scene, "mcengine")
    assert "'MCENGINE'" not in _engine_items()
    addon.register()
    assert "'MCENGINE'" in _engine_items()
    assert scene.mcengine.last_effects == ""


def _context(engine, **data):
    return SimpleNamespace(engine=engine, scene=bpy.context.scene, **data)


@pytest.fixture
def panel_data(scene):
    light = bpy.data.lights.new("Lamp", "AREA")
    return dict(light=light, material=bpy.data.materials.new("Mat"),
                world=bpy.data.worlds.new("World"), camera=scene.camera.data,
                object=bpy.data.objects.new("Obj", bpy.data.meshes.new("Obj")))


PANELS = [
    # Cycles' own panels (shared COMPAT_ENGINES set)
    "CYCLES_RENDER_PT_sampling", "CYCLES_RENDER_PT_light_paths", "CYCLES_RENDER_PT_film",
    "CYCLES_LIGHT_PT_light", "CYCLES_MATERIAL_PT_surface", "CYCLES_WORLD_PT_surface",
    # Blender's panels that Cycles also shows
    "DATA_PT_lens", "DATA_PT_context_light", "RENDER_PT_format", "RENDER_PT_color_management",
    "OBJECT_PT_shading",       # with its Light Linking and Shadow Linking sub-panels
    # ours
    "MCENGINE_RENDER_PT_engine",
]


@pytest.mark.parametrize("name", PANELS)
def test_panels_show_for_mcengine_and_stop_after_unregister(name, panel_data, addon):
    panel = getattr(bpy.types, name)
    assert panel.poll(_context("MCENGINE", **panel_data))
    assert not panel.poll(_context("SOME_OTHER_ENGINE", **panel_data))
    addon.unregister()
    try:
        if name != "MCENGINE_RENDER_PT_engine":  # ours is unregistered altogether
            assert not panel.poll(_context("MCENGINE", **panel_data))
            assert panel.poll(_context("CYCLES", **panel_data)), "Cycles lost its panel"
    finally:
        addon.register()


def test_panels_replaced_by_cycles_stay_hidden(scene, panel_data):
    """Blender's light panel would duplicate Cycles' CYCLES_LIGHT_PT_light."""
    assert "MCENGINE" not in bpy.types.DATA_PT_light.COMPAT_ENGINES
    assert "MCENGINE" not in bpy.types.MATERIAL_PT_preview.COMPAT_ENGINES


def test_loads_as_an_extension_module(scene, addon):
    """As an extension the package is ``bl_ext.<repo>.<id>``: only relative imports work."""
    import sys
    import types

    addon.unregister()
    for parent in ("bl_ext", "bl_ext.test_repo"):
        sys.modules.setdefault(parent, types.ModuleType(parent)).__path__ = []
    ext = load_addon_from_folder("bl_ext.test_repo.mcengine")
    try:
        ext.register()
        assert ext.engine.MCEngine.is_registered
        assert "'MCENGINE'" in _engine_items()
        ext.unregister()
        assert "'MCENGINE'" not in _engine_items()
    finally:
        for key in [k for k in sys.modules if k.startswith("bl_ext")]:
            del sys.modules[key]
        addon.register()

