/* A triangle mesh in world space, as the scene keeps it: the caller's arrays copied and taken
 * through the object-to-world transform once, so that rays, closest points and lights all work in
 * one space. */
#ifndef DWV_GEOM_MESH_H
#define DWV_GEOM_MESH_H

#include <stdint.h>

/* At most 2^28 triangles (and vertices) per mesh: 3 x 2^28 indices still fit Embree's 32-bit
 * primitive ids and the byte sizes fit comfortably in size_t. */
#define DWVG_MAX_MESH_ELEMENTS (1u << 28)

/* The largest world coordinate a triangle may have. Embree intersects in float with products of
 * three coordinate differences (edge x edge . (corner - origin)), which overflow beyond about
 * 3e12: rays then pass through or meet the wrong face (measured: a box scaled 3e12 bakes wrong,
 * 1e12 right). A world coordinate beyond 2^40 (1.1e12), or one that overflows, is stored as NaN:
 * Embree leaves out every triangle touching it, and the scene counts those as warnings. */
#define DWVG_LARGEST_COORDINATE 0x1p40

typedef struct dwvg_mesh {
    uint32_t vertex_count, triangle_count, material_id;
    float *positions;  /* 3 x vertex_count, world space (plus one float of padding for Embree);
                          NaN beyond DWVG_LARGEST_COORDINATE */
    uint32_t *indices; /* 3 x triangle_count, counter-clockwise seen from outside (Blender's
                          convention), the order reversed when the transform mirrors */
    float *normals;    /* 3 x vertex_count, world space, unit; NULL: flat shading */
    float *uvs;        /* 2 x 3 x triangle_count per corner (in the stored corner order); or NULL */
} dwvg_mesh;

/* Fills `mesh` from object-space arrays (already validated: finite, indices in range) and a
 * row-major 3 x 4 object-to-world transform with a non-zero determinant. Normals go through the
 * inverse transpose of the linear part (then are normalised; a zero normal stays zero and the
 * geometric normal is used there). 0 on success, -1 when out of memory (mesh left empty). */
int dwvg_mesh_init(dwvg_mesh *mesh, uint32_t vertex_count, uint32_t triangle_count, uint32_t material_id,
                   const float *positions, const uint32_t *indices, const float *normals, const float *uvs,
                   const double transform[12]);
void dwvg_mesh_free(dwvg_mesh *mesh);

/* The determinant of the linear part of a row-major 3 x 4 transform. */
double dwvg_transform_determinant(const double transform[12]);

#endif
