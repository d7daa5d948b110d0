#include "bake/pixel_filter.h"

#include <math.h>

#include "dwivedi.h"

/* Steps of the cumulative integral per table level (the trapezoid rule on the shape: its error is
 * far below the linear interpolation's between levels). */
#define INTEGRAL_STEPS_PER_LEVEL 16u
#define TWO_PI 6.283185307179586476925

double dwvb_pixel_filter_radius(int kind, double width)
{
    if (kind == DWV_PIXEL_FILTER_GAUSSIAN) return 1.5 * width;
    if (kind == DWV_PIXEL_FILTER_BLACKMAN_HARRIS) return width;
    return 0.5 * width;
}

double dwvb_pixel_filter_shape(int kind, double width, double x)
{
    if (!(fabs(x) <= dwvb_pixel_filter_radius(kind, width))) return 0.0;
    if (kind == DWV_PIXEL_FILTER_GAUSSIAN) return exp(-8.0 * x * x / (width * width));
    if (kind == DWV_PIXEL_FILTER_BLACKMAN_HARRIS) {
        double t = TWO_PI * (x / (2.0 * width) + 0.5);
        return 0.35875 - 0.48829 * cos(t) + 0.14128 * cos(2.0 * t) - 0.01168 * cos(3.0 * t);
    }
    return 1.0;
}

void dwvb_pixel_filter_init(dwvb_pixel_filter *filter, int kind, double width)
{
    if (!(width > 0.0)) width = 1.0;
    const unsigned levels = DWVB_PIXEL_FILTER_TABLE, steps = levels * INTEGRAL_STEPS_PER_LEVEL;
    double radius = dwvb_pixel_filter_radius(kind, width);
    filter->unit_box = kind == DWV_PIXEL_FILTER_BOX && width == 1.0;
    filter->radius = radius;
    if (kind == DWV_PIXEL_FILTER_BOX) {
        for (unsigned i = 0; i <= levels; ++i) filter->offsets[i] = width * ((double)i / levels - 0.5);
        return;
    }
    /* The whole integral first, then each level's offset where the running integral reaches its
     * share, linear within the step that crosses it. */
    double h = 2.0 * radius / steps, total = 0.0;
    for (unsigned k = 0; k < steps; ++k)
        total += 0.5 * h * (dwvb_pixel_filter_shape(kind, width, -radius + k * h) +
                            dwvb_pixel_filter_shape(kind, width, -radius + (k + 1u) * h));
    filter->offsets[0] = -radius;
    filter->offsets[levels] = radius;
    double running = 0.0, left = dwvb_pixel_filter_shape(kind, width, -radius);
    unsigned k = 0;
    for (unsigned i = 1; i < levels; ++i) {
        double target = total * (double)i / levels;
        for (;;) {
            double right = dwvb_pixel_filter_shape(kind, width, -radius + (k + 1u) * h);
            double area = 0.5 * h * (left + right);
            if (running + area >= target || k + 1u == steps) {
                double share = area > 0.0 ? (target - running) / area : 0.0;
                filter->offsets[i] = -radius + (k + fmin(fmax(share, 0.0), 1.0)) * h;
                break;
            }
            running += area;
            left = right;
            ++k;
        }
    }
}

double dwvb_pixel_filter_sample(const dwvb_pixel_filter *filter, double u)
{
    double t = u * DWVB_PIXEL_FILTER_TABLE;
    unsigned i = t >= DWVB_PIXEL_FILTER_TABLE ? DWVB_PIXEL_FILTER_TABLE - 1u : (unsigned)t;
    double f = t - i;
    return filter->offsets[i] + f * (filter->offsets[i + 1u] - filter->offsets[i]);
}

double dwvb_pixel_filter_pdf(const dwvb_pixel_filter *filter, double x)
{
    if (!(x >= filter->offsets[0] && x < filter->offsets[DWVB_PIXEL_FILTER_TABLE])) return 0.0;
    unsigned low = 0, high = DWVB_PIXEL_FILTER_TABLE; /* offsets[low] <= x < offsets[high] */
    while (high - low > 1u) {
        unsigned mid = (low + high) / 2u;
        if (filter->offsets[mid] <= x) low = mid;
        else high = mid;
    }
    double span = filter->offsets[low + 1u] - filter->offsets[low];
    return span > 0.0 ? 1.0 / (DWVB_PIXEL_FILTER_TABLE * span) : 0.0;
}
