/* Auto's pilot: before a bake's first pass, shades the same pixel samples with each candidate
 * technique and keeps, per mesh that auto decides, the one with the largest efficiency (pilot.c
 * says which candidates, and how their cost is counted). */
#ifndef DWV_BAKE_PILOT_H
#define DWV_BAKE_PILOT_H

#include "bake/bake_internal.h"

/* Runs the pilot and narrows bake->guides; 0 done (or nothing to decide), 1 cancelled or out of
 * time, -1 out of memory. */
int dwvb_pilot_choose(dwvb_bake *bake);

/* The mean chord length 4 V / A of the solid the mesh bounds, or -1 where it bounds none that can
 * be trusted (open, inward-facing, non-finite): pilot.c says why the pilot asks. */
double dwvb_mesh_mean_chord(const dwvg_mesh *mesh);

/* The variance per sample in the image of a pixel group of the pilot (pilot.c): `size` (even)
 * samples of one pixel as a bake takes them, in REPLICATES = 2 independent stratified replicates
 * (even and odd samples, dwvb_bake_sample) whose sums of one channel are replicate_sums; an
 * unbiased estimate of size x the variance of the pixel's mean over its `size` samples. */
double dwvb_pilot_group_variance(const double replicate_sums[REPLICATES], uint32_t size);

#endif
