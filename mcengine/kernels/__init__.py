"""The compiled side of the renderer: numba kernels and the device functions they inline.

Nothing here knows about Blender or files; everything works on the flat arrays
that ``mcengine.packing`` builds.  One module per concept:

* ``state``           path state, shadow queue, packed scene record, settings and counters
* ``scalar``          clamps that stay finite (saturate, safe_acos)
* ``sampling``        random numbers, warps, MIS heuristics, the pixel filter table
* ``sobol``           Owen-scrambled, shuffled Sobol points (the default sampler)
* ``intersect``       ray-scene intersection: Embree's BVH merged with moving objects, exact hits
* ``embree``          Embree itself (the only module that calls it): the BVH and its queries
* ``camera``          camera rays, and the stage that starts the paths of a chunk
* ``motion``          motion blur: shutter times and interpolated transforms
* ``surface``         the shading point: hit position, normals, local frame
* ``displace``        true displacement of mesh vertices
* ``tangents``        MikkTSpace tangents of a mesh (for the export; Blender's algorithm, one order)
* ``lights``          lamp shapes and emissive triangles: sampling, intersection, importance
* ``ies``             IES light profiles
* ``light_sampling``  which light next-event estimation picks, and MIS weights
* ``light_tree``      the light tree over emissive triangles
* ``background``      the world as a light: its importance map
* ``closures``        BSDF lobes: evaluation and sampling (one file per family)
* ``svm``             the shader evaluator: a material's node program at a shading point
* ``colorspace``      colour models, XYZ, black bodies
* ``shading``         the steps of shading a hit, shared by every integrator
* ``shadows``         shadow rays and the light that passes them
* ``subsurface``      random walks and disk probes inside one object
* ``passes``          render passes besides Combined
* ``path``            the path tracer's stages and its chunk loop
* ``emission``, ``importance``, ``light_tracing``  light tracing of caustics (Path + Light Tracing)
* ``classic``         ray casting, Whitted and distribution ray tracing
"""
