/* The surfaces that bound a walk's medium, behind one small interface: where a ray from inside
 * leaves, and the closest surface point. Analytic shapes here; triangle meshes plug in later. */
#ifndef DWV_WALK_GEOMETRY_H
#define DWV_WALK_GEOMETRY_H

#include "vec3.h"

typedef enum dwvw_shape_kind { DWVW_HALFSPACE = 0, DWVW_SLAB = 1, DWVW_SPHERE = 2 } dwvw_shape_kind;

/* The medium: half-space z >= 0; slab 0 <= z <= thickness; sphere of `radius` about (0, 0, radius).
 * All three have the point of entry at the origin with outward normal (0, 0, -1). */
typedef struct dwvw_shape {
    dwvw_shape_kind kind;
    double thickness;
    double radius;
} dwvw_shape;

/* The distance along unit d from p (inside) to the surface, +INFINITY if none, and the outward
 * normal there. */
double dwvw_shape_exit(const dwvw_shape *shape, dwvw_vec3 p, dwvw_vec3 d, dwvw_vec3 *normal);
/* The outward normal at the surface point closest to p, and the distance to it. */
double dwvw_shape_closest(const dwvw_shape *shape, dwvw_vec3 p, dwvw_vec3 *normal);

#endif
