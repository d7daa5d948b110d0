/* Texture lookup (src/bake/texture.c) against values worked out by hand from Blender's Image
 * Texture conventions: closest texels, bilinear midpoints, the cubic B-spline's weights at a
 * texel centre (1/6, 4/6, 1/6) and its exactness on linear ramps, each extension (repeat, extend,
 * clip, mirror) at points outside [0, 1), sRGB decoded after interpolation, the tangents made
 * from UVs on a plane, and the mapped normals' bump shadowing (Chiang 2019, Conty 2019) and
 * ensure_valid_reflection (src/bake/textured.c) at hand-computed points. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bake/texture.h"
#include "bake/textured.h"
#include "check.h"

static dwvb_texture make(uint32_t w, uint32_t h, uint32_t channels, dwv_texel_format_t format,
                         dwv_texture_extension_t extension, dwv_texture_interpolation_t interpolation, const void *texels)
{
    dwv_texture_desc_t d = DWV_TEXTURE_DESC_INIT;
    d.width = w, d.height = h, d.channels = channels, d.format = format, d.extension = extension;
    d.interpolation = interpolation, d.texels = texels;
    dwvb_texture t;
    if (dwvb_texture_init(&t, &d)) exit(2);
    return t;
}

static double at(const dwvb_texture *t, double u, double v)
{
    double out[4];
    dwvb_texture_lookup(t, u, v, out);
    return out[0];
}

#define PI 3.14159265358979323846
#define NEAR(a, b, tol) (fabs((a) - (b)) <= (tol))

int main(void)
{
    /* 4 x 2, one channel: row 0 (v < 0.5) 1 2 3 4, row 1 5 6 7 8. */
    const float ramp[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    dwv_texture_interpolation_t closest = DWV_INTERPOLATION_CLOSEST, linear = DWV_INTERPOLATION_LINEAR;
    dwvb_texture t = make(4, 2, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_REPEAT, closest, ramp);
    CHECK(at(&t, 0.1, 0.1) == 1.0 && at(&t, 0.3, 0.1) == 2.0 && at(&t, 0.9, 0.9) == 8.0, "closest texels");
    CHECK(at(&t, 1.1, 0.1) == 1.0 && at(&t, -0.1, 0.1) == 4.0 && at(&t, 0.6, -0.4) == 7.0, "closest repeat");
    CHECK(t.max[0] == 8.0, "max %g", t.max[0]);
    dwvb_texture_free(&t);
    t = make(4, 2, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_EXTEND, closest, ramp);
    CHECK(at(&t, 1.7, 0.1) == 4.0 && at(&t, -3.0, 2.0) == 5.0, "closest extend");
    dwvb_texture_free(&t);
    t = make(4, 2, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_CLIP, closest, ramp);
    CHECK(at(&t, 1.01, 0.1) == 0.0 && at(&t, 0.5, -0.01) == 0.0 && at(&t, 0.99, 0.99) == 8.0, "closest clip");
    dwvb_texture_free(&t);
    t = make(4, 2, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_MIRROR, closest, ramp);
    /* Mirror: u in [1, 2) reads the row backwards; u in [-1, 0) too. */
    CHECK(at(&t, 1.1, 0.1) == 4.0 && at(&t, 1.9, 0.1) == 1.0 && at(&t, -0.1, 0.1) == 1.0 && at(&t, 2.1, 0.1) == 1.0,
          "closest mirror %g %g %g %g", at(&t, 1.1, 0.1), at(&t, 1.9, 0.1), at(&t, -0.1, 0.1), at(&t, 2.1, 0.1));
    dwvb_texture_free(&t);

    /* Bilinear: at texel centres the texel; midway the mean; the wrap mixes across the seam. */
    t = make(4, 2, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_REPEAT, linear, ramp);
    CHECK(NEAR(at(&t, 0.125, 0.25), 1.0, 1e-12) && NEAR(at(&t, 0.25, 0.25), 1.5, 1e-12), "linear centres");
    CHECK(NEAR(at(&t, 0.25, 0.5), (1 + 2 + 5 + 6) / 4.0, 1e-12), "linear midpoint");
    CHECK(NEAR(at(&t, 0.0, 0.25), (4 + 1) / 2.0, 1e-12), "linear across the repeat seam %g", at(&t, 0.0, 0.25));
    dwvb_texture_free(&t);
    t = make(4, 2, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_CLIP, linear, ramp);
    CHECK(NEAR(at(&t, 0.0, 0.25), 0.5, 1e-12), "linear clip: half the edge texel %g", at(&t, 0.0, 0.25));
    dwvb_texture_free(&t);
    t = make(4, 2, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_EXTEND, linear, ramp);
    CHECK(NEAR(at(&t, 0.0, 0.25), 1.0, 1e-12) && NEAR(at(&t, 1.5, 0.75), 8.0, 1e-12), "linear extend");
    dwvb_texture_free(&t);
    t = make(4, 2, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_MIRROR, linear, ramp);
    CHECK(NEAR(at(&t, 0.0, 0.25), 1.0, 1e-12) && NEAR(at(&t, 1.0, 0.25), 4.0, 1e-12), "linear mirror edges");
    dwvb_texture_free(&t);

    /* Cubic B-spline: an impulse at texel (2, 2) of a 5 x 5 image reads (4/6)^2 at its centre,
     * (1/6)(4/6) one texel across, (1/6)^2 diagonally; a linear ramp is reproduced exactly. */
    float impulse[25] = {0};
    impulse[2 * 5 + 2] = 1.0f;
    t = make(5, 5, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_CLIP, DWV_INTERPOLATION_CUBIC, impulse);
    double c = 2.5 / 5.0, one = 1.0 / 5.0;
    CHECK(NEAR(at(&t, c, c), 16.0 / 36.0, 1e-12), "cubic centre %g", at(&t, c, c));
    CHECK(NEAR(at(&t, c + one, c), 4.0 / 36.0, 1e-12), "cubic side %g", at(&t, c + one, c));
    CHECK(NEAR(at(&t, c + one, c + one), 1.0 / 36.0, 1e-12), "cubic diagonal");
    CHECK(NEAR(at(&t, c + 2 * one, c), 0.0, 1e-12), "cubic support");
    dwvb_texture_free(&t);
    float line[8];
    for (int i = 0; i < 8; ++i) line[i] = (float)i;
    t = make(8, 1, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_EXTEND, DWV_INTERPOLATION_CUBIC, line);
    for (double x = 2.0; x <= 5.0; x += 0.37) CHECK(NEAR(at(&t, (x + 0.5) / 8.0, 0.5), x, 1e-12), "cubic ramp at %g", x);
    dwvb_texture_free(&t);

    /* 8-bit sRGB: decoded after interpolation (the midpoint of 0 and 255 is sRGB 0.5, 0.2140
     * linear, not 0.5), alpha linear; 8-bit non-colour is value / 255. */
    const uint8_t bytes[8] = {0, 0, 0, 0, 255, 255, 255, 255};
    t = make(2, 1, 4, DWV_TEXEL_SRGB8, DWV_EXTENSION_EXTEND, linear, bytes);
    double out[4];
    dwvb_texture_lookup(&t, 0.5, 0.5, out);
    CHECK(NEAR(out[0], pow((0.5 + 0.055) / 1.055, 2.4), 1e-12) && NEAR(out[3], 0.5, 1e-12), "sRGB %g %g", out[0], out[3]);
    CHECK(NEAR(dwvb_srgb_to_linear(0.04), 0.04 / 12.92, 1e-15), "sRGB toe");
    CHECK(dwvb_texture_texel_bytes(&t) == 4u, "bytes per texel");
    dwvb_texture_free(&t);
    const uint8_t grey[2] = {51, 204};
    t = make(2, 1, 1, DWV_TEXEL_LINEAR8, DWV_EXTENSION_EXTEND, closest, grey);
    CHECK(NEAR(at(&t, 0.2, 0.5), 0.2, 1e-12) && NEAR(at(&t, 0.7, 0.5), 0.8, 1e-12), "linear 8-bit");
    dwvb_texture_free(&t);
    /* Colours to scalars: Rec.709 luminance. */
    const float rgb[3] = {1.0f, 0.0f, 0.0f};
    t = make(1, 1, 3, DWV_TEXEL_FLOAT32, DWV_EXTENSION_REPEAT, closest, rgb);
    dwvb_texture_lookup(&t, 0.5, 0.5, out);
    CHECK(NEAR(dwvb_texture_scalar(&t, out), 0.2126, 1e-15), "luminance");
    dwvb_texture_free(&t);
    /* Far and non-finite coordinates stay in the image. */
    t = make(4, 2, 1, DWV_TEXEL_FLOAT32, DWV_EXTENSION_REPEAT, linear, ramp);
    double far = at(&t, 1e300, -1e300), nan_value = at(&t, NAN, INFINITY);
    CHECK(far >= 1.0 && far <= 8.0 && nan_value >= 1.0 && nan_value <= 8.0, "far %g nan %g", far, nan_value);
    dwvb_texture_free(&t);

    /* Tangents of a plane z = 0 whose u runs along +x and v along +y: T = +x, sign +1; with v
     * along -y: sign -1. */
    float positions[13] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0};
    uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
    float uvs[12] = {0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1};
    dwvg_mesh mesh = {4u, 2u, 0u, positions, indices, NULL, uvs};
    float *tangents = dwvb_make_tangents(&mesh, uvs);
    CHECK(tangents != NULL, "tangents");
    for (int k = 0; k < 6 && tangents; ++k)
        CHECK(NEAR(tangents[4 * k], 1.0, 1e-6) && NEAR(tangents[4 * k + 1], 0.0, 1e-6) && tangents[4 * k + 3] == 1.0f,
              "corner %d tangent (%g %g %g) sign %g", k, tangents[4 * k], tangents[4 * k + 1], tangents[4 * k + 2],
              tangents[4 * k + 3]);
    free(tangents);
    for (int k = 0; k < 6; ++k) uvs[2 * k + 1] = 1.0f - uvs[2 * k + 1];
    tangents = dwvb_make_tangents(&mesh, uvs);
    for (int k = 0; k < 6 && tangents; ++k) CHECK(tangents[4 * k + 3] == -1.0f, "flipped v: sign %g", tangents[4 * k + 3]);
    free(tangents);

    /* Bump shadowing (Chiang 2019), by hand: n_s = z, n tilted 60 degrees toward x;
     * g = (n_s . L) / ((n . L)(n_s . n)). */
    dwvu_vec3 z = dwvu_v(0, 0, 1), n60 = dwvu_v(sin(PI / 3), 0, cos(PI / 3)), n30 = dwvu_v(sin(PI / 6), 0, cos(PI / 6));
    dwvu_vec3 up = dwvu_v(0, 0, 1);
    CHECK(dwvb_bump_shadowing(DWV_BUMP_SHADOWING_CHIANG2019, z, n60, up) == 1.0, "g = 1 / (1/2 1/2) = 4: unshadowed");
    /* L = normalize(1, 0, 0.2): n_s . L = 0.2 / |.|, n . L = (sin60 + 0.2 cos60) / |.|. */
    double norm = sqrt(1.04);
    dwvu_vec3 low = dwvu_v(1.0 / norm, 0, 0.2 / norm);
    double g = (0.2 / norm) / (((sin(PI / 3) + 0.1) / norm) * 0.5);
    CHECK(NEAR(dwvb_bump_shadowing(DWV_BUMP_SHADOWING_CHIANG2019, z, n60, low), -g * g * g + g * g + g, 1e-12), "Chiang at g = %g", g);
    CHECK(dwvb_bump_shadowing(DWV_BUMP_SHADOWING_CHIANG2019, z, n60, dwvu_v(0.99, 0, -0.141)) == 0.0, "below n_s");
    /* Conty 2019: cos_d = cos 30, cos_i = 1/2: alpha^2 = tan^2 30 / 8 = 1/24, tan^2 theta_i = 3:
     * G1 = 2 / (1 + sqrt(1 + 1/8)); 0 for light above n but below n_s. */
    dwvu_vec3 l60 = dwvu_v(sin(PI / 3), 0, 0.5);
    CHECK(NEAR(dwvb_bump_shadowing(DWV_BUMP_SHADOWING_CONTY2019, z, n30, l60), 2.0 / (1.0 + sqrt(1.125)), 1e-12),
          "Conty %g", dwvb_bump_shadowing(DWV_BUMP_SHADOWING_CONTY2019, z, n30, l60));
    CHECK(dwvb_bump_shadowing(DWV_BUMP_SHADOWING_CONTY2019, z, n30, dwvu_v(0.995, 0, -0.0995)) == 0.0,
          "above n, below n_s");
    CHECK(dwvb_bump_shadowing(DWV_BUMP_SHADOWING_NONE, z, n30, l60) == 1.0, "none");
    /* ensure_valid_reflection: seen along ng = z, a normal tilted 60 degrees reflects the view
     * below the surface (2 cos^2 60 - 1 < 0): the kept normal has 2 z^2 - 1 = 0.01; 30 degrees stays. */
    dwvu_vec3 fixed = dwvb_valid_reflection(z, up, n60);
    CHECK(NEAR(fixed.z, sqrt(0.505), 1e-12) && fixed.x > 0.0 && NEAR(dwvu_length(fixed), 1.0, 1e-12),
          "valid reflection %g %g %g", fixed.x, fixed.y, fixed.z);
    dwvu_vec3 kept = dwvb_valid_reflection(z, up, n30);
    CHECK(kept.x == n30.x && kept.z == n30.z, "a valid normal is kept");
    return check_report("test_texture_lookup");
}
