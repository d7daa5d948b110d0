/* Transforms as Blender builds them: object matrices from location, rotation and scale, and
 * look-at frames for cameras and lights. */
#include "scenefile/transform.h"

#include <math.h>

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double length3(const double a[3])
{
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

void dwvs_transform_trs(const double t[3], const double r_degrees[3], const double s[3], double m[12])
{
    const double to_radians = 3.14159265358979323846 / 180.0;
    double cx = cos(r_degrees[0] * to_radians), sx = sin(r_degrees[0] * to_radians);
    double cy = cos(r_degrees[1] * to_radians), sy = sin(r_degrees[1] * to_radians);
    double cz = cos(r_degrees[2] * to_radians), sz = sin(r_degrees[2] * to_radians);
    /* Rz Ry Rx, multiplied out (Blender's eulO_to_mat3 for the XYZ order). */
    const double r[9] = {cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
                         sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
                         -sy,     cy * sx,                cy * cx};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) m[4 * i + j] = r[3 * i + j] * s[j];
        m[4 * i + 3] = t[i];
    }
}

int dwvs_transform_look_at(const double eye[3], const double target[3], const double up[3], double m[12])
{
    double z[3] = {eye[0] - target[0], eye[1] - target[1], eye[2] - target[2]}, x[3], y[3];
    double lz = length3(z);
    if (!(lz > 0.0) || !isfinite(lz)) return -1;
    for (int i = 0; i < 3; ++i) z[i] /= lz;
    cross(up, z, x);
    /* |up x z| = |up| sin(angle between them). */
    double lu = length3(up), lx = length3(x);
    if (!(lu > 0.0) || !isfinite(lu) || !(lx > 1e-6 * lu)) return -2;
    for (int i = 0; i < 3; ++i) x[i] /= lx;
    cross(z, x, y);
    for (int i = 0; i < 3; ++i) {
        m[4 * i + 0] = x[i];
        m[4 * i + 1] = y[i];
        m[4 * i + 2] = z[i];
        m[4 * i + 3] = eye[i];
    }
    return 0;
}
