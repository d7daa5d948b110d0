#include "geometry.h"

double dwvw_shape_exit(const dwvw_shape *shape, dwvu_vec3 p, dwvu_vec3 d, dwvu_vec3 *normal)
{
    return dwvw_shape_exit_inline(shape, shape->kind, p, d, normal);
}

double dwvw_shape_closest(const dwvw_shape *shape, dwvu_vec3 p, dwvu_vec3 *normal)
{
    switch (shape->kind) {
    case DWVW_HALFSPACE:
        *normal = DWVW_FRONT_NORMAL;
        return dwvw_positive_part(p.z);
    case DWVW_SLAB:
        if (p.z <= 0.5 * shape->thickness) {
            *normal = DWVW_FRONT_NORMAL;
            return dwvw_positive_part(p.z);
        }
        *normal = DWVW_BACK_NORMAL;
        return dwvw_positive_part(shape->thickness - p.z);
    case DWVW_SPHERE: {
        dwvu_vec3 q = dwvu_v(p.x, p.y, p.z - shape->radius);
        double r = dwvu_length(q);
        *normal = r > 0.0 ? dwvu_scale(q, 1.0 / r) : DWVW_FRONT_NORMAL; /* any direction at the centre */
        return dwvw_positive_part(shape->radius - r);
    }
    }
    return 0.0;
}
