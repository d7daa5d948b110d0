/* The scene's triangle meshes in Embree 3: one device per scene, one Embree scene per mesh (the
 * walks inside a mesh trace and query only that mesh), and a top-level scene that instances them
 * all for camera and shadow rays (instances share the meshes' BVHs, so the geometry is stored
 * once). Vertex and index buffers are shared with dwvg_mesh, not copied. */
#ifndef DWV_GEOM_EMBREE_H
#define DWV_GEOM_EMBREE_H

#include <math.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "clearance.h"
#include "mesh.h"
#include "util/vec3.h"

/* A closed convex mesh of few planes without vertex normals (a box), whose walk rays are traced
 * as exits from the intersection of its planes' half-spaces (dwvg_intersect_mesh). */
#define DWVG_POLYTOPE_PLANES 8u
#define DWVG_POLYTOPE_TRIANGLES 32u
typedef struct dwvg_polytope {
    uint32_t plane_count;                       /* 0: not one */
    double planes[DWVG_POLYTOPE_PLANES][4];     /* outward unit normal n (its triangles' geometric
                                                   normal, bit for bit) and offset: n.y <= d inside */
    uint32_t first[DWVG_POLYTOPE_PLANES + 1];   /* plane i's triangles: triangles[first[i] .. first[i+1]) */
    uint32_t triangles[DWVG_POLYTOPE_TRIANGLES];
} dwvg_polytope;

typedef struct dwvg_world {
    void *device;         /* RTCDevice */
    void *top;            /* RTCScene of instances, instance id = mesh index */
    void **mesh_scenes;   /* RTCScene per mesh */
    dwvg_clearance *clearance; /* per mesh: empty unless dwvg_world_build_clearance made it */
    const dwvg_mesh *meshes;
    uint32_t mesh_count;
    double epsilon;       /* ray offset: 2^-17 of the scene's largest coordinate (about 64 float
                             ulps there), so it scales with the scene and clears float rounding */
    uint64_t warnings;    /* zero-area or non-finite triangles (Embree skips them) */
    uint64_t triangles;
    int leaving_filter;   /* Embree runs context filters: mesh scenes take them */
    int *closed;          /* per mesh: dwvg_mesh_closed */
    dwvg_polytope *polytopes; /* per mesh (plane_count 0 where the mesh is not one) */
    /* Per mesh and triangle T: the largest n_T.v over every vertex v of the world, n_T the unit
     * geometric normal (+inf for a zero-area triangle); NULL where the world has more than
     * DWVG_TOPS_WORK vertices x triangles (see dwvg_world_top). */
    double **tops;
    atomic_llong embree_bytes; /* what Embree holds now (its memory monitor) */
    atomic_int embree_error;   /* the first Embree error code, 0 if none */
} dwvg_world;

typedef struct dwvg_hit {
    uint32_t mesh, prim;
    double t;
    double u, v; /* barycentrics of corners 1 and 2 */
} dwvg_hit;

/* Builds the device and scenes for `count` meshes (kept by pointer: they must outlive the world).
 * 0 on success; -1 with a message in `message` (Embree's error, or no memory). */
int dwvg_world_build(dwvg_world *world, const dwvg_mesh *meshes, uint32_t count, char *message, size_t size);
void dwvg_world_free(dwvg_world *world);

/* The first surface along unit d from o within (tnear, tfar): 1 and *hit, or 0. A world that is
 * one polytope (dwvg_polytope) is met by its planes, as dwvg_intersect_mesh's walk rays are. */
int dwvg_intersect(const dwvg_world *world, dwvu_vec3 o, dwvu_vec3 d, double tnear, double tfar, dwvg_hit *hit);
/* Whether anything blocks the segment (tnear, tfar) along d from o. */
int dwvg_occluded(const dwvg_world *world, dwvu_vec3 o, dwvu_vec3 d, double tnear, double tfar);
/* As dwvg_intersect, against one mesh only. A polytope (dwvg_polytope) is intersected by its
 * planes in double precision instead: from a point o inside, the ray leaves through the plane of
 * least t_i = (d_i - n_i.o) / (n_i.d) over those it rises along (n_i.d > 0), held at 0 or more
 * (an o a rounding outside a plane, moving out, leaves at once), and the hit is the triangle of
 * that plane whose barycentrics there are least negative. That is the exit Embree finds, to
 * float rounding (Embree's t is a float; these are exact to double rounding), and no ray is
 * traced: about a tenth of the instructions on a box. */
int dwvg_intersect_mesh(const dwvg_world *world, uint32_t mesh, dwvu_vec3 o, dwvu_vec3 d, double tnear,
                        double tfar, dwvg_hit *hit);
/* Whether every edge of the mesh's triangles is shared, by vertex index, with exactly one other
 * triangle that runs it the other way, and every triangle has area: a closed, consistently
 * oriented surface, which surrounds every point inside it (a ray from inside always meets it:
 * Embree's watertight test leaves no gap along a shared edge). Meshes whose vertices are split
 * (seams) count as open. 1 closed, 0 open, -1 out of memory. */
int dwvg_mesh_closed(const dwvg_mesh *mesh);

/* The first surface of `mesh` along unit d from o, o on triangle `prim`, past that triangle: what
 * dwvg_intersect_mesh over (0, tfar) gives when it is cast again from just past each hit on
 * `prim` (float rounding puts o a little above or below the triangle, so the first ray may meet
 * it). Done as one ray whose context filter rejects the hits on `prim`: the nearest other hit at
 * or beyond 0 is the loop's answer when it lies beyond prim's (the loop's later rays see the same
 * hits at the same distances) or before it (the loop's first ray returns it), and at equal
 * distances, where the loop's answer depends on Embree's order of traversal, the loop itself is
 * run. Adds the rays cast to *rays. */
int dwvg_intersect_mesh_leaving(const dwvg_world *world, uint32_t mesh, dwvu_vec3 o, dwvu_vec3 d, uint32_t prim,
                                double tfar, dwvg_hit *hit, uint32_t *rays);
/* The point of `mesh` closest to p (rtcPointQuery with our own point-triangle distance): 1 and
 * *hit (t = the distance), or 0 if the mesh has no valid triangle. */
int dwvg_closest_mesh(const dwvg_world *world, uint32_t mesh, dwvu_vec3 p, dwvg_hit *hit);
/* The same, with the distance from p to the nearest triangle a ray could hit (zero-area ones
 * included) in *clearance (0 if none found). */
int dwvg_closest_mesh_clearance(const dwvg_world *world, uint32_t mesh, dwvu_vec3 p, dwvg_hit *hit, double *clearance);
/* dwvg_closest_mesh_clearance within distance `within` (> 0) of p: the query visits only that
 * far. Returns 1 with the nearest triangle if one lies within it; else 0 with *clearance =
 * `within` (nothing a ray could hit is nearer: a lower bound), or less for a zero-area triangle
 * nearer, or 0 where p is outside Embree's range. */
int dwvg_closest_mesh_within(const dwvg_world *world, uint32_t mesh, dwvu_vec3 p, double within, dwvg_hit *hit,
                             double *clearance);
/* Builds the clearance grid of one mesh (clearance.h, dwvg_clearance_build) with cells of at least
 * `cell_size` and at most `largest_cell`: for the meshes whose walks may take ray-free steps. 0 on
 * success or where no grid is made (its lookups then give 0), -1 out of memory. */
int dwvg_world_build_clearance(dwvg_world *world, uint32_t mesh, double cell_size, double largest_cell);
/* The radius of a ball about `center` that no ray of dwvg_intersect_mesh can find a hit in, from
 * a lower bound on the distance to the mesh there (the clearance: dwvg_clearance_at, or a
 * closest point's distance): the clearance less a margin for float
 * rounding. Embree traces the ray rounded to float (origin, direction and tfar, each within half
 * an ulp) with a watertight test in float, and culls the point query in float: each errs by a
 * few ulps of the largest coordinate involved, the mesh's (world->epsilon = 2^-17 of it, about
 * 64 ulps) or the ball's (|center| + clearance). The margin is the sum of 2^-17 of each. 0 when
 * nothing is left. A segment with both ends inside the ball (convex) meets no surface of the
 * mesh: a ray along it is skipped. */
static inline double dwvg_clear_radius(const dwvg_world *world, dwvu_vec3 center, double clearance)
{
    /* Inline (a walk asks at most steps): the largest |coordinate| by comparisons, which equal
     * fmax's for numbers; a NaN anywhere gives 0. */
    double largest = fabs(center.x), ay = fabs(center.y), az = fabs(center.z);
    largest = ay > largest ? ay : largest;
    largest = (az > largest ? az : largest) + clearance;
    double margin = world->epsilon + 0x1p-17 * largest;
    double radius = clearance - margin;
    return radius > 0.0 && radius < INFINITY && !isnan(center.x + center.y + center.z) ? radius : 0.0;
}

/* At most this many vertex-triangle products for the tops table (dwvg_world_top): about a tenth
 * of a second at commit. */
#define DWVG_TOPS_WORK (1u << 24)
/* The highest any point of the world reaches along the unit geometric normal n_T of triangle
 * `prim` of `mesh`: max n_T.y over the world's points y (its vertices; every point of a triangle is
 * a mix of its corners), +inf where unknown. A ray from an origin o with n_T.o above that, rising
 * along n_T, meets nothing: it only moves away from the world's half-space n_T.y <= top. */
static inline double dwvg_world_top(const dwvg_world *world, uint32_t mesh, uint32_t prim)
{
    return world->tops ? world->tops[mesh][prim] : INFINITY;
}

/* The unit outward geometric normal of a triangle, (v1 - v0) x (v2 - v0) normalised (zero for a
 * degenerate one). */
dwvu_vec3 dwvg_geometric_normal(const dwvg_mesh *mesh, uint32_t prim);
/* The interpolated vertex normal at barycentrics (u, v), turned to the side of `geometric`; the
 * geometric normal where the mesh has none or they cancel. */
dwvu_vec3 dwvg_shading_normal(const dwvg_mesh *mesh, uint32_t prim, double u, double v, dwvu_vec3 geometric);
dwvu_vec3 dwvg_point(const dwvg_mesh *mesh, uint32_t prim, double u, double v);
/* A triangle's area (0 for degenerate or non-finite ones). */
double dwvg_triangle_area(const dwvg_mesh *mesh, uint32_t prim);

#endif
