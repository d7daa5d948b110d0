/* The shadow terminator of smooth-shaded triangles, as Cycles (3.x, light/sample.h) treats it.
 *
 * A smooth-shaded low-poly mesh is lit by its interpolated normal but shadowed by its flat
 * triangles: near the terminator a shadow ray leaving the flat triangle toward a light that the
 * shading normal still faces grazes (or enters) the neighbouring facets, and the facets show as
 * dark steps. Cycles moves the origin of such shadow rays up onto a smooth surface that the
 * vertex normals describe (Blender's object setting "Shadow Terminator > Geometry Offset",
 * 0.1 by default, dwv_mesh_t.shadow_terminator_geometry_offset; the idea is Hanika 2021, "Hacking the Shadow Terminator", Ray Tracing Gems II
 * ch. 4, with Cycles' own surface: a parabola capped by the vertices' tangent planes). This
 * module computes that lift (dwvl_terminator_lift) and how much of it one shadow ray takes
 * (dwvl_terminator_amount); src/light/direct.c applies them to each shadow ray's origin.
 *
 * It changes which points are shadowed, not any estimator: the shadow ray still tests the
 * visibility of the light sample it was made for. */
#ifndef DWV_LIGHT_TERMINATOR_H
#define DWV_LIGHT_TERMINATOR_H

#include <stdint.h>

#include "geom/mesh.h"
#include "util/vec3.h"

/* Where a shading point's shadow rays find their lift (dwvl_terminator_lift_at, computed only for
 * the rays that take some of it: most points are far from the terminator) and the cutoff. */
typedef struct dwvl_terminator {
    const dwvg_mesh *mesh; /* with vertex normals */
    uint32_t prim;         /* the point's triangle */
    double u, v;           /* the point's barycentrics on it (Embree's) */
    double cutoff;         /* the geometry offset: cosines below it take (part of) the lift; 0: none */
    /* The smooth normal there (dwvg_shading_normal on the shaded side; Cycles' sd->N), which
     * decides the lift whatever normal a normal map or bump gave the lobes (shadow_ray_offset). */
    dwvu_vec3 n;
} dwvl_terminator;

/* The lift at the point with barycentric weights b[0..2] of the triangle with corners v[0..2] and
 * vertex normals n[0..2] (world space, unit), `ng` the unit geometric normal on the side being
 * shaded. With the normals turned to ng's side (s = sign of (sum b_i n_i) . ng, N_i = s n_i) and
 * P = sum b_i v_i, Cycles' surface height above P is
 *   h = max(min_i e_i, h_q),
 *   h_q = 1/2 sum_{i<j} b_i b_j (N_j - N_i).(v_j - v_i)   (the parabola whose slopes at both ends
 *         of each edge average the slopes the two tangent planes give the edge),
 *   e_i = max(0, (v_i - P).N_i + max(0, max_{j != i} (v_j - v_i).N_i))   (the height of corner
 *         i's tangent plane above P, raised by as much as the triangle rises above that plane),
 * h >= 0, and the lift is h sum_i b_i N_i (the interpolated normal, not normalised, as Cycles with
 * the object transform applied). A flat triangle (equal normals) has h = 0; every corner's lift
 * is 0. Returns zero when a vertex normal is zero (no smooth normal there). */
dwvu_vec3 dwvl_terminator_lift(const dwvu_vec3 v[3], const dwvu_vec3 n[3], const double b[3], dwvu_vec3 ng);

/* dwvl_terminator_lift at the point (u, v) of triangle `prim` (Embree's barycentrics: weights
 * 1 - u - v, u, v on the triangle's corners in stored order), from the mesh's positions and
 * vertex normals; `ng` as above. Zero for a mesh without vertex normals (flat shading). */
dwvu_vec3 dwvl_terminator_lift_at(const dwvg_mesh *mesh, uint32_t prim, double u, double v, dwvu_vec3 ng);

/* The share of the lift a shadow ray toward unit direction L takes, with cos_n = N.L >= 0 (the
 * smooth normal, dwvl_terminator.n, on the side it faces L from) and cos_g = Ng.L (the geometric
 * normal on that same side), after Cycles:
 *   cos_n < cutoff:  clamp(2 - (cos_g + cos_n) / cutoff, 0, 1)
 *   otherwise:       clamp(1 - cos_g / cutoff, 0, 1)
 * (continuous at cos_n = cutoff): 1 at grazing light, 0 once the flat triangle faces the light
 * by more than the cutoff. 0 when cutoff <= 0. */
double dwvl_terminator_amount(double cos_n, double cos_g, double cutoff);

#endif
