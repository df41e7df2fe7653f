"""The command line names frames as Blender does: ``RenderSettings.frame_path`` is the oracle.

Blender replaces the last run of ``#`` in the file name by the frame number
(sign first, then zero-padded digits), appends four digits to a name without
``#``, and adds the format's extension.  The one documented difference: a
name already ending in ``.exr``/``.png`` gets its digits before that
extension (Blender would write ``out.exr0005.exr``).
"""
from __future__ import annotations

import pytest

from mcengine_blender.cli.args import _output_for
from mcengine_blender.cli.frames import frame_path

FRAMES = (0, 5, 12, 12345, -3, -250)


@pytest.mark.parametrize("raw", ["out_####", "out_#", "a#/b_##_v##", "//r/x_###_y", "d/", "out"])
@pytest.mark.parametrize("file_format", ["OPEN_EXR", "PNG"])
def test_names_match_blenders_frame_path(scene, tmp_path, raw, file_format):
    blend_dir = tmp_path / "scenes"
    text = raw if raw.startswith("//") else str(tmp_path / raw)
    output = _output_for(text, file_format, blend_dir, several=True)
    scene.render.image_settings.file_format = file_format
    scene.render.use_file_extension = True
    scene.render.filepath = str(blend_dir / raw[2:]) if raw.startswith("//") else text
    for frame in FRAMES:
        assert str(frame_path(output.pattern, frame)) == scene.render.frame_path(frame=frame)
