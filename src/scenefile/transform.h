/* Row-major 3 x 4 object-to-world transforms as Blender builds them, for scene files and the
 * default scene. */
#ifndef DWV_SCENEFILE_TRANSFORM_H
#define DWV_SCENEFILE_TRANSFORM_H

/* M = T R S from a location, an XYZ Euler rotation in degrees (Blender's "XYZ" order: X is
 * applied first, R = Rz Ry Rx) and a per-axis scale. */
void dwvs_transform_trs(const double translate[3], const double rotate_degrees[3], const double scale[3],
                         double m[12]);

/* A camera or light at `eye` looking toward `target` along its local -z, local +y toward `up`
 * (Blender's camera convention). Returns 0, or -1 if eye and target coincide, -2 if up is zero or
 * within about 1e-6 rad of the view axis. */
int dwvs_transform_look_at(const double eye[3], const double target[3], const double up[3], double m[12]);

#endif
