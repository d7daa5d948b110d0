/* A bake's guides per mesh (guides.h): techniques, channel walks, closest-point needs, features. */
#include "bake/guides.h"

/* Which meshes' walks the bake can reach: all for a camera, the one mesh for a UV bake (every
 * mesh where indirect light can reach it). */
static int mesh_used(const dwvb_bake *bake, uint32_t m)
{
    return bake->options.target == DWV_BAKE_CAMERA || m == bake->options.uv_mesh || bake->options.max_bounces > 0u;
}

void dwvb_bake_update_features(dwvb_bake *bake)
{
    const dwvb_scene *scene = bake->scene;
    uint32_t features = scene->features & ~(uint32_t)(DWV_FEATURE_INCIDENT_PATCHES | DWV_FEATURE_CLOSEST_POINT |
                                                      DWV_FEATURE_SHEET);
    int rgb = 0;
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const dwvb_material *material = &scene->shading[scene->meshes[m].material_id];
        if (!material->subsurface || !mesh_used(bake, m)) continue;
        if (bake->needs_closest[m]) features |= DWV_FEATURE_CLOSEST_POINT;
        const dwvw_guide *guides = bake->channel_walks[m] ? &bake->channel_guides[3u * m] : &bake->guides[m];
        for (int c = 0; c < (bake->channel_walks[m] ? 3 : 1); ++c) {
            if (bake->channel_walks[m] && !(material->walk_scale[c] > 0.0)) continue;
            if (guides[c].q_incident > 0.0 && guides[c].patch_count > 0) features |= DWV_FEATURE_INCIDENT_PATCHES;
            if (guides[c].q_classical < 1.0) features |= DWV_FEATURE_GUIDED;
            if (guides[c].q_sheet > 0.0) features |= DWV_FEATURE_SHEET;
        }
        if (bake->channel_walks[m]) features |= DWV_FEATURE_CHANNEL_WALKS;
        else if (!material->grey) rgb = 1;
    }
    /* Three-channel walks only where some mesh walks its channels together. */
    if (!rgb) features &= ~(uint32_t)DWV_FEATURE_RGB_WALKS;
    bake->features = features;
}

int dwvb_mesh_needs_closest(const dwvb_material *material, int channel_walks, const dwvw_guide *guide,
                            const dwvw_guide *channel_guides)
{
    if (!channel_walks) return dwvw_guide_needs_closest(guide);
    int needs = 0;
    for (int c = 0; c < 3; ++c)
        if (material->walk_scale[c] > 0.0) needs |= dwvw_guide_needs_closest(&channel_guides[c]);
    return needs;
}

/* The technique of mesh m's walks in a medium whose largest albedo is `albedo`. */
static dwvw_technique medium_technique(const dwvb_bake *bake, uint32_t m, double albedo)
{
    dwvw_technique technique = (dwvw_technique)bake->options.technique;
    /* Incident guiding needs lit patches; where a mesh has none (no light reaches it) it
     * aims at the closest surface point instead, as auto does. */
    if (technique == DWVW_INCIDENT && bake->scene->patch_count[m] == 0) technique = DWVW_CLOSEST;
    /* Auto leaves media to classical sampling below albedo 0.2 (dwvw_auto_weights); Cycles'
     * floor raises every lower albedo to exactly 0.2, where walks average about 1.25 events
     * and guiding has nothing to gain, so those stay classical too. */
    if (technique == DWVW_AUTO && albedo <= DWVB_MIN_ALPHA) technique = DWVW_CLASSICAL;
    return technique;
}

void dwvb_bake_setup_guides(dwvb_bake *bake)
{
    const dwvb_scene *scene = bake->scene;
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const dwvb_material *material = &scene->shading[scene->meshes[m].material_id];
        if (!material->subsurface) continue;
        dwvw_technique technique = medium_technique(bake, m, material->medium.albedo[material->medium.guide_channel]);
        dwvw_guide_init(&bake->guides[m], technique, &material->medium, scene->patches[m], scene->patch_count[m]);
        /* Channel walks' guides: each channel's own medium, with the technique its albedo gets. */
        int auto_walks = technique == DWVW_AUTO;
        for (int c = 0; c < 3; ++c) {
            if (material->grey || !(material->walk_scale[c] > 0.0)) continue;
            const dwvw_medium *medium = &material->channel_medium[c];
            dwvw_technique own = medium_technique(bake, m, medium->albedo[0]);
            auto_walks |= own == DWVW_AUTO;
            dwvw_guide_init(&bake->channel_guides[3u * m + (uint32_t)c], own, medium, scene->patches[m],
                            scene->patch_count[m]);
        }
        bake->channel_walks[m] = !material->grey && bake->options.channel_walks == DWV_CHANNEL_WALKS_SEPARATE;
        bake->needs_closest[m] = dwvb_mesh_needs_closest(material, bake->channel_walks[m], &bake->guides[m],
                                                         &bake->channel_guides[3u * m]);
        /* Above that albedo the pilot chooses (dwvb_pilot_choose) the technique and, unless the option
         * fixes it, whether the channels walk apart; the mixture stays where it cannot. */
        bake->auto_choice[m] = bake->options.technique == DWV_TECHNIQUE_AUTO && mesh_used(bake, m) &&
                               (auto_walks || (!material->grey && bake->options.channel_walks == DWV_CHANNEL_WALKS_AUTO));
    }
    dwvb_bake_update_features(bake);
}
