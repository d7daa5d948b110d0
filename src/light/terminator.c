#include "terminator.h"

#include <math.h>
#include <stddef.h>

dwvw_vec3 dwvl_terminator_lift(const dwvw_vec3 v[3], const dwvw_vec3 n[3], const double b[3], dwvw_vec3 ng)
{
    for (int i = 0; i < 3; ++i)
        if (n[i].x == 0.0 && n[i].y == 0.0 && n[i].z == 0.0) return dwvw_v(0.0, 0.0, 0.0);
    dwvw_vec3 interpolated = dwvw_v(0.0, 0.0, 0.0), p = dwvw_v(0.0, 0.0, 0.0);
    for (int i = 0; i < 3; ++i) {
        interpolated = dwvw_madd(interpolated, n[i], b[i]);
        p = dwvw_madd(p, v[i], b[i]);
    }
    /* Cycles turns the surface with the side it shades (its branch on n.Ng): the normals are used
     * as seen from ng's side, so that the lift is outward on either side of a two-sided face. */
    double side = dwvw_dot(interpolated, ng) < 0.0 ? -1.0 : 1.0;
    dwvw_vec3 normal[3];
    for (int i = 0; i < 3; ++i) normal[i] = dwvw_scale(n[i], side);
    double parabola = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j)
            parabola += b[i] * b[j] * dwvw_dot(dwvw_sub(normal[j], normal[i]), dwvw_sub(v[j], v[i]));
    parabola *= 0.5;
    double envelope = INFINITY;
    for (int i = 0; i < 3; ++i) {
        double rise = 0.0;
        for (int j = 0; j < 3; ++j)
            if (j != i) rise = fmax(rise, dwvw_dot(dwvw_sub(v[j], v[i]), normal[i]));
        double plane = fmax(dwvw_dot(dwvw_sub(v[i], p), normal[i]) + rise, 0.0);
        envelope = fmin(envelope, plane);
    }
    double height = fmax(envelope, parabola);
    return dwvw_scale(interpolated, side * height);
}

dwvw_vec3 dwvl_terminator_lift_at(const dwvg_mesh *mesh, uint32_t prim, double u, double v, dwvw_vec3 ng)
{
    if (!mesh->normals) return dwvw_v(0.0, 0.0, 0.0);
    const uint32_t *index = mesh->indices + 3u * (size_t)prim;
    dwvw_vec3 corner[3], normal[3];
    for (int k = 0; k < 3; ++k) {
        const float *x = mesh->positions + 3u * (size_t)index[k], *m = mesh->normals + 3u * (size_t)index[k];
        corner[k] = dwvw_v(x[0], x[1], x[2]);
        normal[k] = dwvw_v(m[0], m[1], m[2]);
    }
    const double weight[3] = {1.0 - u - v, u, v};
    return dwvl_terminator_lift(corner, normal, weight, ng);
}

double dwvl_terminator_amount(double cos_n, double cos_g, double cutoff)
{
    if (!(cutoff > 0.0)) return 0.0;
    double amount = cos_n < cutoff ? 2.0 - (cos_g + cos_n) / cutoff : 1.0 - cos_g / cutoff;
    return fmin(fmax(amount, 0.0), 1.0);
}
