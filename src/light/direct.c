#include "direct.h"

#include <math.h>


#define INV_PI 0.31830988618379067154

void dwvl_direct_lobe(const dwvl_environment *env, dwvw_vec3 x, dwvw_vec3 n, dwvw_vec3 ng, const dwvk_sampler *sampler,
                      uint32_t pair, dwvl_lobe_factor factor, const void *context, double lambert[3], double lobe[3])
{
    double plain[3] = {0.0, 0.0, 0.0}, weighted[3] = {0.0, 0.0, 0.0};
    double eps = env->geometry ? env->geometry->epsilon : 0.0;
    dwvw_vec3 origin = dwvw_madd(x, ng, eps);
    for (uint32_t i = 0; i < env->light_count; ++i) {
        dwvl_sample s;
        double u[2];
        dwvk_sampler_pair(sampler, pair + i, u);
        dwvl_light_sample(&env->lights[i], x, u[0], u[1], &s);
        double cos_n = dwvw_dot(n, s.direction);
        if (!(cos_n > 0.0) || !(dwvw_dot(ng, s.direction) > 0.0)) continue;
        if (!(s.value[0] > 0.0 || s.value[1] > 0.0 || s.value[2] > 0.0)) continue;
        /* The segment stops short of the light by the offset, so that an area light lying on a
         * surface does not shadow itself. */
        if (env->geometry && dwvg_occluded(env->geometry, origin, s.direction, 0.0, s.distance - 2.0 * eps)) continue;
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
        if (dwvw_dot(ng, w) > 0.0 && !(env->geometry && dwvg_occluded(env->geometry, origin, w, 0.0, INFINITY))) {
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

void dwvl_direct(const dwvl_environment *env, dwvw_vec3 x, dwvw_vec3 n, dwvw_vec3 ng, const dwvk_sampler *sampler,
                 uint32_t pair, double out[3])
{
    dwvl_direct_lobe(env, x, n, ng, sampler, pair, NULL, NULL, out, NULL);
}
