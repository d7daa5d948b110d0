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
/* The material of the mesh at point (prim, u, v), textures looked up there. */
void dwvb_textured_material(const dwvb_scene *scene, uint32_t mesh_id, uint32_t prim, double u, double v,
                            dwvb_material *out);
/* The shading normal n (unit, from dwvg_shading_normal) after the material's normal map and bump
 * at (prim, u, v); ng the geometric normal on the same side. */
dwvu_vec3 dwvb_textured_normal(const dwvb_scene *scene, uint32_t mesh_id, uint32_t prim, double u, double v,
                               dwvu_vec3 n, dwvu_vec3 ng);
/* The input values a committed material's analysis uses: the material with each binding applied
 * with its texture's largest value per channel (so that a walk, a specular layer or a diffuse lobe
 * that any texel may make is planned for). */
void dwvb_textured_representative(const dwvb_scene *scene, uint32_t material_id, dwv_material_t *out);
/* Tangents for UV layer `layer` of a mesh from its UV gradients (docs/scene-format.md,
 * "Tangents"): 4 x 3 x triangle_count floats, or NULL out of memory. */
float *dwvb_make_tangents(const dwvg_mesh *mesh, const float *uvs);

#endif
