#include "direct.h"

#include <math.h>


#define INV_PI 0.31830988618379067154

/* The share of the smooth surface's lift (terminator.h) a shadow ray along unit `light` takes. */
static double lift_amount(dwvw_vec3 n, dwvw_vec3 ng, const dwvl_terminator *terminator, dwvw_vec3 light)
{
    return terminator ? dwvl_terminator_amount(dwvw_dot(n, light), dwvw_dot(ng, light), terminator->cutoff) : 0.0;
}

/* Whether a light the shading normal faces gets a shadow ray. Shadow rays leave from x + epsilon
 * ng, moved by their share of the lift, which never goes below the flat triangle. Light above the
 * flat triangle (ng.light > 0) always does: the ray cannot meet its own triangle, so the epsilon
 * does what Cycles' skipping of the triangle itself (its self-intersection test when Ng.L > 0)
 * does. Light below it (ng.light <= 0, the shading normal's terminator lies beyond the flat
 * one's) does only from the smooth surface, as in Cycles: the ray takes the whole lift
 * (dwvl_terminator_amount is 1 there) and, Cycles not skipping its own triangle then, is
 * shadowed where it passes through that triangle. A flat point (no terminator, or cutoff 0) is
 * unlit there: its ray would enter the mesh at once. */
static int shadow_ray_allowed(dwvw_vec3 ng, const dwvl_terminator *terminator, dwvw_vec3 light)
{
    return dwvw_dot(ng, light) > 0.0 || (terminator && terminator->cutoff > 0.0);
}

void dwvl_direct_lobe(const dwvl_environment *env, dwvw_vec3 x, dwvw_vec3 n, dwvw_vec3 ng,
                      const dwvl_terminator *terminator, const dwvk_sampler *sampler, uint32_t pair,
                      dwvl_lobe_factor factor, const void *context, double lambert[3], double lobe[3])
{
    double plain[3] = {0.0, 0.0, 0.0}, weighted[3] = {0.0, 0.0, 0.0};
    double eps = env->geometry ? env->geometry->epsilon : 0.0;
    dwvw_vec3 flat_origin = dwvw_madd(x, ng, eps);
    for (uint32_t i = 0; i < env->light_count; ++i) {
        dwvl_sample s;
        double u[2];
        dwvk_sampler_pair(sampler, pair + i, u);
        dwvl_light_sample(&env->lights[i], x, u[0], u[1], &s);
        double cos_n = dwvw_dot(n, s.direction);
        if (!(cos_n > 0.0)) continue;
        double amount = lift_amount(n, ng, terminator, s.direction);
        if (!shadow_ray_allowed(ng, terminator, s.direction)) continue;
        if (!(s.value[0] > 0.0 || s.value[1] > 0.0 || s.value[2] > 0.0)) continue;
        if (env->geometry) {
            dwvw_vec3 origin = amount > 0.0 ? dwvw_madd(flat_origin, terminator->lift, amount) : flat_origin;
            dwvw_vec3 toward = s.direction;
            double distance = s.distance;
            if (amount > 0.0 && isfinite(distance)) {
                /* The sampled light point, seen from the moved origin (as Cycles aims it). */
                dwvw_vec3 to_light = dwvw_sub(dwvw_madd(x, s.direction, s.distance), origin);
                distance = dwvw_length(to_light);
                toward = dwvw_scale(to_light, 1.0 / distance);
            }
            /* The segment stops short of the light by the offset, so that an area light lying on
             * a surface does not shadow itself. */
            if (dwvg_occluded(env->geometry, origin, toward, 0.0, distance - 2.0 * eps)) continue;
        }
        double f = factor ? factor(context, s.direction) : 0.0;
        for (int c = 0; c < 3; ++c) {
            plain[c] += s.value[c] * cos_n * INV_PI;
            weighted[c] += s.value[c] * cos_n * INV_PI * f;
        }
    }
    if (env->world_lit) {
        /* Cosine-weighted direction about n (pdf cos / pi): the estimate is L_world x visibility
         * (x the factor for the lobe). */
        double u[2];
        dwvk_sampler_pair(sampler, pair + env->light_count, u);
        double mu = sqrt(u[0]);
        dwvw_vec3 w = dwvw_direction_about(n, mu, 1.0 - mu, 1.0 + mu, u[1]);
        double amount = lift_amount(n, ng, terminator, w);
        dwvw_vec3 origin = amount > 0.0 ? dwvw_madd(flat_origin, terminator->lift, amount) : flat_origin;
        if (shadow_ray_allowed(ng, terminator, w) &&
            !(env->geometry && dwvg_occluded(env->geometry, origin, w, 0.0, INFINITY))) {
            double f = factor ? factor(context, w) : 0.0;
            for (int c = 0; c < 3; ++c) {
                plain[c] += env->world[c];
                weighted[c] += env->world[c] * f;
            }
        }
    }
    for (int c = 0; c < 3; ++c) {
        if (lambert) lambert[c] = plain[c];
        if (lobe) lobe[c] = weighted[c];
    }
}

void dwvl_direct(const dwvl_environment *env, dwvw_vec3 x, dwvw_vec3 n, dwvw_vec3 ng,
                 const dwvl_terminator *terminator, const dwvk_sampler *sampler, uint32_t pair, double out[3])
{
    dwvl_direct_lobe(env, x, n, ng, terminator, sampler, pair, NULL, NULL, out, NULL);
}
