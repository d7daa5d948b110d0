/* A bake's guides per mesh: the technique each medium walks with (the option's, where the mesh
 * can use it), whether its channels walk apart, whether its walks query the closest surface
 * point, which meshes auto's pilot decides (pilot.h), and the features all that adds up to. */
#ifndef DWV_BAKE_GUIDES_H
#define DWV_BAKE_GUIDES_H

#include "bake/bake_internal.h"

/* Sets the guides, channel guides, channel walks, closest-point needs, auto's choices and the
 * features of a bake whose scene, options and arrays are in place. */
void dwvb_bake_setup_guides(dwvb_bake *bake);
/* The features the bake's guides use, from those of the scene. */
void dwvb_bake_update_features(dwvb_bake *bake);
/* Whether mesh m's walks query the closest surface point, for the guides its samples use. */
int dwvb_mesh_needs_closest(const dwvb_material *material, int channel_walks, const dwvw_guide *guide,
                            const dwvw_guide *channel_guides);

#endif
