/* Lights in Blender's units, as Cycles 3.4 evaluates them (intern/cycles/kernel/light/,
 * scene/light.cpp), with emission closures of value 1 x strength (kernel/closure/emissive.h):
 *   point, power P, colour c: intensity I = P c / (4 pi) W/sr (eval_fac 1/(4 pi) x 1/(pi r^2) on a
 *       disc of radius r facing the shaded point, radiance P c / (4 pi^2 r^2)); Cycles 4.0 onward
 *       without Soft Falloff (kernel/light/point.h, is_sphere): a sphere of radius r with that
 *       radiance, sampled uniformly in the cone it subtends (inside it: uniformly over all
 *       directions);
 *   area, power P: one-sided radiance L = P c / (4 A) along the light's local -z
 *       (eval_fac 0.25 / A), A the rectangle's or ellipse's area;
 *   sun, strength S (W/m^2): irradiance S c on a surface facing it, from a cone of the angular
 *       diameter with constant radiance S c / (pi sin^2(angle/2)) (Cycles' own disc sampling
 *       gives S cos^2(angle/2) instead, which differs by less than 0.01% below 1 degree);
 *   spot, power P: the point light's radiance times the spot attenuation a(w) of the direction w
 *       from the light toward the shaded point (Cycles' spot_light_attenuation, with
 *       spot_angle = cos(spot_size / 2) and spot_smooth = (1 - spot_angle) x spot_blend as
 *       scene/light.cpp sets them): c = axis.w; 0 for c <= spot_angle; else c (Cycles 3.x) or 1
 *       (4.0 onward), times smoothstep((c - spot_angle) / spot_smooth) where that is below 1
 *       (a sphere spot: the same, none from inside the sphere, as Cycles' spot.h);
 *   world: constant radiance colour x strength.
 * A sample returns the direction toward the light, the distance, and the radiance divided by the
 * solid-angle pdf: for a Lambertian surface of albedo rho, rho/pi x value x cos x visibility
 * estimates the reflected radiance. */
#ifndef DWV_LIGHT_LIGHT_H
#define DWV_LIGHT_LIGHT_H

#include <dwivedi.h>
#include "util/vec3.h"

typedef struct dwvl_light {
    dwv_light_kind_t kind;
    double emission[3];        /* sun: irradiance S c; point: intensity P c / (4 pi); area: radiance */
    dwvu_vec3 direction;       /* sun: unit, toward the sun; area: unit emission direction (local -z) */
    double one_minus_cos_half; /* sun: 1 - cos(angle / 2), from 2 sin^2(angle / 4) */
    double chord;              /* sun: sqrt(2 (1 - cos(angle / 2))), the farthest any direction of
                                  the disc is from `direction` (dwvl_light_below) */
    dwvu_vec3 position;        /* point: centre; area: centre */
    double radius;             /* point */
    dwvu_vec3 axis_x, axis_y;  /* area: full extents in the world (size x the transform's axes) */
    double area;               /* area: of the rectangle or ellipse */
    dwvu_vec3 spot_axis;       /* spot: unit, the way the cone opens */
    double spot_cos_half;      /* spot: cos(spot_size / 2) */
    double spot_smooth;        /* spot: (1 - spot_cos_half) x spot_blend */
    int spot_axis_cosine;      /* spot: 1 for Cycles 3.x's extra factor c */
    int sphere;                /* point, spot of radius > 0: DWV_POINT_SHAPE_SPHERE (else the disc) */
} dwvl_light;

/* The spot attenuation of a spot light for c, the cosine between its axis and the direction from
 * the light toward the shaded point (see above). */
double dwvl_spot_attenuation(const dwvl_light *light, double c);

typedef struct dwvl_sample {
    dwvu_vec3 direction; /* unit, from the shaded point toward the light */
    double distance;     /* to the sampled light point; +INFINITY for the sun */
    double value[3];     /* radiance / solid-angle pdf; all 0 when the light cannot reach */
} dwvl_sample;

/* Converts a validated description. */
void dwvl_light_init(dwvl_light *light, const dwv_light_desc_t *desc);
/* Whether every direction the light can be sampled in lies strictly below the plane of unit
 * normal n (n.direction < 0 for all of them), known without sampling: a sun whose disc lies
 * below, by a margin of 1e-9 for the rounding of a sampled direction (about 1e-16); 0 for the
 * other lights. Such a light gives a surface facing n nothing. */
static inline int dwvl_light_below(const dwvl_light *light, dwvu_vec3 n)
{
    return light->kind == DWV_LIGHT_SUN && dwvu_dot(n, light->direction) + light->chord < -1e-9;
}

/* Samples the light as seen from x with two uniform numbers. */
void dwvl_light_sample(const dwvl_light *light, dwvu_vec3 x, double u1, double u2, dwvl_sample *sample);
/* The solid-angle density at x of dwvl_light_sample's direction `direction` (unit) for a point or
 * spot light of radius > 0 (disc or sphere); 0 for a direction it never gives, and for the other
 * kinds (a point of radius 0 and a sun of angle 0 are deltas; the area lights are sampled by area).
 * A sample's value is the light's radiance along its direction divided by this. */
double dwvl_light_pdf(const dwvl_light *light, dwvu_vec3 x, dwvu_vec3 direction);

/* The radiance a ray from `origin` along unit d meets on the light before distance t_max (a path
 * ray that found it: Cycles' lights_intersect, which singular reflections use with no MIS), into
 * rgb (0 where it meets none): a point or spot light of radius r > 0 as Cycles 3.x's disc of
 * radius r through the centre facing the ray's origin (DWV_POINT_SHAPE_SPHERE: 4.0+'s sphere, its
 * nearer intersection ahead), radiance I / (pi r^2), a spot's times its attenuation of -d; an area
 * light from its front (against `direction`), its radiance; a sun of angle > 0 where d lies in
 * its cone and t_max is infinite, S c / (pi sin^2(angle / 2)). Deltas (radius or angle 0) are
 * never met. Returns 1 where the light was met. */
int dwvl_light_along(const dwvl_light *light, dwvu_vec3 origin, dwvu_vec3 d, double t_max, double rgb[3]);

#endif
