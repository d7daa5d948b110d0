#include "terminator.h"

#include <math.h>
#include <stddef.h>

dwvu_vec3 dwvl_terminator_lift(const dwvu_vec3 v[3], const dwvu_vec3 n[3], const double b[3], dwvu_vec3 ng)
{
    for (int i = 0; i < 3; ++i)
        if (n[i].x == 0.0 && n[i].y == 0.0 && n[i].z == 0.0) return dwvu_v(0.0, 0.0, 0.0);
    dwvu_vec3 interpolated = dwvu_v(0.0, 0.0, 0.0), p = dwvu_v(0.0, 0.0, 0.0);
    for (int i = 0; i < 3; ++i) {
        interpolated = dwvu_madd(interpolated, n[i], b[i]);
        p = dwvu_madd(p, v[i], b[i]);
    }
    /* Cycles turns the surface with the side it shades (its branch on n.Ng): the normals are used
     * as seen from ng's side, so that the lift is outward on either side of a two-sided face. */
    double side = dwvu_dot(interpolated, ng) < 0.0 ? -1.0 : 1.0;
    dwvu_vec3 normal[3];
    for (int i = 0; i < 3; ++i) normal[i] = dwvu_scale(n[i], side);
    double parabola = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j)
            parabola += b[i] * b[j] * dwvu_dot(dwvu_sub(normal[j], normal[i]), dwvu_sub(v[j], v[i]));
    parabola *= 0.5;
    double envelope = INFINITY;
    for (int i = 0; i < 3; ++i) {
        double rise = 0.0;
        for (int j = 0; j < 3; ++j)
            if (j != i) rise = fmax(rise, dwvu_dot(dwvu_sub(v[j], v[i]), normal[i]));
        double plane = fmax(dwvu_dot(dwvu_sub(v[i], p), normal[i]) + rise, 0.0);
        envelope = fmin(envelope, plane);
    }
    double height = fmax(envelope, parabola);
    return dwvu_scale(interpolated, side * height);
}

dwvu_vec3 dwvl_terminator_lift_at(const dwvg_mesh *mesh, uint32_t prim, double u, double v, dwvu_vec3 ng)
{
    if (!mesh->normals) return dwvu_v(0.0, 0.0, 0.0);
    const uint32_t *index = mesh->indices + 3u * (size_t)prim;
    dwvu_vec3 corner[3], normal[3];
    for (int k = 0; k < 3; ++k) {
        const float *x = mesh->positions + 3u * (size_t)index[k], *m = mesh->normals + 3u * (size_t)index[k];
        corner[k] = dwvu_v(x[0], x[1], x[2]);
        normal[k] = dwvu_v(m[0], m[1], m[2]);
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
