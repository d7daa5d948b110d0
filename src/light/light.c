#include "light.h"

#include "kernel/direction.h"

#include <math.h>

#define PI 3.14159265358979323846
#define INV_FOUR_PI 0.07957747154594766788

/* An orthonormal basis (t, s) about unit n (Duff et al. 2017). */
static void basis(dwvu_vec3 n, dwvu_vec3 *t, dwvu_vec3 *s)
{
    double sign = copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z);
    double b = n.x * n.y * a;
    *t = dwvu_v(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    *s = dwvu_v(b, sign + n.y * n.y * a, -n.y);
}

void dwvl_light_init(dwvl_light *light, const dwv_light_desc_t *desc)
{
    const double *m = desc->transform;
    light->kind = desc->kind;
    light->radius = 0.0;
    light->area = 0.0;
    light->one_minus_cos_half = 0.0;
    light->chord = 0.0;
    light->position = light->direction = light->axis_x = light->axis_y = light->spot_axis = dwvu_v(0.0, 0.0, 0.0);
    light->spot_cos_half = light->spot_smooth = 0.0;
    light->spot_axis_cosine = 0;
    light->sphere = 0;
    for (int c = 0; c < 3; ++c) light->emission[c] = desc->color[c] * desc->strength;
    switch (desc->kind) {
    case DWV_LIGHT_SUN: {
        dwvu_vec3 d = dwvu_v(desc->direction[0], desc->direction[1], desc->direction[2]);
        light->direction = dwvu_scale(d, -1.0 / dwvu_length(d));
        double s = sin(0.25 * desc->angle);
        light->one_minus_cos_half = 2.0 * s * s;
        /* |w - direction|^2 = 2 (1 - cos) for a unit w at angle theta <= angle / 2 from it. */
        light->chord = sqrt(2.0 * light->one_minus_cos_half);
        break;
    }
    case DWV_LIGHT_SPOT: /* a point light with a cone */
    case DWV_LIGHT_POINT:
        if (desc->kind == DWV_LIGHT_SPOT) {
            dwvu_vec3 d = dwvu_v(desc->direction[0], desc->direction[1], desc->direction[2]);
            light->spot_axis = dwvu_scale(d, 1.0 / dwvu_length(d));
            light->spot_cos_half = cos(0.5 * desc->spot_size);
            light->spot_smooth = (1.0 - light->spot_cos_half) * desc->spot_blend;
            light->spot_axis_cosine = desc->spot_falloff == DWV_SPOT_FALLOFF_CYCLES3;
        }
        light->position = dwvu_v(desc->position[0], desc->position[1], desc->position[2]);
        light->radius = desc->radius;
        light->sphere = desc->point_shape == DWV_POINT_SHAPE_SPHERE && desc->radius > 0.0;
        for (int c = 0; c < 3; ++c) light->emission[c] *= INV_FOUR_PI;
        break;
    default: {
        light->position = dwvu_v(m[3], m[7], m[11]);
        light->axis_x = dwvu_scale(dwvu_v(m[0], m[4], m[8]), desc->size_x);
        light->axis_y = dwvu_scale(dwvu_v(m[1], m[5], m[9]), desc->size_y);
        light->direction = dwvu_normalize(dwvu_v(-m[2], -m[6], -m[10]));
        dwvu_vec3 ax = light->axis_x, ay = light->axis_y;
        double parallelogram = dwvu_length(dwvu_v(ax.y * ay.z - ax.z * ay.y, ax.z * ay.x - ax.x * ay.z,
                                                  ax.x * ay.y - ax.y * ay.x));
        light->area = desc->kind == DWV_LIGHT_AREA_RECTANGLE ? parallelogram : 0.25 * PI * parallelogram;
        for (int c = 0; c < 3; ++c) light->emission[c] *= 0.25 / light->area;
        break;
    }
    }
}

double dwvl_spot_attenuation(const dwvl_light *light, double c)
{
    if (!(c > light->spot_cos_half)) return 0.0;
    double a = light->spot_axis_cosine ? c : 1.0;
    double t = c - light->spot_cos_half;
    if (light->spot_smooth > 0.0 && t < light->spot_smooth) {
        double s = t / light->spot_smooth;
        a *= s * s * (3.0 - 2.0 * s);
    }
    return a;
}

/* 1 - cos of the half-angle a sphere of radius r subtends at distance d > r, from
 * sin^2 = r^2 / d^2 without cancellation: s / (1 + sqrt(1 - s)). */
static double sphere_one_minus_cos(double r, double d)
{
    double s = (r / d) * (r / d);
    return s / (1.0 + sqrt(fmax(1.0 - s, 0.0)));
}

/* A sphere light (Cycles 4.0+ without Soft Falloff) seen from x at distance d from its centre,
 * toward it along unit `axis`: outside, a direction uniform in the cone it subtends (pdf
 * 1 / (2 pi (1 - cos theta_max)), dwvl_light_pdf), the nearer intersection; inside, uniform over
 * the sphere of directions (pdf 1 / (4 pi)), the intersection ahead. Returns f with radiance /
 * pdf = I f for the radiance I / (pi r^2), I = light->emission: 2 (1 - cos theta_max) / r^2
 * outside, 4 / r^2 inside; *outside says which. */
static double sphere_sample(const dwvl_light *light, dwvu_vec3 axis, double d, double u1, double u2,
                            dwvl_sample *sample, int *outside)
{
    double r = light->radius, r2 = r * r;
    *outside = d > r;
    double mu, omc, factor;
    if (*outside) {
        double omc_max = sphere_one_minus_cos(r, d);
        omc = u1 * omc_max;
        mu = 1.0 - omc;
        factor = 2.0 * omc_max / r2;
    } else {
        mu = 1.0 - 2.0 * u1;
        omc = 2.0 * u1;
        factor = 4.0 / r2;
    }
    sample->direction = dwvk_direction_about(axis, mu, omc, 2.0 - omc, u2);
    /* Law of cosines: |x + t w - centre| = r, t = d mu -+ sqrt(r^2 - d^2 (1 - mu^2)). */
    double root = sqrt(fmax(r2 - d * d * (1.0 - mu) * (1.0 + mu), 0.0));
    sample->distance = *outside ? d * mu - root : d * mu + root;
    return factor;
}

double dwvl_light_pdf(const dwvl_light *light, dwvu_vec3 x, dwvu_vec3 direction)
{
    if ((light->kind != DWV_LIGHT_POINT && light->kind != DWV_LIGHT_SPOT) || !(light->radius > 0.0)) return 0.0;
    dwvu_vec3 to_centre = dwvu_sub(light->position, x);
    double d = dwvu_length(to_centre), r = light->radius;
    if (!(d > 0.0)) return light->sphere ? 0.25 / PI : 0.0;
    double mu = dwvu_dot(direction, to_centre) / d;
    if (light->sphere) {
        if (!(d > r)) return 0.25 / PI;
        double omc_max = sphere_one_minus_cos(r, d);
        return 1.0 - mu <= omc_max ? 1.0 / (2.0 * PI * omc_max) : 0.0;
    }
    /* The disc through the centre facing x: the direction meets its plane at t = d / mu, at
     * d tan(theta) from the centre; area density 1 / (pi r^2) -> solid angle t^2 / (pi r^2 mu). */
    if (!(mu > 0.0)) return 0.0;
    double t = d / mu, off2 = t * t - d * d;
    if (!(off2 <= r * r)) return 0.0;
    return t * t / (PI * r * r * mu);
}

void dwvl_light_sample(const dwvl_light *light, dwvu_vec3 x, double u1, double u2, dwvl_sample *sample)
{
    double factor = 0.0;
    switch (light->kind) {
    case DWV_LIGHT_SUN: {
        /* Uniform in the cone: 1 - cos(theta) = u1 (1 - cos(half)); pdf 1 / (2 pi (1 - cos(half))).
         * radiance / pdf = S 2 pi (1 - cos h) / (pi sin^2 h) = 2 S / (1 + cos h). */
        double omc = u1 * light->one_minus_cos_half;
        sample->direction = dwvk_direction_about(light->direction, 1.0 - omc, omc, 2.0 - omc, u2);
        sample->distance = INFINITY;
        factor = 2.0 / (2.0 - light->one_minus_cos_half);
        break;
    }
    case DWV_LIGHT_SPOT:
    case DWV_LIGHT_POINT: {
        /* A disc of radius r about the centre, facing x, radiance I / (pi r^2): a uniform point q
         * on it gives radiance / pdf = I cos_q / |q - x|^2 (r = 0: the point light I / d^2). A
         * spot's radiance along the sampled direction carries its attenuation, as Cycles'. */
        dwvu_vec3 to_centre = dwvu_sub(light->position, x);
        double d = dwvu_length(to_centre);
        if (!(d > 0.0)) break;
        dwvu_vec3 axis = dwvu_scale(to_centre, 1.0 / d), t, s;
        if (light->sphere) {
            int outside;
            factor = sphere_sample(light, axis, d, u1, u2, sample, &outside);
            if (light->kind == DWV_LIGHT_SPOT && outside)
                factor *= dwvl_spot_attenuation(light, -dwvu_dot(light->spot_axis, sample->direction));
            if (!(sample->distance > 0.0)) factor = 0.0;
            break;
        }
        dwvu_vec3 q = light->position;
        if (light->radius > 0.0) {
            basis(axis, &t, &s);
            double r = light->radius * sqrt(u1), phi = 2.0 * PI * u2;
            q = dwvu_add(q, dwvu_add(dwvu_scale(t, r * cos(phi)), dwvu_scale(s, r * sin(phi))));
        }
        dwvu_vec3 to_q = dwvu_sub(q, x);
        double dq = dwvu_length(to_q);
        if (!(dq > 0.0)) break;
        sample->direction = dwvu_scale(to_q, 1.0 / dq);
        sample->distance = dq;
        factor = dwvu_dot(sample->direction, axis) / (dq * dq);
        if (light->kind == DWV_LIGHT_SPOT) factor *= dwvl_spot_attenuation(light, -dwvu_dot(light->spot_axis, sample->direction));
        break;
    }
    default: {
        /* A uniform point q on the rectangle (ellipse): radiance / pdf = L A cos_q / |q - x|^2,
         * one-sided: cos_q = (emission direction) . (x - q) / |x - q| > 0. */
        double a, b;
        if (light->kind == DWV_LIGHT_AREA_RECTANGLE) {
            a = u1 - 0.5;
            b = u2 - 0.5;
        } else {
            double r = 0.5 * sqrt(u1), phi = 2.0 * PI * u2;
            a = r * cos(phi);
            b = r * sin(phi);
        }
        dwvu_vec3 q = dwvu_add(light->position, dwvu_add(dwvu_scale(light->axis_x, a), dwvu_scale(light->axis_y, b)));
        dwvu_vec3 to_q = dwvu_sub(q, x);
        double dq = dwvu_length(to_q);
        if (!(dq > 0.0)) break;
        sample->direction = dwvu_scale(to_q, 1.0 / dq);
        sample->distance = dq;
        double cos_q = -dwvu_dot(light->direction, sample->direction);
        if (cos_q > 0.0) factor = light->area * cos_q / (dq * dq);
        break;
    }
    }
    if (!(factor > 0.0) || !isfinite(factor)) {
        sample->direction = dwvu_v(0.0, 0.0, 1.0);
        sample->distance = 0.0;
        factor = 0.0;
    }
    for (int c = 0; c < 3; ++c) sample->value[c] = light->emission[c] * factor;
}

int dwvl_light_along(const dwvl_light *light, dwvu_vec3 origin, dwvu_vec3 d, double t_max, double rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    double scale = 0.0;
    switch (light->kind) {
    case DWV_LIGHT_SUN: {
        /* In the cone: 1 - cos(theta) <= 1 - cos(half); sin^2(half) = (1 - cos)(1 + cos). */
        double omc = light->one_minus_cos_half;
        if (!(omc > 0.0) || t_max < INFINITY || !(1.0 - dwvu_dot(d, light->direction) <= omc)) return 0;
        scale = 1.0 / (PI * omc * (2.0 - omc));
        break;
    }
    case DWV_LIGHT_SPOT:
    case DWV_LIGHT_POINT: {
        double r = light->radius;
        if (!(r > 0.0)) return 0;
        dwvu_vec3 to_centre = dwvu_sub(light->position, origin);
        double dist2 = dwvu_dot(to_centre, to_centre), along = dwvu_dot(to_centre, d), t;
        if (light->sphere) {
            /* |origin + t d - centre| = r: t = along -+ sqrt(r^2 - (dist^2 - along^2)). */
            double disc = r * r - (dist2 - along * along);
            if (!(disc >= 0.0)) return 0;
            double root = sqrt(disc);
            t = along - root > 0.0 ? along - root : along + root;
        } else {
            /* The disc's plane through the centre, normal to to_centre: t = dist^2 / along, at
             * t^2 - dist^2 from the centre squared. */
            if (!(along > 0.0)) return 0;
            t = dist2 / along;
            if (!(t * t - dist2 <= r * r)) return 0;
        }
        if (!(t > 0.0) || !(t < t_max)) return 0;
        scale = 1.0 / (PI * r * r);
        /* (From inside a sphere spot: its radiance without the attenuation, as its samples.) */
        if (light->kind == DWV_LIGHT_SPOT && !(light->sphere && dist2 <= r * r))
            scale *= dwvl_spot_attenuation(light, -dwvu_dot(light->spot_axis, d));
        break;
    }
    default: {
        /* Its plane: (origin + t d - centre) . direction = 0, from the front (d . direction < 0);
         * the point's coordinates along the axes (a, b) in [-1/2, 1/2]^2, or a^2 + b^2 <= 1/4. */
        double facing = dwvu_dot(d, light->direction);
        if (!(facing < 0.0)) return 0;
        double t = dwvu_dot(dwvu_sub(light->position, origin), light->direction) / facing;
        if (!(t > 0.0) || !(t < t_max)) return 0;
        dwvu_vec3 q = dwvu_sub(dwvu_madd(origin, d, t), light->position);
        /* q = a axis_x + b axis_y: the normal equations (the axes may be sheared by a transform). */
        double xx = dwvu_dot(light->axis_x, light->axis_x), yy = dwvu_dot(light->axis_y, light->axis_y);
        double xy = dwvu_dot(light->axis_x, light->axis_y), det = xx * yy - xy * xy;
        if (!(det > 0.0)) return 0;
        double qx = dwvu_dot(q, light->axis_x), qy = dwvu_dot(q, light->axis_y);
        double a = (qx * yy - qy * xy) / det, b = (qy * xx - qx * xy) / det;
        int inside = light->kind == DWV_LIGHT_AREA_RECTANGLE ? fabs(a) <= 0.5 && fabs(b) <= 0.5 : a * a + b * b <= 0.25;
        if (!inside) return 0;
        scale = 1.0;
        break;
    }
    }
    if (!(scale > 0.0) || !isfinite(scale)) return 0;
    for (int c = 0; c < 3; ++c) rgb[c] = light->emission[c] * scale;
    return 1;
}
