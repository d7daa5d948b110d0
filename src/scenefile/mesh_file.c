/* OBJ and PLY meshes through Assimp's C API: triangulated, node transforms applied, every mesh of
 * the file concatenated into one set of arrays for dwv_scene_add_mesh. */
#define _POSIX_C_SOURCE 200809L
#include "scenefile/mesh_file.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include <assimp/cimport.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "util/error.h"
#include "scenefile/ply_check.h"

/* Assimp keeps its last error in one global string, so imports are taken one at a time: the
 * message read after a failed import is then that import's own. */
static pthread_mutex_t assimp_lock = PTHREAD_MUTEX_INITIALIZER;

void dwvs_mesh_data_free(dwvs_mesh_data *mesh)
{
    if (!mesh) return;
    free(mesh->positions);
    free(mesh->indices);
    free(mesh->normals);
    free(mesh->uvs);
    memset(mesh, 0, sizeof *mesh);
}

static int has_extension(const char *path, const char *extension)
{
    size_t n = strlen(path), e = strlen(extension);
    return n > e && strcasecmp(path + n - e, extension) == 0;
}

/* What Assimp said, without line breaks (its messages sometimes end in one). */
static void assimp_message(char *out, size_t size)
{
    const char *message = aiGetErrorString();
    snprintf(out, size, "%s", message && message[0] ? message : "no reason given");
    for (char *c = out; *c; ++c)
        if (*c == '\n' || *c == '\r') *c = ' ';
}

static int finite3(const struct aiVector3D *v)
{
    return isfinite(v->x) && isfinite(v->y) && isfinite(v->z);
}

static int all_finite(const struct aiScene *scene)
{
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const struct aiMesh *mesh = scene->mMeshes[m];
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            if (!finite3(&mesh->mVertices[v])) return 0;
            if (mesh->mNormals && !finite3(&mesh->mNormals[v])) return 0;
            if (mesh->mTextureCoords[0] && !finite3(&mesh->mTextureCoords[0][v])) return 0;
        }
    }
    return 1;
}

static int has_polygons(const struct aiScene *scene)
{
    for (unsigned m = 0; m < scene->mNumMeshes; ++m)
        for (unsigned f = 0; f < scene->mMeshes[m]->mNumFaces; ++f)
            if (scene->mMeshes[m]->mFaces[f].mNumIndices > 3u) return 1;
    return 0;
}

static dwv_result_t convert(const struct aiScene *scene, const char *path, dwvs_mesh_data *out)
{
    uint64_t vertices = 0, triangles = 0;
    int normals = 1, uvs = 1;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const struct aiMesh *mesh = scene->mMeshes[m];
        vertices += mesh->mNumVertices;
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) triangles += mesh->mFaces[f].mNumIndices == 3u;
        if (!mesh->mNormals) normals = 0;
        if (!mesh->mTextureCoords[0]) uvs = 0;
        /* Checked as we go so that the sums cannot overflow on hostile counts. */
        if (vertices > DWVS_MESH_MAX_ELEMENTS || triangles > DWVS_MESH_MAX_ELEMENTS)
            return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': more than %u vertices or triangles", path,
                            DWVS_MESH_MAX_ELEMENTS);
    }
    if (triangles == 0)
        return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': no triangles in it", path);

    out->vertex_count = (uint32_t)vertices;
    out->triangle_count = (uint32_t)triangles;
    out->positions = malloc((size_t)vertices * 3u * sizeof(float));
    out->indices = malloc((size_t)triangles * 3u * sizeof(uint32_t));
    out->normals = normals ? malloc((size_t)vertices * 3u * sizeof(float)) : NULL;
    out->uvs = uvs ? malloc((size_t)triangles * 6u * sizeof(float)) : NULL;
    if (!out->positions || !out->indices || (normals && !out->normals) || (uvs && !out->uvs)) {
        dwvs_mesh_data_free(out);
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "mesh file '%s': no memory for %llu vertices and %llu triangles",
                        path, (unsigned long long)vertices, (unsigned long long)triangles);
    }

    uint32_t base = 0, t = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const struct aiMesh *mesh = scene->mMeshes[m];
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            float *p = out->positions + 3u * ((size_t)base + v);
            p[0] = mesh->mVertices[v].x;
            p[1] = mesh->mVertices[v].y;
            p[2] = mesh->mVertices[v].z;
            if (normals) {
                float *n = out->normals + 3u * ((size_t)base + v);
                n[0] = mesh->mNormals[v].x;
                n[1] = mesh->mNormals[v].y;
                n[2] = mesh->mNormals[v].z;
            }
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const struct aiFace *face = &mesh->mFaces[f];
            if (face->mNumIndices != 3u) continue; /* points and lines left by the importer */
            for (unsigned c = 0; c < 3u; ++c) {
                unsigned i = face->mIndices[c];
                if (i >= mesh->mNumVertices) { /* Assimp validates this; a cheap second look */
                    dwvs_mesh_data_free(out);
                    return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': a face refers to vertex %u of %u", path,
                                    i, mesh->mNumVertices);
                }
                out->indices[3u * (size_t)t + c] = base + i;
                if (uvs) {
                    out->uvs[6u * (size_t)t + 2u * c] = mesh->mTextureCoords[0][i].x;
                    out->uvs[6u * (size_t)t + 2u * c + 1u] = mesh->mTextureCoords[0][i].y;
                }
            }
            ++t;
        }
        base += mesh->mNumVertices;
    }
    return DWV_SUCCESS;
}

dwv_result_t dwvs_mesh_file_read(const char *path, dwvs_mesh_data *mesh)
{
    memset(mesh, 0, sizeof *mesh);
    if (!has_extension(path, ".obj") && !has_extension(path, ".ply"))
        return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': only .obj and .ply files are read", path);
    /* Assimp's own message for a missing file is vague; say what the system said. */
    struct stat st;
    if (stat(path, &st) != 0)
        return dwv_fail(DWV_ERROR_IO, "mesh file '%s': %s", path, strerror(errno));
    if (!S_ISREG(st.st_mode)) return dwv_fail(DWV_ERROR_IO, "mesh file '%s': not a regular file", path);
    FILE *probe = fopen(path, "rb");
    if (!probe) return dwv_fail(DWV_ERROR_IO, "mesh file '%s': %s", path, strerror(errno));
    fclose(probe);
    if (has_extension(path, ".ply")) DWV_TRY(dwvs_ply_check(path));

    /* Bake the node hierarchy into the vertices; drop points and lines; let Assimp check its own
     * output (indices in range and the like). */
    const unsigned flags = aiProcess_PreTransformVertices | aiProcess_SortByPType | aiProcess_ValidateDataStructure;
    struct aiPropertyStore *props = aiCreatePropertyStore();
    if (!props) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "mesh file '%s': no memory for the importer", path);
    aiSetImportPropertyInteger(props, AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);

    pthread_mutex_lock(&assimp_lock);
    const struct aiScene *scene = aiImportFileExWithProperties(path, flags, NULL, props);
    /* Triangulate only when a face has more than 3 corners: Assimp 5.2's triangulation asserts
     * (and aborts the process) on a mesh flagged as polygons that holds only triangles, which its
     * PLY reader can produce (found by tests/fuzz/fuzz_mesh_file). */
    if (scene && has_polygons(scene)) scene = aiApplyPostProcessing(scene, aiProcess_Triangulate);
    /* Then join identical vertices (OBJ corners come one vertex each), so that smooth normals are
     * shared. Not with a NaN or infinity in the file: the join would merge such a vertex into
     * another one and hide it, where the scene's own check should refuse it. */
    if (scene && all_finite(scene)) scene = aiApplyPostProcessing(scene, aiProcess_JoinIdenticalVertices);
    char why[256] = "";
    if (!scene) assimp_message(why, sizeof why);
    pthread_mutex_unlock(&assimp_lock);
    aiReleasePropertyStore(props);

    if (!scene) return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': %s", path, why);
    dwv_result_t result;
    if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)
        result = dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': no mesh in it", path);
    else
        result = convert(scene, path, mesh);
    aiReleaseImport(scene);
    return result;
}
