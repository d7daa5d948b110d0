/* Textured material inputs at a surface point: the material of a textured mesh's hit (Cycles
 * evaluates the shader there once; the walk from that point goes through the homogeneous medium
 * it makes), its normal after the Normal Map and Bump nodes, and the tangents that normal maps
 * need. */
#ifndef DWV_BAKE_TEXTURED_H
#define DWV_BAKE_TEXTURED_H

#include "bake/scene.h"
#include "util/vec3.h"

/* Whether the material of mesh `mesh_id` has bindings on inputs other than the normal, or on the
 * normal. */
int dwvb_textured_inputs(const dwvb_scene *scene, uint32_t mesh_id);
int dwvb_textured_normal_bound(const dwvb_scene *scene, uint32_t mesh_id);
/* The DWV_BUMP_SHADOWING_* of the material of mesh `mesh_id` (0 without a normal binding). */
int dwvb_textured_bump_shadowing(const dwvb_scene *scene, uint32_t mesh_id);
/* The shadowing of a diffuse lobe whose normal n was tilted from the smooth normal n_s, for
 * light along `light`, as DWV_BUMP_SHADOWING_* `mode` says (capi/dwivedi.h): Chiang et al.
 * 2019's g = (n_s . L) / ((n . L)(n_s . n)), 1 for g >= 1, 0 for g < 0, else -g^3 + g^2 + g (a
 * smooth step that is 1 with slope 0 at g = 1); or Conty Estevez et al. 2019's GGX G1 with
 * alpha^2 = min(tan^2(n_s, n) / 8, 1) at the angle (n_s, L), 0 across the smooth surface. */
double dwvb_bump_shadowing(int mode, dwvu_vec3 n_s, dwvu_vec3 n, dwvu_vec3 light);
/* Cycles' ensure_valid_reflection for a mapped normal n (unit) at a point of geometric normal ng
 * seen from unit direction `to_view` (ng . to_view > 0): n itself where the mirror reflection of
 * to_view about n leaves at least t = min(0.9 ng . to_view, 0.01) above the surface (R . ng >= t),
 * else the normal n' = x X + z ng (X: n's part across ng, normalised) closest to n for which
 * R' . ng = t. With w = z^2, Ix = to_view . X, Iz = to_view . ng, a = Ix^2 + Iz^2: squaring
 * 2 (x Ix + z Iz) z - Iz = t gives w = (a + Iz t +- sqrt(Ix^2 (a - t^2))) / (2 a); roots with w
 * in (1e-5, 1 + 1e-5] whose reflection is really above the surface are kept, the shallower if
 * both are; ng if none is. */
dwvu_vec3 dwvb_valid_reflection(dwvu_vec3 ng, dwvu_vec3 to_view, dwvu_vec3 n);
/* The material of the mesh at point (prim, u, v), textures looked up there. */
void dwvb_textured_material(const dwvb_scene *scene, uint32_t mesh_id, uint32_t prim, double u, double v,
                            dwvb_material *out);
/* The shading normal n (unit, from dwvg_shading_normal) after the material's normal map and bump
 * at (prim, u, v). */
dwvu_vec3 dwvb_textured_normal(const dwvb_scene *scene, uint32_t mesh_id, uint32_t prim, double u, double v,
                               dwvu_vec3 n);
/* The input values a committed material's analysis uses: the material with each binding applied
 * with its texture's largest value per channel (so that a walk, a specular layer or a diffuse lobe
 * that any texel may make is planned for). */
void dwvb_textured_representative(const dwvb_scene *scene, uint32_t material_id, dwv_material_t *out);
/* Tangents for UV layer `layer` of a mesh from its UV gradients (docs/scene-format.md,
 * "Tangents"): 4 x 3 x triangle_count floats, or NULL out of memory. */
float *dwvb_make_tangents(const dwvg_mesh *mesh, const float *uvs);

#endif
