"""The closure list: how a shading point's closures are stored, and their codes.

Evaluating a material at a shading point (``kernels.svm``) produces a short
list of closures, as Cycles does (kernel/closure/alloc.h): each is one row of
a float64 array ``cl`` of shape (MAX_CLOSURES, CL_STRIDE), owned by the worker
thread and overwritten at every hit.  A row holds the closure's type, its
weight (colour, mix factors, layering, energy-compensation darkening), its
sample weight (the probability of picking it, unnormalised), its shading frame
and its parameters.  Every closure module reads the columns it needs.

Directions: ``wo`` points to the viewer (Cycles' ``sd->wi``), ``wi`` to the
light or the sampled direction (Cycles' ``wo``).  In a closure's local frame
the normal ``CL_N`` is +z and the tangent ``CL_T`` is +x.

Codes
-----
``CT_*``  closure types (which module evaluates the row)
``FR_*``  Fresnel models of microfacet closures (kernel/closure/bsdf_microfacet.h)
``MD_*``  microfacet distributions
``LABEL_*`` lobe labels of a sample, as Cycles' LABEL_* (kernel/closure/bsdf.h)
"""
from __future__ import annotations

MAX_CLOSURES = 16        # Principled + Mix of two Principled stays below 16 (Cycles allows 64)

# -- columns of a closure row ------------------------------------------------------------------
CL_TYPE = 0              # CT_* code
CL_W = 1                 # 3: weight RGB (what eval/sample results are multiplied by)
CL_SW = 4                # sample weight (>= 0): probability of picking the closure, unnormalised
CL_N = 5                 # 3: unit normal, world space, on the viewer's side
CL_T = 8                 # 3: unit tangent, world space, orthogonal to CL_N (the frame's +x)
CL_AX = 11               # microfacet alpha along the tangent (alpha = roughness^2)
CL_AY = 12               # microfacet alpha along the bitangent
CL_ETA = 13              # relative index of refraction (inside / outside; 1/IOR on back faces)
CL_DIST = 14             # MD_* distribution
CL_FRESNEL = 15          # FR_* Fresnel model
CL_F0 = 16               # 3: reflectance at normal incidence (Schlick, F82); conductor: n
CL_F90 = 19              # 3: generalized Schlick: reflectance at grazing incidence; F82: B term;
                         #    conductor: k
CL_EXPONENT = 22         # generalized Schlick exponent (< 0: remap the real Fresnel curve)
CL_RTINT = 23            # 3: reflection tint
CL_TTINT = 26            # 3: transmission tint
CL_ENERGY = 29           # multiple-scattering energy scale 1 + (1 - E) / E (1: none)
CL_P0 = 30               # closure-specific parameters (Oren-Nayar A, B, multiscatter RGB;
CL_P1 = 31               # sheen LTC a, b)
CL_P2 = 32
CL_P3 = 33
CL_P4 = 34
CL_ALBEDO = 35           # 3: microfacet: the albedo estimate at the view, from the setup (layering)
CL_NS = 38               # 3: the point's smooth (interpolated, not normal-mapped) normal, viewer's side
CL_BUMP_CORRECTION = 41  # 1: the material's Bump Map Correction is on (softens diffuse closures)
CL_TERMINATOR = 42       # the object's Shadow Terminator Shading Offset as a frequency (> 1: on)
CL_FILM_THICKNESS = 43   # microfacet: thin film over the surface, thickness in nm (<= 0.1: none)
CL_FILM_IOR = 44         # microfacet: the film's IOR relative to the outside (tf / IOR on back faces)
CL_STRIDE = 45
# A BSSRDF row (CT_BSSRDF) keeps its walk's parameters in these columns; its microfacet
# alpha (the refractive entry's roughness) in CL_AX and its IOR in CL_ETA.
CL_RADIUS = CL_P0        # 3: mean free path per channel (after Cycles' scaling; 0: no walk)
CL_SSS_ALBEDO = CL_F0    # 3: the surface albedo the walk reproduces
CL_ANISOTROPY = CL_P3    # the phase function's g, in [0, 0.9]
CL_SSS_METHOD = CL_P4    # SSS_* method
CL_VELVET_INV_SIGMA2 = CL_P0   # a velvet's 1 / sigma^2 (sigma = max(roughness, 0.01))
# A Hair BSDF row: the strand's tangent in the closure's local frame (not orthogonal to the
# normal when a Tangent is linked), the roughnesses along and around it, and its offset angle.
CL_HAIR_T = CL_F0        # 3
CL_HAIR_R1 = CL_P0
CL_HAIR_R2 = CL_P1
CL_HAIR_OFFSET = CL_P2
# A Ray Portal row: where the ray continues and in which unit direction (world space).
CL_PORTAL_P = CL_F0      # 3
CL_PORTAL_D = CL_F90     # 3

# -- closure types -------------------------------------------------------------------------------
CT_NONE = 0
CT_DIFFUSE = 1           # Lambert: f = 1/pi
CT_OREN_NAYAR = 2        # Fujii's improved Oren-Nayar with the OpenPBR multiple-scatter term
CT_TRANSLUCENT = 3       # Lambert on the far side
CT_SHEEN = 4             # Zeltner et al. 2022 microfibre sheen (LTC)
CT_MICROFACET = 5        # rough (or smooth) reflection only
CT_MICROFACET_REFRACTION = 6   # rough (or smooth) refraction only
CT_MICROFACET_GLASS = 7  # reflection and refraction, split by Fresnel
CT_TRANSPARENT = 8       # straight pass-through (a transparent bounce)
CT_BSSRDF = 9            # subsurface scattering: a random walk inside the object (``subsurface``)
CT_ASHIKHMIN_SHIRLEY = 10  # the Glossy BSDF's Ashikhmin-Shirley lobe (``ashikhmin``)
CT_VELVET = 11           # the Sheen BSDF's Ashikhmin velvet (``ashikhmin``)
CT_DIFFUSE_TOON = 12     # the Toon BSDF's diffuse component (``toon``)
CT_GLOSSY_TOON = 13      # the Toon BSDF's glossy component (``toon``)
CT_HAIR_REFLECTION = 14  # the Hair BSDF's reflection component (``hair``)
CT_HAIR_TRANSMISSION = 15  # the Hair BSDF's transmission component (``hair``)
CT_RAY_PORTAL = 16       # the Ray Portal BSDF: the ray goes on from another point (a transparent bounce)

# -- subsurface methods (the nodes' subsurface_method / falloff) -------------------------------
SSS_BURLEY = 0           # Christensen-Burley: disk probes of the surface around the point
SSS_RANDOM_WALK = 1      # refractive GGX entry with the material's IOR and roughness
SSS_RANDOM_WALK_SKIN = 2  # half diffuse entry, half refractive with roughness 1; dipole radius

# -- Fresnel models --------------------------------------------------------------------------
FR_NONE = 0              # reflectance 1 (the weight carries the colour), no TIR handling
FR_DIELECTRIC = 1        # exact unpolarised dielectric Fresnel with CL_ETA
FR_SCHLICK = 2           # generalized Schlick: mix(F0, F90, s) x tints
FR_F82 = 3               # F82-tint conductor: Schlick(F0) - B cos (1 - cos)^6
FR_CONDUCTOR = 4         # conductor of complex IOR: n in CL_F0, k in CL_F90 (per channel)

# -- microfacet distributions ------------------------------------------------------------------
MD_GGX = 0
MD_BECKMANN = 1

# -- lobe labels (bit flags) -------------------------------------------------------------------
LABEL_NONE = 0
LABEL_REFLECT = 1
LABEL_TRANSMIT = 2
LABEL_DIFFUSE = 4
LABEL_GLOSSY = 8
LABEL_SINGULAR = 16
LABEL_TRANSPARENT = 32
LABEL_SUBSURFACE = 256   # into the object, for a random walk (Cycles' LABEL_SUBSURFACE_SCATTER)
LABEL_RAY_PORTAL = 512   # on from the Ray Portal's point and direction

# alpha_x * alpha_y at or below this is a singular (perfectly smooth) lobe: it can only be
# sampled, never evaluated (Cycles' BSDF_ROUGHNESS_SQ_THRESH; roughness about 0.0038).
ROUGHNESS_SQ_THRESHOLD = 2e-10
# Closures with |average weight| below this are not allocated (Cycles' CLOSURE_WEIGHT_CUTOFF).
CLOSURE_WEIGHT_CUTOFF = 1e-5
