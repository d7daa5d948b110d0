/* The bake engine: progressive passes over the pixels (camera view) or texels (UV layout) of a
 * committed scene, each pass split into tiles that a pool of threads takes in turn.
 *
 * Determinism: sample s of pixel p uses random numbers keyed by (seed, p, s) only, and a pixel's
 * samples are added as exact fixed-point integers (bake_internal.h), so the image is the same bit
 * for bit for any thread count, tile order and split into sample ranges (docs/farm.md). Per-tile counters are summed in tile order.
 * Budgets: samples per pixel (passes of 2, 2, 4, 8... samples, so that every pass after the first
 * doubles the count), a time limit checked before each tile (pixels keep the samples they got),
 * and a target relative error checked after each pass. */
#ifndef DWV_BAKE_BAKE_H
#define DWV_BAKE_BAKE_H

#include <stdint.h>

#include "bake/image.h"
#include "bake/scene.h"
#include <dwivedi.h>

typedef struct dwvb_bake dwvb_bake;

/* Starts a bake of a committed scene with validated options (threads resolved: >= 1, tile size
 * and max_events non-zero) on a control thread; the bake holds no reference of its own: the
 * caller keeps the scene alive until dwvb_bake_free. DWV_SUCCESS and *bake, or a code with a
 * message in `message`. */
dwv_result_t dwvb_bake_start(dwvb_scene *scene, const dwv_bake_options_t *options, dwvb_bake **bake,
                             char *message, size_t size);
/* Waits up to `seconds` (negative: forever) for the end; 1 if it ended. */
int dwvb_bake_wait(dwvb_bake *bake, double seconds);
void dwvb_bake_progress(dwvb_bake *bake, dwv_bake_progress_t *progress);
void dwvb_bake_cancel(dwvb_bake *bake);
/* Waits for the end; DWV_SUCCESS hands over the image (once), else the bake's code and message. */
dwv_result_t dwvb_bake_finish(dwvb_bake *bake, dwvb_image **image, char *message, size_t size);
/* Cancels if running, waits, frees. */
void dwvb_bake_free(dwvb_bake *bake);

/* The bake's resolved options. */
const dwv_bake_options_t *dwvb_bake_options(const dwvb_bake *bake);

/* Embree's memory for the scene's geometry, in bytes (for memory per triangle). */
long long dwvb_scene_geometry_bytes(const dwvb_scene *scene);

#endif
