"""MC Engine for Blender: render with the mcengine Monte Carlo path tracer.

Pick "MC Engine" in Render Properties > Render Engine and press F12.  The
add-on is a thin layer: ``export`` turns the evaluated scene into an
``mcengine.scene.SceneDescription``, ``engine`` runs the core's render
session and shows its passes.  Cycles' settings, panels and shader nodes are
reused (see ``ui``).

Works as the Python package ``mcengine_blender`` and as a Blender extension
(``bl_ext.<repo>.<id>``): imports inside the add-on are relative; the core is
``import mcengine``.  ``register`` and ``unregister`` may be called twice.

Importing this package does not import ``bpy``: the command line
(``mcengine_blender.cli``) lives here too and must reject bad arguments
before paying for Blender's start-up.
"""

__all__ = ["register", "unregister"]


def register() -> None:
    from . import engine, operators, properties, ui, warmup
    properties.register()
    engine.register()
    operators.register()
    ui.register()
    warmup.start()


def unregister() -> None:
    from . import engine, operators, properties, ui, warmup
    warmup.stop()
    ui.unregister()
    operators.unregister()
    engine.unregister()
    properties.unregister()
