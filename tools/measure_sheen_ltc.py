"""Measure Cycles' Sheen (microfibre) LTC table by rendering, and fit it.

Cycles' Sheen BSDF (Zeltner, Burley and Chiang 2022, ``kernel/closure/bsdf_sheen.h``)
evaluates a linearly transformed cosine whose parameters *a*, *b* and albedo *rho*
come from a 32 x 32 table indexed by (cos theta_view, roughness), nodes at k/31,
read with bilinear interpolation (``kernel/util/lookup_table.h``).  We may not
copy that table, so this script measures it: it renders white Sheen BSDFs with
Cycles (bpy 5.0.1) and fits the three parameters.

Model (local frame z = N, x = T with (T, B) = make_orthonormals_safe_tangent(N,
wi): B = normalize(N x wi), T = B x N, so the view lies in the +x half of the
xz plane; wo = local light direction)::

    eval(wo) = max(wo.z, 0) * (a / l)^2 / pi,  l = (a x + b z)^2 + (a y)^2 + z^2

and the closure weight is multiplied by rho.  With a delta sun of strength S
(irradiance S cos theta on a plane), a black world and max_bounces 0, a lit
pixel is ``rho * eval(wo) * S`` (checked in every render on a row of white
Lambert facets, which must show S cos theta / pi).

Table written (``mcengine/kernels/closures/data/sheen_ltc.npy``)
----------------------------------------------------------------
::

    float64, shape (3, 32, 32) = (a, b, rho)[param, j, i]
    j: roughness index, roughness = j / 31 (Cycles clamps roughness to [1e-3, 1])
    i: cos(theta_view) index, cos theta_view = i / 31

This is Cycles' own order (offset + 32 * j + i within each parameter), read
with lookup_table_read_2D(x = cos theta_view, y = roughness).  Values have 5
decimals, as Cycles' table evidently has (see "How it fits").  Cycles drops
the closure where the *interpolated* |a| < 1e-5 or rho < 1e-5.  At low
roughness rho is 0 over a whole region of nodes (roughness <= 4/31, the
more so the larger cos theta_view).  Nodes there that share a table cell with a
kept node still shape what Cycles renders in that cell: their a and b are
measured at off-node points of those cells and stored, with rho = 0 (which
is what the measurement gives).  The other nodes of that region never
influence a render (every cell around them is dropped): they hold
a = b = rho = 0.  rho = 1e-5 exactly is kept (not below the threshold).

What is rendered
----------------
One render per sun direction.  The orthographic camera looks straight down
-Z, so the view direction is wi = +Z for every pixel; the sun (angle 0, a
delta light, strength pi) lies in the XZ plane at an angle gamma from +Z.
The image is a grid of cells of ``--cell`` x ``--cell`` pixels (5); each
cell is one flat facet (a quad) whose vertices are placed so that its
projection is exactly the cell square (a height field z = -(Nx dx + Ny dy)
/ Nz), so facets never overlap on screen, whatever their tilt.  Shadows are
off (sun ``use_shadow`` False, facets ``visible_shadow`` False), so no facet
shadows another.  The facet normal N is chosen so that N . wi = mu (the
view cosine of the measured point) and the local light direction is the
point at azimuth psi on the circle of directions at angle gamma around the
local view direction.  Each measured point (mu, roughness) is a block of 12
cells, psi = 0, 30, ..., 330 degrees; the sun angles are gamma = 0, 15, ...,
165 degrees (gamma = 0 is the one configuration wo = wi); configurations
with wo.z < 0.02 are left out.  So a point gets 55 to 66 light directions
spread over the hemisphere in elevation and in azimuth relative to the view
plane.  One material per distinct roughness (white Sheen BSDF, MICROFIBER),
plus a row of white Lambert facets in every render: they must show
S cos theta / pi (the radiometric check; max error 1.7e-6).

Pass 1 (12 renders of 1980 x 175 px): the node grid, roughness 1e-3 (what
Cycles reads for j = 0 after its clamp: 0.031 of the way to node 1),
1/31, ..., 1 times mu = 0.1/31 (stands for node i = 0, which is edge-on),
1/31, ..., 30/31, 30.9/31 (stands for node i = 31: at mu = 1 the tangent
frame is degenerate); the half-way points mu = 0.5/31 and roughness 0.5/31
of the boundary cells; mu = 1 exactly (fallback frame; a check only).

Pass 2 (12 renders of 1980 x 55 px): for every table cell with both dropped
and kept corners, the 3 x 3 points at fractions 1/4, 1/2, 3/4.

Cells are read from the 32-bit EXR: the mean of the cell minus a one-pixel
border.  With a delta sun, one sample per pixel, max_bounces 0 and a Box
filter the values are noise-free: every pixel of a facet sees the same
configuration (largest relative spread inside a cell 3e-6; seeds 0 and 1
give bit-identical images, ``--seed-check``).  Exception, the "knife edge":
where the interpolated rho is exactly 1e-5 (between nodes of 0 and 2e-5,
or of 1e-5 and 1e-5) Cycles' float32 lookup rounding decides whether the
closure is dropped, differently on the two triangles of a facet; such
points are neither used nor counted as disagreements.

How it fits
-----------
1. Per point: (a, b, rho) by least squares on log(radiance) (relative
   residuals), started from the best point of a coarse (a, b) grid with rho
   solved in closed form.  Local light directions are computed from the
   float32 facet vertices and sun matrix as Cycles computes them (triangle
   normal, make_orthonormals_safe_tangent), in float64.  Standard errors
   follow from the Jacobian and the residuals.  Max relative residual 1.8e-5,
   median 6e-7.
2. Nodes, linear: Cycles interpolates a, b and rho linearly and
   independently, so every fitted point is a known combination of node
   values (bilinear weights, roughness clamp included); weighted least
   squares (1 / standard error) of all these equations.
3. Nodes, direct: where a is tiny the lobe depends on rho a^2 alone and
   step 1 cannot split a, b and rho; so the node values are refined by
   fitting them to every rendered cell at once (78871 cells, 2868 unknowns,
   sparse trust-region least squares): max relative error 9.7e-6.
4. Rounding: the fitted node values fall on multiples of 1e-5 (median
   distance 0.002 to 0.005 of a step, 99 % within 0.03 of a step; random
   values would give 0.25): Cycles' table evidently holds 5 decimals.  The
   table is rounded to 5 decimals, which reproduces every rendered cell to
   4.6e-6 (median 3e-7), better than the unrounded fit.  Nodes that no
   rendered point depends on are set to a = b = rho = 0.

Checks printed: the dropped/lit state of every point (0 disagreements),
mu = 1 exactly (5.3e-7), and a validation render of 2000 random off-node
configurations (gamma 60 degrees, one light direction each, a quarter of
them in the cells at the edge of the dropped region), predicted from the
table with Cycles' bilinear lookup and dropping rule: max relative error
2.9e-6, 0 disagreements.  Then the oracles of cycles-closures.md section 10.

Cost: 25 renders (at most 1980 x 175 pixels, 1 sample, 2 threads), about
25 s of rendering including scene building; the whole run takes about 70 s
wall-clock on 2 cores (about 40 s CPU), 1.5 times that with ``--seed-check``.

Usage::

    .venv/bin/python -m tools.measure_sheen_ltc               # measure, fit, write the table
    .venv/bin/python -m tools.measure_sheen_ltc --seed-check  # also render one set twice, seeds 0 and 1
"""
from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
TABLE_PATH = REPO / "mcengine" / "kernels" / "closures" / "data" / "sheen_ltc.npy"

SIZE = 32                                   # nodes per axis, at k / 31
SUN_STRENGTH = math.pi                      # a Lambert facet at normal incidence shows 1
GAMMAS_DEG = tuple(15.0 * k for k in range(12))           # 0, 15, ..., 165
PSI = tuple(2.0 * math.pi * k / 12 for k in range(12))    # 0, 30, ..., 330 degrees
MIN_COS_LIGHT = 0.02                        # configurations closer to grazing are not used
MAX_CELL_SPREAD = 1e-4                      # relative difference allowed between the pixels of a cell
BLOCKS_PER_ROW = 33                         # measured points per image row
CAMERA_HEIGHT = 1.0e4
# Cycles drops the closure below these (bsdf_sheen_setup), on interpolated values.
MIN_A = 1e-5
MIN_RHO = 1e-5
MIN_ROUGHNESS = 1e-3                        # bsdf_sheen_setup clamps the roughness to [1e-3, 1]

# Pass 1: what stands for node k along each axis (see the module docstring).
MU_NODE_POINTS = np.array([0.1 / 31] + [i / 31 for i in range(1, 31)] + [30.9 / 31])
ROUGHNESS_NODE_POINTS = np.array([MIN_ROUGHNESS] + [j / 31 for j in range(1, 32)])
EDGE_FRACTIONS = (0.25, 0.5, 0.75)          # pass 2 points inside a cell


# ----------------------------------------------------------------------------- model


def sheen_eval(a, b, wo):
    """Cycles' bsdf_sheen_eval (f * cos) for local light directions ``wo`` (..., 3).

    ``a`` and ``b`` are scalars or arrays of shape (m,), broadcast against wo (m, n, 3).
    """
    x, y, z = wo[..., 0], wo[..., 1], wo[..., 2]
    a = np.asarray(a, dtype=float)[..., None] if np.ndim(a) else a
    b = np.asarray(b, dtype=float)[..., None] if np.ndim(b) else b
    length_sq = (a * x + b * z) ** 2 + (a * y) ** 2 + z ** 2
    return np.maximum(z, 0.0) * (a / length_sq) ** 2 / math.pi


def lookup_1d_weights(x: float, size: int = SIZE) -> dict[int, float]:
    """Node weights of Cycles' lookup_table_read at x (saturated, nodes at k / (size - 1))."""
    x = float(np.float32(min(max(float(np.float32(x)), 0.0), 1.0)) * np.float32(size - 1))
    index = min(int(x), size - 1)
    following = min(index + 1, size - 1)
    t = x - index
    weights = {index: 1.0 - t}
    weights[following] = weights.get(following, 0.0) + t
    return weights


def lookup_2d_weights(mu: float, roughness: float) -> np.ndarray:
    """(32, 32) weights [j, i] of lookup_table_read_2D(mu, clamped roughness)."""
    w = np.zeros((SIZE, SIZE))
    for j, wj in lookup_1d_weights(min(max(roughness, MIN_ROUGHNESS), 1.0)).items():
        for i, wi in lookup_1d_weights(mu).items():
            w[j, i] += wj * wi
    return w


def lookup_table(table: np.ndarray, mu: float, roughness: float) -> np.ndarray:
    """(a, b, rho) read from ``table`` (3, 32, 32) as Cycles' lookup_table_read_2D does."""
    return np.tensordot(table, lookup_2d_weights(mu, roughness), axes=([1, 2], [0, 1]))


def dropped(a, rho) -> bool:
    """Cycles' bsdf_sheen_setup drops the closure for these interpolated values."""
    return abs(a) < MIN_A or rho < MIN_RHO


def safe_tangent_frame(normal: np.ndarray, wi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """make_orthonormals_safe_tangent(N, wi) -> (T, B), in float64."""
    b = np.cross(normal, wi)
    length = np.linalg.norm(b)
    b = b / length if length > 0.0 else b
    if b @ b < 0.99:                                       # fallback: make_orthonormals(N)
        n = normal
        if n[0] != n[1] or n[0] != n[2]:
            t = np.array([n[2] - n[1], n[0] - n[2], n[1] - n[0]])
        else:
            t = np.array([n[2] - n[1], n[0] + n[2], -n[1] - n[0]])
        t = t / np.linalg.norm(t)
        return t, np.cross(n, t)
    return np.cross(b, normal), b


# ----------------------------------------------------------------------------- layout


def facet_normal(mu: float, gamma: float, psi: float) -> np.ndarray:
    """World normal N with N . (0, 0, 1) = mu that puts the sun at (gamma, psi) around the local view.

    The sun is at (sin gamma, 0, cos gamma) in the world; locally the view is
    wi = (s, 0, mu) and the light wo = cos gamma wi + sin gamma (cos psi e1 + sin psi e2),
    with e1 = (mu, 0, -s) and e2 = (0, 1, 0).  The rotation taking the local
    (wi, wo) pair to the world pair gives N.  mu = 1 gives exactly +Z.
    """
    if mu >= 1.0:
        return np.array([0.0, 0.0, 1.0])
    s = math.sqrt(1.0 - mu * mu)
    v1 = np.array([s, 0.0, mu])
    v2 = math.cos(psi) * np.array([mu, 0.0, -s]) + math.sin(psi) * np.array([0.0, 1.0, 0.0])
    v3 = np.cross(v1, v2)
    # World basis: u1 = view (0, 0, 1), u2 = (1, 0, 0) towards the sun, u3 = u1 x u2 = (0, 1, 0).
    return np.array([v2[2], v3[2], v1[2]])


def layout(points, gamma: float, psis=PSI):
    """The cells of one render for measured ``points`` [(mu, roughness), ...].

    Returns (cells, ncols, nrows); a cell is a dict with col, row, point (index
    into points, -1 for the Lambert row), roughness (None for Lambert), normal.
    """
    psis = psis[:1] if gamma == 0.0 else psis
    light = np.array([math.sin(gamma), 0.0, math.cos(gamma)])
    cells = []
    for p, (mu, roughness) in enumerate(points):
        block_row, block_col = divmod(p, BLOCKS_PER_ROW)
        for k, psi in enumerate(psis):
            normal = facet_normal(mu, gamma, psi)
            if normal @ light >= MIN_COS_LIGHT:
                cells.append(dict(col=block_col * len(psis) + k, row=block_row, point=p,
                                  roughness=float(roughness), normal=normal))
    nrows = (len(points) + BLOCKS_PER_ROW - 1) // BLOCKS_PER_ROW
    lambert = [dict(c, row=nrows, point=-1, roughness=None) for c in cells if c["row"] == 0]
    return cells + lambert, BLOCKS_PER_ROW * len(psis), nrows + 1


# ----------------------------------------------------------------------------- rendering


def _material(bpy, name: str, roughness: float | None):
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    tree = material.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    if roughness is None:
        bsdf = tree.nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Roughness"].default_value = 0.0
    else:
        bsdf = tree.nodes.new("ShaderNodeBsdfSheen")
        bsdf.distribution = "MICROFIBER"
        bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    tree.links.new(bsdf.outputs[0], output.inputs["Surface"])
    return material


def render_cells(cells, ncols: int, nrows: int, gamma: float, cell: int, seed: int = 0, threads: int = 2):
    """Render one sun direction with Cycles.

    Returns (mean, spread, wo, seconds): per cell the mean grey value of the
    pixels inside the one-pixel border, the largest difference between those
    pixels (and between the RGB channels), and the local light direction
    (3,) as Cycles computes it.
    """
    import bpy
    import OpenEXR

    started = time.perf_counter()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = 1
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.max_bounces = 0
    cycles.seed = seed
    cycles.pixel_filter_type = "BOX"
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.view_settings.view_transform = "Standard"
    width, height = ncols * cell, nrows * cell
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    # One quad per cell, projecting exactly onto its cell square.
    slots = {}
    half = cell / 2.0
    verts, faces, material_index = [], [], []
    for c in cells:
        cx, cy = c["col"] * cell + half, c["row"] * cell + half
        n = c["normal"]
        base = len(verts)
        for dx, dy in ((-half, -half), (half, -half), (half, half), (-half, half)):
            verts.append((cx + dx, cy + dy, -(n[0] * dx + n[1] * dy) / n[2]))
        faces.append((base, base + 1, base + 2, base + 3))
        material_index.append(slots.setdefault(c["roughness"], len(slots)))
    mesh = bpy.data.meshes.new("facets")
    mesh.from_pydata(verts, [], faces)
    for roughness in slots:
        mesh.materials.append(_material(bpy, f"r{roughness}", roughness))
    mesh.polygons.foreach_set("material_index", material_index)
    mesh.polygons.foreach_set("use_smooth", [False] * len(faces))
    mesh.update()
    obj = bpy.data.objects.new("facets", mesh)
    obj.visible_shadow = False
    scene.collection.objects.link(obj)

    camera = bpy.data.cameras.new("camera")
    camera.type = "ORTHO"
    camera.ortho_scale = max(width, height)
    camera.clip_start = 1.0
    camera.clip_end = 2.0 * CAMERA_HEIGHT
    camera_obj = bpy.data.objects.new("camera", camera)
    camera_obj.location = (width / 2.0, height / 2.0, CAMERA_HEIGHT)
    scene.collection.objects.link(camera_obj)
    scene.camera = camera_obj

    sun = bpy.data.lights.new("sun", "SUN")
    sun.energy = SUN_STRENGTH
    sun.angle = 0.0
    sun.use_shadow = False
    sun_obj = bpy.data.objects.new("sun", sun)
    sun_obj.rotation_euler = (0.0, gamma, 0.0)
    scene.collection.objects.link(sun_obj)
    bpy.context.view_layer.update()
    light = np.array(sun_obj.matrix_world, dtype=np.float32)[:3, 2].astype(np.float64)
    light /= np.linalg.norm(light)

    # Local light directions as Cycles computes them, from the stored float32 vertices.
    mesh.calc_loop_triangles()
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3).astype(np.float64)
    tri = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tri)
    tri = tri.reshape(-1, 3)
    tri_poly = np.empty(len(mesh.loop_triangles), dtype=np.int32)
    mesh.loop_triangles.foreach_get("polygon_index", tri_poly)
    normals = np.cross(co[tri[:, 1]] - co[tri[:, 0]], co[tri[:, 2]] - co[tri[:, 0]])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    wi = np.array([0.0, 0.0, 1.0])
    wo = np.zeros((len(cells), 3))
    for p in range(len(cells)):
        local = []
        for n in normals[tri_poly == p]:                   # the quad's two (coplanar) triangles
            t, b = safe_tangent_frame(n, wi)
            local.append([light @ t, light @ b, light @ n])
        wo[p] = np.mean(local, axis=0)

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "sheen.exr"
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        scene.render.filepath = str(path)
        bpy.ops.render.render(write_still=True)
        with OpenEXR.File(str(path)) as exr:
            rgba = exr.channels()["RGBA"].pixels
    image = np.asarray(rgba, dtype=np.float64)[::-1, :, :3]        # row 0 = bottom, as the cells
    mean = np.zeros(len(cells))
    spread = np.zeros(len(cells))
    for p, c in enumerate(cells):
        block = image[c["row"] * cell + 1:(c["row"] + 1) * cell - 1, c["col"] * cell + 1:(c["col"] + 1) * cell - 1]
        mean[p] = block.mean()
        spread[p] = block.max() - block.min()
    return mean, spread, wo, time.perf_counter() - started


def measure(points, cell: int, threads: int, seed: int = 0, log=print):
    """Render ``points`` [(mu, roughness), ...] under every sun direction.

    Returns (samples, checks): samples[p] = (wo (n, 3), radiance (n,), spread (n,))
    of point p, spread = largest difference between the pixels of a cell;
    checks: Lambert relative error, render seconds.
    """
    collected = [[] for _ in points]
    checks = dict(lambert_error=0.0, seconds=0.0, renders=0)
    for gamma_deg in GAMMAS_DEG:
        gamma = math.radians(gamma_deg)
        cells, ncols, nrows = layout(points, gamma)
        mean, spread, wo, took = render_cells(cells, ncols, nrows, gamma, cell, seed=seed, threads=threads)
        checks["seconds"] += took
        checks["renders"] += 1
        for p, c in enumerate(cells):
            if c["point"] < 0:
                expected = SUN_STRENGTH * wo[p, 2] / math.pi
                checks["lambert_error"] = max(checks["lambert_error"], abs(mean[p] / expected - 1.0))
                continue
            collected[c["point"]].append((wo[p], mean[p], spread[p]))
        log(f"  gamma {gamma_deg:5.1f} deg: {len(cells)} cells, {ncols * cell} x {nrows * cell} px, {took:.1f} s")
    samples = [tuple(np.array([cell[k] for cell in data]) for k in range(3)) for data in collected]
    return samples, checks


# ----------------------------------------------------------------------------- fitting


def fit_point(wo: np.ndarray, radiance: np.ndarray):
    """Least-squares (a, b, rho) of one measured point, on log radiance.

    Returns (params (3,), standard errors (3,), max relative residual).
    """
    from scipy.optimize import least_squares

    target = np.log(radiance / SUN_STRENGTH)
    a_grid = np.geomspace(1e-2, 1e2, 81)
    b_grid = np.linspace(-6.0, 6.0, 121)
    aa, bb = (g.reshape(-1) for g in np.meshgrid(a_grid, b_grid, indexing="ij"))
    some = np.linspace(0, len(target) - 1, min(len(target), 24)).astype(int)     # the grid on a subset
    model = np.log(sheen_eval(aa, bb, wo[None, some, :]))
    log_rho = (target[None, some] - model).mean(axis=1)
    best = int(np.argmin(((target[None, some] - model - log_rho[:, None]) ** 2).sum(axis=1)))
    x0 = np.array([aa[best], bb[best], log_rho[best]])

    def residual(x):
        return np.log(sheen_eval(x[0], x[1], wo)) + x[2] - target

    result = least_squares(residual, x0, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    a, b, log_rho = result.x
    dof = max(len(target) - 3, 1)
    covariance = np.linalg.pinv(result.jac.T @ result.jac) * (result.fun @ result.fun) / dof
    sigma = np.sqrt(np.diag(covariance))
    sigma[2] *= math.exp(log_rho)                          # d rho = rho d log rho
    if a < 0.0:                                            # (a, b) and (-a, -b) are the same lobe
        a, b = -a, -b
    return np.array([a, b, math.exp(log_rho)]), sigma, float(np.abs(np.expm1(result.fun)).max())


def point_state(radiance: np.ndarray, spread: np.ndarray) -> int:
    """1: every cell lit and uniform; 0: every cell black (closure dropped); -1: neither.

    The last happens where the interpolated rho is exactly 1e-5 (between
    nodes of 2e-5 and 0, or of 1e-5): float32 rounding of the lookup, which
    differs between the two triangles of a facet, decides whether Cycles
    keeps the closure.
    """
    if not np.any(radiance > 0.0) and not np.any(spread > 0.0):
        return 0
    if np.all(radiance > 0.0) and np.all(spread <= MAX_CELL_SPREAD * radiance):
        return 1
    return -1


def fit_points(samples):
    """Fit every point: params (n, 3), sigma (n, 3), residual (n,), state (n,) (see point_state)."""
    n = len(samples)
    params, sigma, residual = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n)
    state = np.array([point_state(radiance, spread) for _, radiance, spread in samples])
    for p in np.flatnonzero(state == 1):
        wo, radiance, _ = samples[p]
        if len(radiance) < 6:
            raise RuntimeError(f"point {p}: only {len(radiance)} light directions")
        params[p], sigma[p], residual[p] = fit_point(wo, radiance)
    return params, sigma, residual, state


def solve_nodes(points, params, sigma, state):
    """Node values from the fitted points: weighted least squares of the bilinear equations.

    Each lit point p gives, per parameter k, sum_n W[p, n] T_k[n] = params[p, k]
    (W: Cycles' bilinear weights), weighted by 1 / sigma[p, k] so that the few
    ill-conditioned points (tiny a, where b hardly changes the lobe) do not
    pull on their nodes.  Returns (table (3, 32, 32), known (32, 32): nodes
    that some lit point depends on with weight > 1e-6, max |misfit| per
    parameter relative to max(|value|, 1e-3)).
    """
    lit = state == 1
    weights = np.array([lookup_2d_weights(mu, r).reshape(-1) for mu, r in points])[lit]
    known = np.any(weights > 1e-6, axis=0)
    table = np.zeros((3, SIZE * SIZE))
    misfit = np.zeros(3)
    for k in range(3):
        scale = 1.0 / np.maximum(sigma[lit, k], 1e-9)
        solution, _, rank, _ = np.linalg.lstsq(weights[:, known] * scale[:, None], params[lit, k] * scale,
                                               rcond=None)
        if rank < known.sum():
            raise RuntimeError(f"node system rank {rank} < {known.sum()} unknowns")
        table[k, known] = solution
        misfit[k] = np.max(np.abs(weights[:, known] @ solution - params[lit, k])
                           / np.maximum(np.abs(params[lit, k]), 1e-3))
    return table.reshape(3, SIZE, SIZE), known.reshape(SIZE, SIZE), misfit


def refine_nodes(table: np.ndarray, known: np.ndarray, points, samples, state, max_evaluations: int = 50):
    """Fit the node values directly to every rendered pixel value (all points at once).

    The per-point fits leave a, b and rho individually ill-determined where a
    is tiny (there the lobe depends on rho a^2 alone), and such a point then
    pulls its nodes off.  This step minimises the relative difference between
    every measured cell and the value predicted from the nodes through
    Cycles' bilinear lookup (sparse trust-region least squares, analytic
    Jacobian), starting from ``table``.  Unknowns: the ``known`` nodes.
    """
    import scipy.sparse as sparse
    from scipy.optimize import least_squares

    columns = np.flatnonzero(known.reshape(-1))
    n = len(columns)
    lit_points = np.flatnonzero(state == 1)
    weights = sparse.csr_matrix(np.array([lookup_2d_weights(*points[p]).reshape(-1)[columns] for p in lit_points]))
    owner = np.concatenate([np.full(len(samples[p][1]), q) for q, p in enumerate(lit_points)])
    weights = weights[owner]                                # one row per rendered cell
    wo = np.concatenate([samples[p][0] for p in lit_points])
    measured = np.concatenate([samples[p][1] for p in lit_points])
    x, y, z = wo.T

    def model(v):
        a, b, rho = weights @ v[:n], weights @ v[n:2 * n], weights @ v[2 * n:]
        u = a * x + b * z
        length_sq = u * u + (a * y) ** 2 + z * z
        value = z * (a / length_sq) ** 2 / math.pi
        return a, b, rho, u, length_sq, value

    def residual(v):
        _, _, rho, _, _, value = model(v)
        return SUN_STRENGTH * rho * value / measured - 1.0

    def jacobian(v):
        a, b, rho, u, length_sq, value = model(v)
        scale = SUN_STRENGTH * value / measured
        d_a = scale * rho * (2.0 / a - 4.0 * (u * x + a * y * y) / length_sq)
        d_b = scale * rho * (-4.0 * u * z / length_sq)
        return sparse.hstack([weights.multiply(d[:, None]) for d in (d_a, d_b, scale)]).tocsr()

    start = np.concatenate([table[k].reshape(-1)[columns] for k in range(3)])
    result = least_squares(residual, start, jac=jacobian, method="trf", tr_solver="lsmr",
                           xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=max_evaluations)
    refined = np.zeros((3, SIZE * SIZE))
    for k in range(3):
        refined[k, columns] = result.x[k * n:(k + 1) * n]
    return refined.reshape(3, SIZE, SIZE), len(measured)


def prediction_errors(table: np.ndarray, points, samples, state):
    """Compare rendered cells with the table's prediction.

    Returns (relative errors of the cells of lit points that the table keeps,
    number of points whose dropped/lit state disagrees, number of points on
    the float32 knife edge: interpolated rho within 1e-10 of 1e-5, or cells
    that are neither all lit nor all black; there Cycles' float32 rounding
    decides).
    """
    errors, disagree, knife_edge = [], 0, 0
    for p, (mu, roughness) in enumerate(points):
        a, b, rho = lookup_table(table, mu, roughness)
        if abs(rho - MIN_RHO) < 1e-10 or state[p] < 0:
            knife_edge += 1
            continue
        if dropped(a, rho) == (state[p] == 1):
            disagree += 1
            continue
        if state[p] == 1:
            wo, measured, _ = samples[p]
            errors.append(np.abs(SUN_STRENGTH * rho * sheen_eval(a, b, wo) / measured - 1.0))
    return np.concatenate(errors), disagree, knife_edge


def edge_cells(table: np.ndarray):
    """Table cells (j, i) whose corners include dropped and kept nodes."""
    kept = ~((np.abs(table[0]) < MIN_A) | (table[2] < MIN_RHO))
    cells = []
    for j in range(SIZE - 1):
        for i in range(SIZE - 1):
            corners = kept[j:j + 2, i:i + 2]
            if corners.any() and not corners.all():
                cells.append((j, i))
    return cells


def predict(table: np.ndarray, mu: float, roughness: float, wo: np.ndarray) -> float:
    """Pixel value Cycles shows for one configuration, from the table."""
    a, b, rho = lookup_table(table, mu, roughness)
    return 0.0 if dropped(a, rho) else SUN_STRENGTH * rho * float(sheen_eval(a, b, wo))


def validate(table: np.ndarray, edge: list, cell: int, threads: int, count: int = 2000, seed: int = 1,
             gamma_deg: float = 60.0):
    """Render random off-node configurations (a quarter in ``edge`` cells) against the table.

    Returns (cells rendered, max relative error on lit cells, lit/dropped disagreements,
    cells on the float32 knife edge (see prediction_errors), seconds).
    """
    rng = np.random.default_rng(seed)
    gamma = math.radians(gamma_deg)
    light = np.array([math.sin(gamma), 0.0, math.cos(gamma)])
    mus = rng.uniform(0.004, 1.0, count)
    roughnesses = rng.uniform(0.0, 1.0, count)
    if edge:
        picked = rng.integers(0, len(edge), count // 4)
        j, i = np.array(edge)[picked].T
        roughnesses[:len(picked)] = (j + rng.uniform(0.0, 1.0, len(picked))) / 31
        mus[:len(picked)] = np.maximum(i + rng.uniform(0.0, 1.0, len(picked)), 0.1) / 31
    psis = rng.uniform(0.0, 2.0 * math.pi, count)
    ncols = 64
    cells = []
    for k in range(count):
        normal = facet_normal(mus[k], gamma, psis[k])
        if normal @ light >= MIN_COS_LIGHT:
            cells.append(dict(col=len(cells) % ncols, row=len(cells) // ncols, point=k,
                              roughness=float(roughnesses[k]), normal=normal))
    nrows = (len(cells) + ncols - 1) // ncols
    mean, spread, wo, took = render_cells(cells, ncols, nrows, gamma, cell, threads=threads)
    worst, disagree, knife_edge = 0.0, 0, 0
    for p, c in enumerate(cells):
        state = point_state(mean[p:p + 1], spread[p:p + 1])
        if state < 0 or abs(lookup_table(table, mus[c["point"]], c["roughness"])[2] - MIN_RHO) < 1e-10:
            knife_edge += 1
            continue
        predicted = predict(table, mus[c["point"]], c["roughness"], wo[p])
        if (predicted > 0.0) != (state == 1):
            disagree += 1
        elif predicted > 0.0:
            worst = max(worst, abs(mean[p] / predicted - 1.0))
    return len(cells), worst, disagree, knife_edge, took


# ----------------------------------------------------------------------------- driver


def oracles(table: np.ndarray) -> dict:
    """cycles-closures.md section 10: table values and two renders (1000 W point light 2 m away)."""
    out = {"table r .5 mu .2": lookup_table(table, 0.2, 0.5), "table r .5 mu 1": lookup_table(table, 1.0, 0.5)}
    for roughness in (0.5, 1.0):
        a, b, rho = lookup_table(table, 1.0, roughness)
        out[f"render r {roughness}"] = rho * float(sheen_eval(a, b, np.array([0.0, 0.0, 1.0]))) * 1000.0 / (
            4.0 * math.pi * 2.0 ** 2)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=TABLE_PATH, help="where to write the (3, 32, 32) table")
    parser.add_argument("--cell", type=int, default=5, help="cell size in pixels (>= 3)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--seed-check", action="store_true", help="render pass 1 twice, seeds 0 and 1")
    args = parser.parse_args(argv)
    started = time.perf_counter()
    seconds = {"render": 0.0}

    def run(points, seed=0):
        samples, checks = measure(points, args.cell, args.threads, seed=seed)
        seconds["render"] += checks["seconds"]
        print(f"  Lambert facets: max relative error {checks['lambert_error']:.2g}")
        return samples

    # Pass 1: the node grid, half-way points of the boundary cells, mu = 1 exactly (a check only).
    grid = [(mu, r) for r in ROUGHNESS_NODE_POINTS for mu in MU_NODE_POINTS]
    grid += [(0.5 / 31, r) for r in ROUGHNESS_NODE_POINTS] + [(mu, 0.5 / 31) for mu in MU_NODE_POINTS]
    check_mu1 = [(1.0, r) for r in ROUGHNESS_NODE_POINTS]
    print(f"pass 1: {len(grid)} points (node grid and boundary cells) and {len(check_mu1)} at mu = 1")
    samples = run(grid + check_mu1)
    if args.seed_check:
        print("pass 1 again with seed 1")
        again = run(grid + check_mu1, seed=1)
        differences = [np.abs(v2 - v1).max() / max(v1.max(), 1e-30) for (_, v1, _), (_, v2, _) in zip(samples, again)]
        print(f"  seeds 0 and 1: max relative difference {max(differences):.3g}")
    samples, check_samples = samples[:len(grid)], samples[len(grid):]
    params, sigma, residual, state = fit_points(samples)
    table, known, _ = solve_nodes(grid, params, sigma, state)
    edge = edge_cells(np.where(known, table, 0.0))
    print(f"  {np.sum(state == 0)} points black (closure dropped), {np.sum(state < 0)} on the knife edge; "
          f"{len(edge)} table cells on the edge of the dropped region")

    # Pass 2: points inside the cells at the edge of the dropped region.
    extra = [((i + s) / 31, max((j + t) / 31, MIN_ROUGHNESS)) for j, i in edge
             for t in EDGE_FRACTIONS for s in EDGE_FRACTIONS]
    print(f"pass 2: {len(extra)} points in the edge cells")
    extra_samples = run(extra)
    fitted = fit_points(extra_samples)
    points, samples = grid + extra, samples + extra_samples
    params, sigma, residual, state = (np.concatenate([u, v]) for u, v in zip((params, sigma, residual, state), fitted))
    lit = state == 1
    spread = max(np.max(samples[p][2] / samples[p][1]) for p in np.flatnonzero(lit))
    print(f"per-point fits: {lit.sum()} lit points ({sum(len(samples[p][1]) for p in np.flatnonzero(lit))} "
          f"cells, largest relative spread inside a cell {spread:.2g}), {np.sum(state == 0)} black, "
          f"{np.sum(state < 0)} on the knife edge; max relative residual {residual[lit].max():.2g}, "
          f"median {np.median(residual[lit]):.2g}")

    # Nodes: linear solve of the fitted points, then a direct fit to every cell, then 5 decimals.
    table, known, misfit = solve_nodes(points, params, sigma, state)
    print("  node equations: max misfit relative to max(|value|, 1e-3), a b rho:", np.array2string(misfit, precision=2))
    table, cells = refine_nodes(table, known, points, samples, state)
    errors, disagree, knife = prediction_errors(table, points, samples, state)
    print(f"global fit to {cells} cells ({3 * known.sum()} unknowns): max relative error {errors.max():.2g}, "
          f"median {np.median(errors):.2g}")
    steps = table * 1e5
    distance = np.abs(steps - np.round(steps))[:, known]
    print("  distance of the node values from multiples of 1e-5 (in steps), median / 99% / max, a b rho:",
          "; ".join(f"{np.median(d):.3f} / {np.quantile(d, 0.99):.3f} / {d.max():.3f}" for d in distance))
    table = np.round(table, 5)
    table[:, ~known] = 0.0
    errors, disagree, knife = prediction_errors(table, points, samples, state)
    print(f"rounded to 5 decimals: max relative error {errors.max():.2g}, median {np.median(errors):.2g}, "
          f"99.9% {np.quantile(errors, 0.999):.2g}; dropped/lit disagreements {disagree} "
          f"(+ {knife} points on the float32 knife edge at rho = 1e-5)")
    kept = ~((np.abs(table[0]) < MIN_A) | (table[2] < MIN_RHO))
    print(f"  nodes: {kept.sum()} kept, {(known & ~kept).sum()} dropped and measured (edge cells), "
          f"{(~known).sum()} never used (a = b = rho = 0); rho at the dropped measured nodes: "
          f"{np.unique(table[2][known & ~kept])}")

    check_state = np.array([point_state(v, d) for _, v, d in check_samples])
    errors, disagree, knife = prediction_errors(table, check_mu1, check_samples, check_state)
    print(f"mu = 1 exactly (fallback tangent frame), predicted: max relative error {errors.max():.2g}, "
          f"dropped/lit disagreements {disagree}")

    count, worst, disagree, knife, took = validate(table, edge, args.cell, args.threads)
    seconds["render"] += took
    print(f"validation: {count} random off-node configurations, max relative error {worst:.2g}, "
          f"dropped/lit disagreements {disagree}, on the knife edge {knife}")
    for name, value in oracles(table).items():
        print(f"  oracle {name}: {np.array2string(np.asarray(value), precision=6)}")

    args.out.parent.mkdir(parents=True, exist_ok=True)
    np.save(args.out, table)
    print(f"wrote {args.out} {table.shape}; total {time.perf_counter() - started:.0f} s, "
          f"of which rendering (scene building included) {seconds['render']:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
