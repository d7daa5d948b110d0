/* Triangle meshes read from OBJ and PLY files with Assimp's C API (src/scenefile knows nothing of the
 * scene store: the caller hands the arrays to dwv_scene_add_mesh, which validates them). */
#ifndef DWV_SCENEFILE_MESH_FILE_H
#define DWV_SCENEFILE_MESH_FILE_H

#include <stdint.h>

#include <dwivedi.h>

/* The arrays dwv_mesh_t wants, owned (free with dwvs_mesh_data_free). normals is NULL unless
 * every part of the file has normals, uvs NULL unless every part has a first UV channel. */
typedef struct dwvs_mesh_data {
    uint32_t vertex_count;
    uint32_t triangle_count;
    float *positions; /* 3 x vertex_count */
    uint32_t *indices;/* 3 x triangle_count */
    float *normals;   /* 3 x vertex_count or NULL */
    float *uvs;       /* 2 x 3 x triangle_count (per corner) or NULL */
} dwvs_mesh_data;

/* The most vertices or triangles a mesh file may bring (each array stays below 2^31 bytes). */
#define DWVS_MESH_MAX_ELEMENTS (1u << 26)

/* Reads `path` (.obj or .ply, by its extension): triangulated, every mesh in the file
 * concatenated with its node transform applied. Fails with DWV_ERROR_IO (cannot read) or
 * DWV_ERROR_FORMAT (not a mesh, no triangles, too large), the message naming the path. */
dwv_result_t dwvs_mesh_file_read(const char *path, dwvs_mesh_data *mesh);
void dwvs_mesh_data_free(dwvs_mesh_data *mesh);

#endif
