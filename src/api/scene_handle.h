/* dwv_scene_t is the scene object itself; these casts are the only place that says so. */
#ifndef DWV_API_SCENE_HANDLE_H
#define DWV_API_SCENE_HANDLE_H

#include "bake/scene.h"
#include <dwivedi.h>

struct dwv_scene_s {
    dwvb_scene scene;
};

static inline dwv_scene_t *dwv_scene_handle(dwvb_scene *scene)
{
    return (dwv_scene_t *)scene;
}

static inline dwvb_scene *dwv_scene_object(const dwv_scene_t *scene)
{
    return (dwvb_scene *)&((dwv_scene_t *)scene)->scene;
}

#endif
