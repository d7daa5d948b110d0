/* The pixel filters' names (dwv_pixel_filter_name / dwv_pixel_filter_from_name), the one table the
 * scene file, the CLI and the shim read: every DWV_PIXEL_FILTER_* round-trips under the name the
 * scene format documents, values that are no filter have no name, and a refused name leaves the
 * result alone with a message that quotes it and lists every accepted name. */
#include <stdint.h>
#include <string.h>

#include "api_checks.h"
#include "check.h"
#include <dwivedi.h>

static void test_round_trip(void)
{
    static const struct {
        dwv_pixel_filter_t value;
        const char *name; /* as docs/scene-format.md spells them */
    } filters[] = {{DWV_PIXEL_FILTER_BOX, "box"},
                   {DWV_PIXEL_FILTER_GAUSSIAN, "gaussian"},
                   {DWV_PIXEL_FILTER_BLACKMAN_HARRIS, "blackman_harris"}};
    for (size_t i = 0; i < sizeof filters / sizeof filters[0]; ++i) {
        const char *name = dwv_pixel_filter_name(filters[i].value);
        CHECK(name && strcmp(name, filters[i].name) == 0, "name of %d: %s", (int)filters[i].value,
              name ? name : "NULL");
        dwv_pixel_filter_t value = -7;
        CHECK(dwv_pixel_filter_from_name(filters[i].name, &value) == DWV_SUCCESS && value == filters[i].value,
              "%s read as %d: %s", filters[i].name, (int)value, dwv_last_error_message());
    }
    static const dwv_pixel_filter_t no_filters[] = {DWV_PIXEL_FILTER_BLACKMAN_HARRIS + 1, -1, INT32_MIN, INT32_MAX};
    for (size_t i = 0; i < sizeof no_filters / sizeof no_filters[0]; ++i)
        CHECK(dwv_pixel_filter_name(no_filters[i]) == NULL, "%d has a name", (int)no_filters[i]);
}

/* from_name refuses `name` with `code`, leaves the result as it was and, for an unknown name,
 * quotes it and lists every filter's name from dwv_pixel_filter_name. */
static void expect_refused(const char *what, const char *name, dwv_result_t code)
{
    dwv_pixel_filter_t value = -7;
    prime_message();
    dwv_result_t r = dwv_pixel_filter_from_name(name, &value);
    const char *message = dwv_last_error_message();
    CHECK(r == code && value == -7, "%s: result %d, value %d (%s)", what, (int)r, (int)value, message);
    CHECK(fresh_message_with("dwv_pixel_filter_from_name"), "%s: message '%s'", what, message);
    if (code != DWV_ERROR_UNKNOWN_NAME) return;
    char quoted[80];
    snprintf(quoted, sizeof quoted, "'%s'", name);
    CHECK(strstr(message, quoted) != NULL, "%s: '%s' does not quote %s", what, message, quoted);
    for (dwv_pixel_filter_t f = DWV_PIXEL_FILTER_BOX; dwv_pixel_filter_name(f); ++f)
        CHECK(strstr(message, dwv_pixel_filter_name(f)) != NULL, "%s: '%s' does not list %s", what, message,
              dwv_pixel_filter_name(f));
}

static void test_refusals(void)
{
    expect_refused("unknown", "mitchell", DWV_ERROR_UNKNOWN_NAME);
    expect_refused("capitals", "Box", DWV_ERROR_UNKNOWN_NAME);
    expect_refused("Blender's enum spelling", "BLACKMAN_HARRIS", DWV_ERROR_UNKNOWN_NAME);
    expect_refused("a prefix", "gauss", DWV_ERROR_UNKNOWN_NAME);
    expect_refused("empty", "", DWV_ERROR_UNKNOWN_NAME);
    expect_refused("NULL name", NULL, DWV_ERROR_NULL_POINTER);
    prime_message();
    CHECK(dwv_pixel_filter_from_name("box", NULL) == DWV_ERROR_NULL_POINTER &&
              fresh_message_with("pixel_filter"),
          "NULL result: %s", dwv_last_error_message());
}

int main(void)
{
    test_round_trip();
    test_refusals();
    return check_report("test_pixel_filter_names");
}
