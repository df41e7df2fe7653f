"""Material, light and world previews render with MC Engine, cheaply, like Cycles' (bpy, no window).

``bpy.ops.ed.lib_id_generate_preview`` renders an ID's preview icon through
the engine of the current scene, in Blender's preview scene, on a job thread;
``preview.render_icon`` polls the icon's pixels until they are written.  Cycles' icon of the
same material is the oracle: the mean display value over the sphere agrees
within 0.02 (measured: 0.003; a 10 % darker albedo moves it by 0.035).
"""
from __future__ import annotations

import bpy
import numpy as np
import pytest

from mcengine_blender.preview import render_icon as render_preview

ICON = 128           # Blender's preview icon size (ICON_SIZE_PREVIEW)


def diffuse_material(name, colour):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*colour, 1.0)
    tree.links.new(diffuse.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    return mat


def sphere_mean(pixels) -> np.ndarray:
    """Mean RGB over a disk of radius 30 px at the icon's centre (inside the sphere)."""
    rows, cols = np.mgrid[0:pixels.shape[0], 0:pixels.shape[1]]
    disk = (rows - pixels.shape[0] / 2) ** 2 + (cols - pixels.shape[1] / 2) ** 2 < 30 ** 2
    return pixels[disk][:, :3].mean(axis=0)


@pytest.fixture
def sessions(addon, monkeypatch):
    """The scene descriptions MC Engine rendered (the real session renders them)."""
    made = []
    real = addon.engine.session_factory

    def factory(desc, threads=None):
        made.append(desc)
        return real(desc, threads=threads)

    monkeypatch.setattr(addon.engine, "session_factory", factory)
    return made


def test_material_preview_is_cheap_and_has_the_materials_colour(scene, sessions, addon):
    red = render_preview(diffuse_material("Red", (0.8, 0.1, 0.1)))
    green = render_preview(diffuse_material("Green", (0.1, 0.8, 0.1)))
    assert len(sessions) == 2
    for desc in sessions:   # Blender's preview scene, at the icon's size, few samples
        assert desc.integrator.samples == addon.preview.PREVIEW_SAMPLES
        assert not desc.integrator.use_adaptive_sampling and desc.integrator.time_limit == 0
        assert desc.film.window == (0, 0, ICON, ICON)
        assert desc.geometry.num_triangles > 100     # the preview sphere, not an empty frame
    ours_red, ours_green = sphere_mean(red), sphere_mean(green)
    assert ours_red[0] > 1.4 * ours_red[1:].max()
    assert ours_green[1] > 1.4 * ours_green[[0, 2]].max()
    scene.render.engine = "CYCLES"
    cycles_red = sphere_mean(render_preview(diffuse_material("Red for Cycles", (0.8, 0.1, 0.1))))
    assert np.abs(ours_red - cycles_red).max() < 0.02, (ours_red, cycles_red)


def test_world_preview_shows_the_world_colour_as_cycles_does(scene, sessions):
    world = bpy.data.worlds.new("Sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.2, 0.4, 1.0, 1.0)
    ours = render_preview(world)
    assert len(sessions) == 1 and sessions[0].geometry.num_triangles == 0
    scene.render.engine = "CYCLES"
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0   # a new preview
    cycles = render_preview(world)
    assert np.abs(ours[..., :3] - cycles[..., :3]).max() < 0.01
    assert ours[..., 2].mean() > ours[..., 0].mean() + 0.2      # blue, not black


def test_light_preview_is_lit_by_the_light(scene, sessions):
    light = bpy.data.lights.new("Warm", "POINT")
    light.color = (1.0, 0.3, 0.05)
    light.energy = 5.0
    pixels = render_preview(light)
    assert len(sessions) == 1 and len(sessions[0].lights) == 1
    rgb = pixels[..., :3].mean(axis=(0, 1))
    assert rgb.max() > 0.2 and rgb[0] > 1.5 * rgb[2], rgb     # lit, in the light's colour
