// Display images through OpenColorIO 2 (the only C++ in dwivedi: OCIO has no C API).
//
// The processing is Blender's colour management (its OCIO view pipeline, which OCIO 2 offers as
// LegacyViewingPipeline):
//   0. un-premultiply: rgb / alpha where alpha is neither 0 nor 1 (see straight_colour)
//   1. exposure in scene linear: rgb * 2^exposure (alpha untouched)
//   2. the look, if one is asked for (in the look's process space)            looks override
//   3. the display/view transform from the config's scene_linear role          DisplayViewTransform
//   4. gamma on the display values: display^(1/gamma) (negative values -> 0)   display CC
// then [0, 1] clamping and rounding to 8 bits (v -> floor(255 v + 1/2)).
//
// Every OCIO call sits inside one try block per entry point: exceptions become a dwv_result_t
// and a message; nothing is thrown across the C boundary.
#include "display.h"

#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <sstream>
#include <string>
#include <vector>

namespace OCIO = OCIO_NAMESPACE;

namespace {

struct Failure {
    dwv_result_t result;
    std::string message;
};

[[noreturn]] void fail(dwv_result_t result, const std::string &message)
{
    throw Failure{result, message};
}

// The config and where it came from (for messages).
struct LoadedConfig {
    OCIO::ConstConfigRcPtr config;
    std::string origin;
};

OCIO::ConstConfigRcPtr load_file(const std::string &path, const std::string &origin)
{
    // Check readability ourselves first: OCIO's message for a missing file does not say why.
    FILE *probe = std::fopen(path.c_str(), "rb");
    if (!probe) fail(DWV_ERROR_IO, "cannot read the OCIO config " + origin + ": " + std::strerror(errno));
    std::fclose(probe);
    try {
        return OCIO::Config::CreateFromFile(path.c_str());
    } catch (const OCIO::Exception &e) {
        fail(DWV_ERROR_FORMAT, "the OCIO config " + origin + " is not valid: " + e.what());
    }
}

// The built-in config, parsed once (C++11 makes the initialisation thread-safe); an OCIO config is
// immutable and safe to share between threads.
OCIO::ConstConfigRcPtr default_config()
{
    static const OCIO::ConstConfigRcPtr config = [] {
        std::istringstream text(std::string(reinterpret_cast<const char *>(dwvo_default_ocio_config),
                                             dwvo_default_ocio_config_size));
        return OCIO::Config::CreateFromStream(text);
    }();
    return config;
}

LoadedConfig load_config(const char *explicit_path)
{
    if (explicit_path && explicit_path[0])
        return {load_file(explicit_path, "'" + std::string(explicit_path) + "'"),
                "'" + std::string(explicit_path) + "'"};
    const char *env = std::getenv("OCIO");
    if (env && env[0]) {
        std::string origin = "'" + std::string(env) + "' (from $OCIO)";
        return {load_file(env, origin), origin};
    }
    return {default_config(), "(dwivedi's built-in default)"};
}

std::string join(const std::vector<std::string> &names)
{
    std::string out;
    for (const std::string &name : names) {
        if (!out.empty()) out += ", ";
        out += "'" + name + "'";
    }
    return out.empty() ? "none" : out;
}

void require_name(const std::vector<std::string> &valid, const std::string &name, const char *kind,
                  const std::string &where)
{
    for (const std::string &v : valid)
        if (v == name) return;
    fail(DWV_ERROR_UNKNOWN_NAME,
         "unknown " + std::string(kind) + " '" + name + "'" + where + "; valid: " + join(valid));
}

// The largest magnitude the view transforms get: the largest half float. Every SDR view has
// saturated long before it, and tone curves with powers and logarithms (the ACES RRT) overflow
// to NaN on values near FLT_MAX.
const float max_scene_value = 65504.0f;

// NaN -> 0, anything else clamped to [-max_scene_value, max_scene_value] (so +infinity shows as
// the brightest value the view makes and -infinity as the darkest).
inline float sane(float v)
{
    if (std::isnan(v)) return 0.0f;
    return std::min(std::max(v, -max_scene_value), max_scene_value);
}

// The colour of a premultiplied pixel as straight (unassociated) colour: rgb / alpha, except where
// alpha is 0 or 1 (kept as they are). This is what Blender does before its view transform when it
// writes a display image (Image.save_render): OCIO_cpuProcessorApply_predivide divides by alpha
// under exactly that condition, runs the processor and multiplies by alpha again, and
// IMB_buffer_byte_from_float divides once more (premul_to_straight_v4_v4) before quantising; so
// the bytes are display(rgb / alpha) with alpha as it was. PNG stores straight colour too.
inline float straight_colour(float premultiplied, float alpha)
{
    return (alpha == 0.0f || alpha == 1.0f) ? premultiplied : premultiplied / alpha;
}

// Clamp to [0, 1] (NaN -> 0) and round to the nearest of 256 levels.
inline uint8_t quantise(float v)
{
    if (!(v > 0.0f)) return 0;
    if (v >= 1.0f) return 255;
    return static_cast<uint8_t>(v * 255.0f + 0.5f);
}

void to_display(const float *rgba, uint32_t width, uint32_t height, const dwv_display_options_t *options,
                uint8_t *out)
{
    LoadedConfig loaded = load_config(options->config_path);
    const OCIO::ConstConfigRcPtr &config = loaded.config;
    const std::string in_config = " in the OCIO config " + loaded.origin;

    OCIO::ConstColorSpaceRcPtr linear = config->getColorSpace(OCIO::ROLE_SCENE_LINEAR);
    if (!linear) fail(DWV_ERROR_FORMAT, "the OCIO config " + loaded.origin + " has no scene_linear role");

    std::vector<std::string> displays;
    for (int i = 0; i < config->getNumDisplays(); ++i) displays.emplace_back(config->getDisplay(i));
    std::string display = options->display ? options->display : config->getDefaultDisplay();
    require_name(displays, display, "display", in_config);

    std::vector<std::string> views;
    for (int i = 0; i < config->getNumViews(display.c_str()); ++i)
        views.emplace_back(config->getView(display.c_str(), i));
    std::string view = options->view ? options->view : config->getDefaultView(display.c_str());
    require_name(views, view, "view", " of display '" + display + "'" + in_config);

    auto dvt = OCIO::DisplayViewTransform::Create();
    dvt->setSrc(linear->getName());
    dvt->setDisplay(display.c_str());
    dvt->setView(view.c_str());
    auto pipeline = OCIO::LegacyViewingPipeline::Create();
    pipeline->setDisplayViewTransform(dvt);

    // Exposure: rgb * 2^exposure in scene linear, alpha kept (Blender's exposure, a gain in stops).
    // Applied here rather than as an OCIO matrix so that the clamp below comes after it.
    const float gain = static_cast<float>(std::exp2(options->exposure));
    if (!std::isfinite(gain) || gain == 0.0f)
        fail(DWV_ERROR_OUT_OF_RANGE, "exposure " + std::to_string(options->exposure) +
                                         " stops gives a gain outside the float range");

    // NULL keeps the view's own looks (the config's default); "" means none; else one look.
    // "None" is Blender's name for no look (its look menu's first entry, not a look of the
    // config): unless the config has a look of that name, it means what NULL does, as in Blender.
    std::vector<std::string> looks;
    for (int i = 0; i < config->getNumLooks(); ++i) looks.emplace_back(config->getLookNameByIndex(i));
    const bool blender_none = options->look && std::string(options->look) == "None" &&
                              std::find(looks.begin(), looks.end(), "None") == looks.end();
    if (options->look && !blender_none) {
        std::string look = options->look;
        if (!look.empty()) require_name(looks, look, "look", in_config);
        pipeline->setLooksOverrideEnabled(true);
        pipeline->setLooksOverride(look.c_str());
    }

    if (options->gamma != 1.0) {
        // display^(1/gamma) on RGB, as Blender's display gamma; alpha exponent 1.
        auto exponent = OCIO::ExponentTransform::Create();
        const double inverse = 1.0 / options->gamma;
        const double value4[4] = {inverse, inverse, inverse, 1.0};
        exponent->setValue(value4);
        pipeline->setDisplayCC(exponent);
    }

    OCIO::ConstProcessorRcPtr processor = pipeline->getProcessor(config);
    OCIO::ConstCPUProcessorRcPtr cpu = processor->getDefaultCPUProcessor();

    // Strips of rows keep the float buffer small whatever the image size.
    const size_t strip_rows = 64;
    std::vector<float> strip(static_cast<size_t>(width) * 4u * strip_rows);
    for (uint32_t y0 = 0; y0 < height; y0 += static_cast<uint32_t>(strip_rows)) {
        const uint32_t rows = static_cast<uint32_t>(std::min<size_t>(strip_rows, height - y0));
        const size_t values = static_cast<size_t>(width) * 4u * rows;
        const float *source = rgba + static_cast<size_t>(y0) * width * 4u;
        for (size_t i = 0; i < values; i += 4) {
            // sane() again after the division (a tiny alpha can overflow it) and the gain.
            const float alpha = sane(source[i + 3]);
            strip[i + 0] = sane(sane(straight_colour(sane(source[i + 0]), alpha)) * gain);
            strip[i + 1] = sane(sane(straight_colour(sane(source[i + 1]), alpha)) * gain);
            strip[i + 2] = sane(sane(straight_colour(sane(source[i + 2]), alpha)) * gain);
            strip[i + 3] = alpha;
        }
        OCIO::PackedImageDesc desc(strip.data(), static_cast<long>(width), static_cast<long>(rows), 4);
        cpu->apply(desc);
        uint8_t *target = out + static_cast<size_t>(y0) * width * 4u;
        for (size_t i = 0; i < values; ++i) target[i] = quantise(strip[i]); // quantise sends NaN to 0
    }
}

void copy_message(const std::string &text, char *message, size_t size)
{
    if (!message || size == 0) return;
    std::snprintf(message, size, "%s", text.c_str());
}

} // namespace

extern "C" dwv_result_t dwvo_to_display(const float *rgba, uint32_t width, uint32_t height,
                                         const dwv_display_options_t *options, uint8_t *out, char *message,
                                         size_t size)
{
    try {
        to_display(rgba, width, height, options, out);
        return DWV_SUCCESS;
    } catch (const Failure &f) {
        copy_message(f.message, message, size);
        return f.result;
    } catch (const OCIO::Exception &e) {
        copy_message(std::string("OpenColorIO: ") + e.what(), message, size);
        return DWV_ERROR_FORMAT;
    } catch (const std::bad_alloc &) {
        copy_message("out of memory in the display transform", message, size);
        return DWV_ERROR_OUT_OF_MEMORY;
    } catch (const std::exception &e) {
        copy_message(std::string("display transform: ") + e.what(), message, size);
        return DWV_ERROR_INTERNAL;
    } catch (...) {
        copy_message("display transform: an unknown C++ exception", message, size);
        return DWV_ERROR_INTERNAL;
    }
}
