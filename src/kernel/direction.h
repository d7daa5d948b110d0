/* Directions about a frame from a sampled cosine and azimuth (the kernel's single-precision
 * unit-circle points): what every technique's direction sampler ends in. */
#ifndef DWV_KERNEL_DIRECTION_H
#define DWV_KERNEL_DIRECTION_H

#include <math.h>

#include "kernel/fastmath.h"
#include "util/vec3.h"

/* The direction with cosine mu to the frame's axis, sine sin_theta (from 1 -+ mu without
 * cancellation) and azimuth `azimuth` (a point of the unit circle, dwvk_azimuth_f). The
 * single-precision inputs leave it unit only to |l^2 - 1| <= ~1e-6; hosts and the analytic shapes
 * rely on unit directions, so it is rescaled in double by one Newton step for 1/sqrt(l^2) from 1,
 * (3 - l^2)/2, which leaves |l - 1| <= (3/8)(l^2 - 1)^2 ~ 4e-13: no square root or division. */
static inline dwvu_vec3 dwvk_frame_direction(const dwvu_frame *f, double mu, double sin_theta, dwvk_unit2_f azimuth)
{
    double c = (double)azimuth.c * sin_theta, d = (double)azimuth.s * sin_theta;
    dwvu_vec3 w = dwvu_v(f->t.x * c + f->s.x * d + f->n.x * mu, f->t.y * c + f->s.y * d + f->n.y * mu,
                         f->t.z * c + f->s.z * d + f->n.z * mu);
    return dwvu_scale(w, 1.5 - 0.5 * dwvu_dot(w, w));
}

/* The direction with cosine mu to the unit axis n and azimuth from u in [0, 1] (dwvk_azimuth_f). */
static inline dwvu_vec3 dwvk_direction_about(dwvu_vec3 n, double mu, double one_minus_mu, double one_plus_mu,
                                             double u)
{
    dwvu_frame f = dwvu_frame_about(n);
    return dwvk_frame_direction(&f, mu, sqrt(fmax(0.0, one_minus_mu * one_plus_mu)), dwvk_azimuth_f((float)u));
}

#endif
