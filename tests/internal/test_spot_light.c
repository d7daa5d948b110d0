/* Spot lights (src/light/light.c): the attenuation against values computed apart from the library
 * (Python, from Cycles 3.x's spot_light_attenuation and 4.x's smoothstep of
 * (c - cos(size/2)) / ((1 - cos(size/2)) blend)), and the light's sample against the point light's
 * times that attenuation. */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "light/light.h"

int main(void)
{
    /* spot_size 60 degrees, blend 0.5: cos(30 deg) = 0.8660254, smooth width 0.0669873. */
    static const struct { double c, cycles3, cycles4; } table[] = {
        {0.8, 0.0, 0.0},
        {0.866, 0.0, 0.0}, /* just outside the cone */
        {0.87, 0.008824981199070565, 0.010143656550655822},
        {0.9, 0.45969189773950936, 0.5107687752661215},
        {0.92, 0.8293378915218816, 0.9014542299150887},
        {0.95, 0.95, 1.0},
        {1.0, 1.0, 1.0},
    };
    for (int falloff = DWV_SPOT_FALLOFF_CYCLES3; falloff <= DWV_SPOT_FALLOFF_CYCLES4; ++falloff) {
        dwv_light_desc_t desc = DWV_LIGHT_DESC_INIT;
        desc.kind = DWV_LIGHT_SPOT;
        desc.spot_size = 60.0 * 3.14159265358979323846 / 180.0;
        desc.spot_blend = 0.5;
        desc.spot_falloff = falloff;
        dwvl_light light;
        dwvl_light_init(&light, &desc);
        for (size_t i = 0; i < sizeof table / sizeof table[0]; ++i) {
            double want = falloff == DWV_SPOT_FALLOFF_CYCLES3 ? table[i].cycles3 : table[i].cycles4;
            double got = dwvl_spot_attenuation(&light, table[i].c);
            CHECK(fabs(got - want) <= 1e-12, "falloff %d, c = %g: %.17g, want %.17g", falloff, table[i].c, got, want);
        }
        /* Blend 0: a hard edge. */
        desc.spot_blend = 0.0;
        dwvl_light_init(&light, &desc);
        CHECK(dwvl_spot_attenuation(&light, 0.87) == (falloff == DWV_SPOT_FALLOFF_CYCLES3 ? 0.87 : 1.0), "hard edge");
        CHECK(dwvl_spot_attenuation(&light, 0.86) == 0.0, "hard edge outside");
    }
    /* A sample of a spot light pointing down from (0, 0, 2) at a point off its axis is the point
     * light's of the same power times the attenuation of the direction light -> point. */
    dwv_light_desc_t spot = DWV_LIGHT_DESC_INIT, point = DWV_LIGHT_DESC_INIT;
    spot.kind = DWV_LIGHT_SPOT;
    point.kind = DWV_LIGHT_POINT;
    spot.position[2] = point.position[2] = 2.0;
    spot.strength = point.strength = 100.0;
    spot.direction[0] = 0.0;
    spot.direction[1] = 0.0;
    spot.direction[2] = -3.0;
    spot.spot_size = 1.2;
    spot.spot_blend = 0.4;
    dwvl_light ls, lp;
    dwvl_light_init(&ls, &spot);
    dwvl_light_init(&lp, &point);
    for (int i = 0; i < 20; ++i) {
        dwvu_vec3 x = dwvu_v(0.05 * i, 0.02 * i, 0.0);
        dwvl_sample a, b;
        dwvl_light_sample(&ls, x, 0.3, 0.7, &a);
        dwvl_light_sample(&lp, x, 0.3, 0.7, &b);
        double c = 2.0 / sqrt(2.0 * 2.0 + x.x * x.x + x.y * x.y);
        double want = b.value[0] * dwvl_spot_attenuation(&ls, c);
        CHECK(fabs(a.value[0] - want) <= 1e-12 * (want + 1e-30) + 1e-300, "point %d: %.17g, want %.17g", i, a.value[0],
              want);
    }
    return check_report("test_spot_light");
}
