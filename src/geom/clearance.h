/* A conservative distance field of one mesh on a regular grid, for ray-free walk steps: at any
 * point it gives a lower bound on the distance to the mesh's triangles (all of them that a ray
 * could hit, zero-area ones included), so that a walk step shorter than the bound cannot meet the
 * surface and needs no ray (src/bake/shade.c run_walk).
 *
 * Construction: a cell is marked where it may hold a surface point: its centre lies within half a
 * cell diagonal h sqrt(3)/2 of a triangle (exact distances from the centres near the surface),
 * or, where computing those would take too long, a triangle's bounding box touches it. An exact
 * Euclidean distance transform (Felzenszwalb and Huttenlocher 2012, squared distances by lower
 * envelopes of parabolas, one axis at a time) gives each cell centre c its distance D(c) to the
 * nearest marked cell centre. For a point x, any cell centre c and a surface point y in marked
 * cell M, the triangle inequality gives
 *     |x - y| >= |c - c_M| - |x - c| - |y - c_M| >= D(c) - h sqrt(3)/2 - |x - c|,
 * and likewise |x - y| >= d(c) - |x - c| with d(c) the centre's exact distance where it is known.
 * The table keeps the larger bound at each centre (rounded down to float); a lookup subtracts
 * |x - c| for the centre of x's cell. A lookup is a few dozen instructions, against some 500 for an
 * Embree ray and some 6000 for an Embree closest-point query on the report's sphere. */
#ifndef DWV_GEOM_CLEARANCE_H
#define DWV_GEOM_CLEARANCE_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "util/vec3.h"

/* At most this many cells per mesh (4 bytes each: 1 MiB). */
#define DWVG_CLEARANCE_MAX_CELLS (1u << 18)
/* A mesh whose triangles lie in at most this many planes gets the planes instead of a grid: the
 * distance from a point p to a triangle is at least that to the triangle's plane, |n.p - d|, so
 * the least over the planes is a lower bound for any mesh, and for a convex one (a box: 6
 * planes) it is the distance itself: no cell to lose, and no grid too coarse for a thin box (the
 * leaf). A lookup costs about what a grid's does. */
#define DWVG_CLEARANCE_MAX_PLANES 8u

typedef struct dwvg_clearance {
    float *lower;      /* per cell (x fastest): the bound at the cell centre; <= 0 where marked */
    double origin[3];  /* the grid's lowest corner */
    double cell;       /* the cell size h */
    uint32_t n[3];     /* cells per axis */
    double inverse_cell, cells[3]; /* 1 / cell and n as doubles, for lookups */
    double largest;    /* no lookup gives more: the largest bound of any cell; +inf with planes; 0 if
                          neither */
    uint32_t plane_count;                          /* 0: none (the grid, if any, is used) */
    double planes[DWVG_CLEARANCE_MAX_PLANES][4];   /* unit normal n and offset d: n.p = d on it */
} dwvg_clearance;

/* Keeps the planes of `mesh` where it has at most DWVG_CLEARANCE_MAX_PLANES (triangles in the
 * same plane share one) and no triangle of zero area or with a non-finite corner (returns 0);
 * else builds the grid with cells of at least `cell_size` (finite, > 0), coarser where
 * DWVG_CLEARANCE_MAX_CELLS would be exceeded. 0 on success, 1 when no grid is made (no finite
 * triangle; cells would have to be larger than `largest_cell`; or the marking would take more than
 * 64 cell visits per cell): *grid is then empty and every lookup returns 0. -1 out of memory. */
int dwvg_clearance_build(dwvg_clearance *grid, const dwvg_mesh *mesh, double cell_size, double largest_cell);
void dwvg_clearance_free(dwvg_clearance *grid);

/* The barycentrics (u, v) of the point of triangle abc closest to p (Ericson, Real-Time Collision
 * Detection, Sec. 5.1.5). */
void dwvg_closest_on_triangle(dwvu_vec3 p, dwvu_vec3 a, dwvu_vec3 b, dwvu_vec3 c, double *u, double *v);
/* The distance from p to triangle abc; to its edges where it has zero area (a ray may still graze
 * it). */
double dwvg_triangle_distance(dwvu_vec3 p, dwvu_vec3 a, dwvu_vec3 b, dwvu_vec3 c);

static inline dwvu_vec3 dwvg_clearance_centre(const dwvg_clearance *grid, uint32_t ix, uint32_t iy, uint32_t iz)
{
    return dwvu_v(grid->origin[0] + (ix + 0.5) * grid->cell, grid->origin[1] + (iy + 0.5) * grid->cell,
                  grid->origin[2] + (iz + 0.5) * grid->cell);
}

/* A lower bound on the distance from p to the mesh where it exceeds `floor` (>= 0), else 0: 0 also
 * where none is known (outside the grid, or near the surface; or p not finite). A walk asks with
 * its step's length as the floor (a bound no longer than the step cannot spare the ray), which
 * lets the planes stop at the first one that close (they are kept largest first: the nearest,
 * in a thin box). */
static inline double dwvg_clearance_above(const dwvg_clearance *grid, dwvu_vec3 p, double floor)
{
    if (grid->plane_count) {
        double bound = INFINITY;
        for (uint32_t i = 0; i < grid->plane_count; ++i) {
            const double *q = grid->planes[i];
            double d = fabs(q[0] * p.x + q[1] * p.y + q[2] * p.z - q[3]);
            if (!(d > floor)) return 0.0; /* a NaN p stops here */
            bound = d < bound ? d : bound;
        }
        return bound < INFINITY ? bound : 0.0; /* an infinite p leaves it infinite */
    }
    if (!grid->lower) return 0.0;
    double inverse = grid->inverse_cell;
    double fx = (p.x - grid->origin[0]) * inverse, fy = (p.y - grid->origin[1]) * inverse,
           fz = (p.z - grid->origin[2]) * inverse;
    /* The negated tests also send NaN to 0. */
    if (!(fx >= 0.0 && fy >= 0.0 && fz >= 0.0 && fx < grid->cells[0] && fy < grid->cells[1] && fz < grid->cells[2]))
        return 0.0;
    uint32_t ix = (uint32_t)fx, iy = (uint32_t)fy, iz = (uint32_t)fz;
    double bound = grid->lower[((size_t)iz * grid->n[1] + iy) * grid->n[0] + ix];
    if (!(bound > floor)) return 0.0;
    bound -= dwvu_length(dwvu_sub(p, dwvg_clearance_centre(grid, ix, iy, iz)));
    return bound > floor ? bound : 0.0;
}

/* A lower bound on the distance from p to the mesh (0 where none is known). */
static inline double dwvg_clearance_at(const dwvg_clearance *grid, dwvu_vec3 p)
{
    return dwvg_clearance_above(grid, p, 0.0);
}

#endif
