"""The compiled side of the renderer: numba kernels and the device functions they inline.

Nothing here knows about Blender or files; everything works on the flat arrays
that ``mcengine.packing`` builds.  One module per concept:

* ``state``           path state, shadow queue, packed scene record, settings and counters
* ``sampling``        random numbers, warps, MIS heuristics, the pixel filter table
* ``intersect``       Embree (the only module that uses it) and exact triangle hits
* ``camera``          camera rays, and the stage that starts the paths of a chunk
* ``surface``         the shading point: hit position, normals, local frame
* ``lights``          lamp shapes: sampling, intersection, importance
* ``light_sampling``  which light next-event estimation picks, and MIS weights
* ``materials``       the material table
* ``closures``        BSDF lobes: evaluation and sampling (one file per family)
* ``shading``         the steps of shading a hit, shared by every integrator
* ``path``            the path tracer's stages and its chunk loop
* ``classic``         ray casting, Whitted and distribution ray tracing
"""
