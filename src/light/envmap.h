/* The world's equirectangular environment (dwv_environment_t): its radiance toward a direction,
 * as Cycles' Environment Texture node looks it up, and a distribution of directions for light
 * sampling, its pdf beside it.
 *
 * Mapping (Cycles' direction_to_equirectangular, for b = rotation x d, unit):
 *   u = 0.5 - atan2(b.y, b.x) / (2 pi),  v = 1 - acos(b.z) / pi;  inversely
 *   phi = pi (1 - 2u),  theta = pi (1 - v),  b = (sin theta cos phi, sin theta sin phi, cos theta).
 * Texel (c, r) (row 0 at the bottom) covers u in [c/w, (c+1)/w], v in [r/h, (r+1)/h]: the solid
 * angle Omega_r = (2 pi / w) (z_{r+1} - z_r), z_r = cos(pi (1 - r/h)) = -cos(pi r / h), the
 * integral of the sin(theta) Jacobian over the row.
 *
 * Sampling: a piecewise-constant distribution over the texels, P(c, r) proportional to
 * W(c, r) Omega_r with W the largest luminance among the texels the interpolation reads anywhere
 * in the cell (its own; 3 x 3 around it for linear, 5 x 5 for cubic), so that the pdf is above 0
 * wherever the radiance is. A row is drawn by its marginal CDF, a column by the row's conditional
 * CDF, and the direction uniformly in the cell's solid angle (z uniform in [z_r, z_{r+1}], phi
 * uniform in the column): pdf(d) = P(c, r) / Omega_r, constant over the cell. P is read from the
 * CDFs' differences, the very numbers the sampler inverts, so sample and pdf agree exactly. */
#ifndef DWV_LIGHT_ENVMAP_H
#define DWV_LIGHT_ENVMAP_H

#include <stddef.h>
#include <stdint.h>

#include <dwivedi.h>
#include "util/vec3.h"

typedef struct dwvl_envmap {
    uint32_t width, height;
    dwv_environment_interpolation_t interpolation;
    double strength;
    double rotation[9]; /* row-major: b = rotation d */
    float *texels;      /* 3 x width x height, row 0 at the bottom */
    float *column_cdf;  /* per row, width entries: the conditional CDF at the end of each column */
    double *row_cdf;    /* height entries: the marginal CDF at the end of each row (the last is 1) */
} dwvl_envmap;

/* Builds the map from validated texels (copied; width x height > 1, strength > 0). Returns 0; 1
 * when no texel has a luminance above 0 (a black world: nothing left allocated); -1 out of
 * memory (nothing left allocated). */
int dwvl_envmap_init(dwvl_envmap *map, const dwv_environment_t *desc);
void dwvl_envmap_free(dwvl_envmap *map);
/* Bytes the map holds (texels and distribution). */
size_t dwvl_envmap_bytes(const dwvl_envmap *map);

/* The radiance toward unit world direction d. */
void dwvl_envmap_radiance(const dwvl_envmap *map, dwvu_vec3 d, double rgb[3]);
/* The sampling pdf per steradian of unit world direction d. */
double dwvl_envmap_pdf(const dwvl_envmap *map, dwvu_vec3 d);
/* A direction for uniform u1 (row), u2 (column) in [0, 1), and its pdf per steradian (0 and an
 * arbitrary direction where none can be drawn). */
void dwvl_envmap_sample(const dwvl_envmap *map, double u1, double u2, dwvu_vec3 *d, double *pdf);

#endif
