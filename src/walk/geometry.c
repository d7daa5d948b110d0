#include "geometry.h"

static const dwvw_vec3 FRONT_NORMAL = {0.0, 0.0, -1.0};
static const dwvw_vec3 BACK_NORMAL = {0.0, 0.0, 1.0};

double dwvw_shape_exit(const dwvw_shape *shape, dwvw_vec3 p, dwvw_vec3 d, dwvw_vec3 *normal)
{
    switch (shape->kind) {
    case DWVW_HALFSPACE:
        *normal = FRONT_NORMAL;
        return d.z < 0.0 ? fmax(p.z, 0.0) / -d.z : INFINITY;
    case DWVW_SLAB:
        if (d.z < 0.0) {
            *normal = FRONT_NORMAL;
            return fmax(p.z, 0.0) / -d.z;
        }
        *normal = BACK_NORMAL;
        return d.z > 0.0 ? fmax(shape->thickness - p.z, 0.0) / d.z : INFINITY;
    case DWVW_SPHERE: {
        /* |q + t d|^2 = R^2 with q = p - centre: t = -b + sqrt(b^2 - c), c = |q|^2 - R^2 <= 0; for
         * b > 0 the equivalent -c / (b + sqrt(b^2 - c)) avoids cancellation. */
        double R = shape->radius;
        dwvw_vec3 q = dwvw_v(p.x, p.y, p.z - R);
        double b = dwvw_dot(q, d);
        double c = fmin((dwvw_length(q) - R) * (dwvw_length(q) + R), 0.0);
        double root = sqrt(b * b - c);
        double t = b > 0.0 ? -c / (b + root) : root - b;
        *normal = dwvw_normalize(dwvw_madd(q, d, t));
        return t;
    }
    }
    return INFINITY;
}

double dwvw_shape_closest(const dwvw_shape *shape, dwvw_vec3 p, dwvw_vec3 *normal)
{
    switch (shape->kind) {
    case DWVW_HALFSPACE:
        *normal = FRONT_NORMAL;
        return fmax(p.z, 0.0);
    case DWVW_SLAB:
        if (p.z <= 0.5 * shape->thickness) {
            *normal = FRONT_NORMAL;
            return fmax(p.z, 0.0);
        }
        *normal = BACK_NORMAL;
        return fmax(shape->thickness - p.z, 0.0);
    case DWVW_SPHERE: {
        dwvw_vec3 q = dwvw_v(p.x, p.y, p.z - shape->radius);
        double r = dwvw_length(q);
        *normal = r > 0.0 ? dwvw_scale(q, 1.0 / r) : FRONT_NORMAL; /* any direction at the centre */
        return fmax(shape->radius - r, 0.0);
    }
    }
    return 0.0;
}
