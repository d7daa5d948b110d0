/* libFuzzer target: mesh files. The first byte picks OBJ (even) or PLY (odd) (or the environment
 * variable DWV_FUZZ_MESH_KIND=obj / ply fixes it); the rest is written to a file of that kind and
 * read by dwvs_mesh_file_read (src/scenefile/mesh_file.c: our checks, then Assimp), the internal call
 * that dwv_scene_load makes for each mesh file, so that a run does not pay for building a scene.
 * Any file must give arrays that keep their promises (indices below the vertex count) or a
 * message, never a crash.
 * Run: build-fuzz/tests/fuzz/fuzz_mesh_file -max_len=8192 new_corpus/ tests/fuzz/corpus/mesh_file/ */
#define _POSIX_C_SOURCE 200809L
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dwivedi.h>
#include "scenefile/mesh_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char folder[64];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    if (!folder[0]) {
        snprintf(folder, sizeof folder, "/tmp/dwv_fuzz_mesh_XXXXXX");
        if (!mkdtemp(folder)) abort();
    }
    const char *only = getenv("DWV_FUZZ_MESH_KIND");
    const char *extension = only && (!strcmp(only, "obj") || !strcmp(only, "ply")) ? only
                            : (data[0] & 1u)                                        ? "ply"
                                                                                    : "obj";
    char path[128];
    snprintf(path, sizeof path, "%s/mesh.%s", folder, extension);
    FILE *file = fopen(path, "wb");
    if (!file) abort();
    if (size > 1 && fwrite(data + 1, 1, size - 1, file) != size - 1) abort();
    fclose(file);
    dwvs_mesh_data mesh;
    dwv_result_t r = dwvs_mesh_file_read(path, &mesh);
    if (r == DWV_SUCCESS) {
        if (mesh.vertex_count < 1u || mesh.triangle_count < 1u || !mesh.positions || !mesh.indices) __builtin_trap();
        for (size_t i = 0; i < 3u * (size_t)mesh.triangle_count; ++i)
            if (mesh.indices[i] >= mesh.vertex_count) __builtin_trap();
        dwvs_mesh_data_free(&mesh);
    } else if (!dwv_last_error_message()[0]) {
        __builtin_trap();
    }
    return 0;
}
