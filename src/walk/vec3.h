/* Small 3-vector helpers for the walk (double precision). */
#ifndef DWV_WALK_VEC3_H
#define DWV_WALK_VEC3_H

#include <math.h>

typedef struct dwvw_vec3 { double x, y, z; } dwvw_vec3;

static inline dwvw_vec3 dwvw_v(double x, double y, double z) { dwvw_vec3 r = {x, y, z}; return r; }
static inline dwvw_vec3 dwvw_add(dwvw_vec3 a, dwvw_vec3 b) { return dwvw_v(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline dwvw_vec3 dwvw_sub(dwvw_vec3 a, dwvw_vec3 b) { return dwvw_v(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline dwvw_vec3 dwvw_scale(dwvw_vec3 a, double s) { return dwvw_v(a.x * s, a.y * s, a.z * s); }
static inline dwvw_vec3 dwvw_madd(dwvw_vec3 a, dwvw_vec3 d, double t) { return dwvw_v(a.x + d.x * t, a.y + d.y * t, a.z + d.z * t); }
static inline double dwvw_dot(dwvw_vec3 a, dwvw_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline double dwvw_length(dwvw_vec3 a) { return sqrt(dwvw_dot(a, a)); }
static inline dwvw_vec3 dwvw_normalize(dwvw_vec3 a) { return dwvw_scale(a, 1.0 / dwvw_length(a)); }

/* The direction with cosine mu (and sine from 1 -+ mu without cancellation) to the unit axis n
 * and azimuth 2 pi u, in the branchless orthonormal basis of Duff et al. 2017. */
static inline dwvw_vec3 dwvw_direction_about(dwvw_vec3 n, double mu, double one_minus_mu,
                                             double one_plus_mu, double u)
{
    double sign = copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z);
    double b = n.x * n.y * a;
    dwvw_vec3 t = dwvw_v(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    dwvw_vec3 s = dwvw_v(b, sign + n.y * n.y * a, -n.y);
    double sin_theta = sqrt(fmax(0.0, one_minus_mu * one_plus_mu));
    float phi = 6.2831853f * (float)u; /* single precision: the per-event path */
    double c = cosf(phi) * sin_theta, d = sinf(phi) * sin_theta;
    /* Renormalised in double: the single-precision inputs leave it unit only to ~2e-7, and hosts
     * and the analytic shapes rely on unit directions. */
    return dwvw_normalize(dwvw_v(t.x * c + s.x * d + n.x * mu, t.y * c + s.y * d + n.y * mu, t.z * c + s.z * d + n.z * mu));
}

#endif
