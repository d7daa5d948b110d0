#include "mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double dwvg_transform_determinant(const double m[12])
{
    return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
           m[2] * (m[4] * m[9] - m[5] * m[8]);
}

int dwvg_mesh_init(dwvg_mesh *mesh, uint32_t vertex_count, uint32_t triangle_count, uint32_t material_id,
                   const float *positions, const uint32_t *indices, const float *normals, const float *uvs,
                   const double m[12])
{
    memset(mesh, 0, sizeof *mesh);
    size_t nv = (size_t)vertex_count, nt = (size_t)triangle_count;
    /* One float of padding: Embree reads shared vertex buffers 16 bytes at a time. */
    mesh->positions = malloc((nv * 3u + 1u) * sizeof *mesh->positions);
    mesh->indices = malloc(nt * 3u * sizeof *mesh->indices);
    if (normals) mesh->normals = malloc(nv * 3u * sizeof *mesh->normals);
    if (uvs) mesh->uvs = malloc(nt * 6u * sizeof *mesh->uvs);
    if (!mesh->positions || !mesh->indices || (normals && !mesh->normals) || (uvs && !mesh->uvs)) {
        dwvg_mesh_free(mesh);
        return -1;
    }
    mesh->vertex_count = vertex_count;
    mesh->triangle_count = triangle_count;
    mesh->material_id = material_id;
    mesh->positions[3u * nv] = 0.0f;
    for (size_t v = 0; v < nv; ++v) {
        double x = positions[3 * v], y = positions[3 * v + 1], z = positions[3 * v + 2];
        double world[3] = {m[0] * x + m[1] * y + m[2] * z + m[3], m[4] * x + m[5] * y + m[6] * z + m[7],
                           m[8] * x + m[9] * y + m[10] * z + m[11]};
        for (int k = 0; k < 3; ++k)
            mesh->positions[3 * v + (size_t)k] = fabs(world[k]) <= DWVG_LARGEST_COORDINATE ? (float)world[k] : NAN;
    }
    double det = dwvg_transform_determinant(m);
    /* A mirroring transform (det < 0) turns counter-clockwise into clockwise: swap two corners so
     * that the winding still says "outside", as Blender does for negatively scaled objects. */
    int mirror = det < 0.0;
    for (size_t t = 0; t < nt; ++t) {
        mesh->indices[3 * t] = indices[3 * t];
        mesh->indices[3 * t + 1] = indices[3 * t + (mirror ? 2 : 1)];
        mesh->indices[3 * t + 2] = indices[3 * t + (mirror ? 1 : 2)];
        if (uvs) {
            for (int k = 0; k < 2; ++k) {
                mesh->uvs[6 * t + k] = uvs[6 * t + k];
                mesh->uvs[6 * t + 2 + k] = uvs[6 * t + (mirror ? 4 : 2) + k];
                mesh->uvs[6 * t + 4 + k] = uvs[6 * t + (mirror ? 2 : 4) + k];
            }
        }
    }
    if (normals) {
        /* Normals transform by the inverse transpose of the linear part A: A^-T = cof(A) / det(A),
         * cof being the cofactor matrix; the 1/|det| is dropped by the normalisation but its sign
         * is kept so that normals stay on the outside under mirroring. */
        double c[9] = {m[5] * m[10] - m[6] * m[9], m[6] * m[8] - m[4] * m[10], m[4] * m[9] - m[5] * m[8],
                       m[2] * m[9] - m[1] * m[10], m[0] * m[10] - m[2] * m[8], m[1] * m[8] - m[0] * m[9],
                       m[1] * m[6] - m[2] * m[5], m[2] * m[4] - m[0] * m[6], m[0] * m[5] - m[1] * m[4]};
        double sign = mirror ? -1.0 : 1.0;
        for (size_t v = 0; v < nv; ++v) {
            double x = normals[3 * v], y = normals[3 * v + 1], z = normals[3 * v + 2];
            /* n' = cof(A) n: row i of cof(A) is c[3i..3i+2]. */
            double nx = sign * (c[0] * x + c[1] * y + c[2] * z);
            double ny = sign * (c[3] * x + c[4] * y + c[5] * z);
            double nz = sign * (c[6] * x + c[7] * y + c[8] * z);
            double len = sqrt(nx * nx + ny * ny + nz * nz);
            double inv = len > 0.0 && isfinite(len) ? 1.0 / len : 0.0;
            mesh->normals[3 * v] = (float)(nx * inv);
            mesh->normals[3 * v + 1] = (float)(ny * inv);
            mesh->normals[3 * v + 2] = (float)(nz * inv);
        }
    }
    return 0;
}

void dwvg_mesh_free(dwvg_mesh *mesh)
{
    free(mesh->positions);
    free(mesh->indices);
    free(mesh->normals);
    free(mesh->uvs);
    memset(mesh, 0, sizeof *mesh);
}
