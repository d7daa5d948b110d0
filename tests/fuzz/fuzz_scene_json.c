/* libFuzzer target: dwv_scene_load_json on arbitrary bytes. Mesh paths resolve against
 * examples/scenes, so that inputs naming its OBJ and PLY files reach Assimp too. The library must
 * never crash, hang or leak, must hand out a scene exactly when it reports success, and must leave
 * a message when it fails.
 * Build: cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang-14 -DDWV_BUILD_FUZZERS=ON
 * Run:   build-fuzz/tests/fuzz/fuzz_scene_json -dict=tests/fuzz/scene_json.dict \
 *          -max_len=4096 new_corpus/ tests/fuzz/corpus/scene_json/ */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <dwivedi.h>

#ifndef DWV_FUZZ_BASE_DIR
#define DWV_FUZZ_BASE_DIR "."
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    dwv_scene_t *scene = NULL;
    dwv_bake_options_t options = DWV_BAKE_OPTIONS_INIT;
    dwv_result_t r = dwv_scene_load_json((const char *)data, size, DWV_FUZZ_BASE_DIR, &scene, &options);
    if (r == DWV_SUCCESS) {
        if (!scene) __builtin_trap();
        /* committed: no more changes */
        double black[3] = {0.0, 0.0, 0.0};
        if (dwv_scene_set_world(scene, black, 0.0) != DWV_ERROR_INVALID_STATE) __builtin_trap();
        if (options.width < 1u || options.height < 1u || options.samples < 1u) __builtin_trap();
        dwv_scene_release(scene);
    } else {
        if (scene) __builtin_trap();
        const char *message = dwv_last_error_message();
        if (!message[0] || strlen(message) >= 512u) __builtin_trap();
    }
    return 0;
}
