"""Batch tools: render .blend files in this process, compare with Cycles, study accuracy.

* ``render``: open a .blend, render a scene with either engine and get the
  pixels back (the one place that names the engines and turns a bpy error
  into one line);
* ``settings``: the scene settings these tools change (overrides for one
  render, the unbiased settings of a comparison) and putting them back;
* ``comparison``: MC Engine against Cycles on a scene, a file or a folder;
* ``study``: accuracy against time on a scene or a file;
* ``outputs``: files written atomically (temporary file, checked, renamed);
* ``interrupt``: the stop flag that the command line's signal handlers set and
  that these tools and MC Engine renders honour.

The command line (``cli``), the operators, the tests and the benchmark use
them; the numbers and files come from :mod:`mcengine.evaluation`.  Importing
this package does not import ``bpy``.
"""
