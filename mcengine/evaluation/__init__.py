"""Evaluation: how MC Engine is measured against Cycles and against time.

Never imported by the renderer, and never imports Blender.  Models compute,
writers only format:

* ``stats``: do two stacks of renders agree (the verdict's statistics), and
  the image error metrics relMSE and SMAPE;
* ``comparison``: one scene compared with Cycles (the report's numbers), and
  the rows of a suite of scenes;
* ``study``: accuracy against time (the ladder of renders, the error model,
  slopes, time to a target error);
* ``figures`` (the only matplotlib user), ``pages`` (Markdown and HTML) and
  ``datafiles`` (CSV and JSON) write them; ``output`` writes a whole result
  into a folder.
"""
