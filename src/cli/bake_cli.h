/* What `dwivedi bake` (bake.c) shares with its MPI driver (mpi_bake.c): the parsed flags, the
 * scene and options they give, and the outputs' checks and writing. A client of capi only. */
#ifndef DWV_CLI_BAKE_H
#define DWV_CLI_BAKE_H

#include <stdint.h>

#include <dwivedi.h>

typedef struct cli_bake_flags {
    const char *scene_path, *prefix;
    int chunk, budget; /* --samples given; --time or --error given */
    uint64_t first, count;
    dwv_display_options_t display;
    int quiet;
    int mpi;             /* --mpi */
    uint64_t mpi_chunk;  /* --mpi-chunk: samples per work item; 0: chosen from the ranks */
    double mpi_timeout;  /* --mpi-timeout: seconds a rank waits on another beyond baking */
} cli_bake_flags;

#define CLI_MPI_TIMEOUT_DEFAULT 300.0

/* Parses argv (argv[0] the verb) twice around loading the scene: the flags' syntax and the scene
 * path, the scene file (or the default scene) with its settings in *o, then the flags over them.
 * Returns CLI_OK with *scene set, else CLI_USAGE or CLI_FAILED after one line on stderr. */
int cli_bake_load(int argc, char **argv, cli_bake_flags *f, dwv_bake_options_t *o, dwv_scene_t **scene);

/* Whether files can be created beside `prefix` and the display options name what exists; 0, or -1
 * after reporting. */
int cli_bake_check_outputs(const char *prefix, const dwv_display_options_t *display);

/* PREFIX.exr, .png and .json of `image`, each written under a temporary name and renamed into
 * place only when all three are complete; 0, or -1 after reporting (earlier outputs kept).
 * `scene` (NULL for a merge): the baked scene, whose texture memory the JSON reports. */
int cli_bake_write_outputs(const char *prefix, const dwv_image_t *image, const dwv_bake_options_t *o,
                           const dwv_display_options_t *display, const char *scene_name, const dwv_scene_t *scene);

/* `dwivedi bake ... --mpi` (mpi_bake.c, built where CMake finds MPI): the exit code. */
int cli_mpi_bake(int argc, char **argv);

#endif
