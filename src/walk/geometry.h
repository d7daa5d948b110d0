/* The surfaces that bound a walk's medium, behind one small interface: where a ray from inside
 * leaves, and the closest surface point. Analytic shapes here; triangle meshes plug in later. */
#ifndef DWV_WALK_GEOMETRY_H
#define DWV_WALK_GEOMETRY_H

#include <dwivedi.h>

#include "util/vec3.h"

typedef enum dwvw_shape_kind { DWVW_HALFSPACE = 0, DWVW_SLAB = 1, DWVW_SPHERE = 2 } dwvw_shape_kind;
/* The API passes DWV_SHAPE_* values through as dwvw_shape_kind: the same numbers. */
_Static_assert((int)DWVW_HALFSPACE == DWV_SHAPE_HALFSPACE && (int)DWVW_SLAB == DWV_SHAPE_SLAB &&
                   (int)DWVW_SPHERE == DWV_SHAPE_SPHERE,
               "dwvw_shape_kind must equal the DWV_SHAPE_* values (capi/dwivedi.h)");

/* The medium: half-space z >= 0; slab 0 <= z <= thickness; sphere of `radius` about (0, 0, radius).
 * All three have the point of entry at the origin with outward normal (0, 0, -1). */
typedef struct dwvw_shape {
    dwvw_shape_kind kind;
    double thickness;
    double radius;
} dwvw_shape;

/* The distance along unit d from p (inside) to the surface, +INFINITY if none, and the outward
 * normal there. */
double dwvw_shape_exit(const dwvw_shape *shape, dwvu_vec3 p, dwvu_vec3 d, dwvu_vec3 *normal);
static const dwvu_vec3 DWVW_FRONT_NORMAL = {0.0, 0.0, -1.0};
static const dwvu_vec3 DWVW_BACK_NORMAL = {0.0, 0.0, 1.0};

/* max(x, 0) inline (libm's fmax is an out-of-line call, and this is on the per-event path). */
static inline double dwvw_positive_part(double x)
{
    return x > 0.0 ? x : 0.0;
}

/* The distance along a direction of z component wz < 0 from height pz to the front plane z = 0,
 * and along wz > 0 to the back plane z = thickness (0 from a point already past it). */
static inline double dwvw_front_plane_distance(double pz, double wz)
{
    return dwvw_positive_part(pz) / -wz;
}

static inline double dwvw_back_plane_distance(double thickness, double pz, double wz)
{
    return dwvw_positive_part(thickness - pz) / wz;
}

/* dwvw_shape_exit inline, with the kind given apart so that a caller that knows it at compile
 * time gets one case (the estimator's fast path, per event). */
static inline double dwvw_shape_exit_inline(const dwvw_shape *shape, dwvw_shape_kind kind, dwvu_vec3 p, dwvu_vec3 d,
                                            dwvu_vec3 *normal)
{
    switch (kind) {
    case DWVW_HALFSPACE:
        *normal = DWVW_FRONT_NORMAL;
        return d.z < 0.0 ? dwvw_front_plane_distance(p.z, d.z) : INFINITY;
    case DWVW_SLAB:
        if (d.z < 0.0) {
            *normal = DWVW_FRONT_NORMAL;
            return dwvw_front_plane_distance(p.z, d.z);
        }
        *normal = DWVW_BACK_NORMAL;
        return d.z > 0.0 ? dwvw_back_plane_distance(shape->thickness, p.z, d.z) : INFINITY;
    case DWVW_SPHERE: {
        /* |q + t d|^2 = R^2 with q = p - centre: t = -b + sqrt(b^2 - c), c = |q|^2 - R^2 <= 0; for
         * b > 0 the equivalent -c / (b + sqrt(b^2 - c)) avoids cancellation. */
        double R = shape->radius;
        dwvu_vec3 q = dwvu_v(p.x, p.y, p.z - R);
        double b = dwvu_dot(q, d);
        double c = (dwvu_length(q) - R) * (dwvu_length(q) + R);
        c = c < 0.0 ? c : 0.0;
        double root = sqrt(b * b - c);
        double t = b > 0.0 ? -c / (b + root) : root - b;
        *normal = dwvu_normalize(dwvu_madd(q, d, t));
        return t;
    }
    }
    return INFINITY;
}

/* The outward normal at the surface point closest to p, and the distance to it. */
double dwvw_shape_closest(const dwvw_shape *shape, dwvu_vec3 p, dwvu_vec3 *normal);

#endif
