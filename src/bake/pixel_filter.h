#ifndef DWV_BAKE_PIXEL_FILTER_H
#define DWV_BAKE_PIXEL_FILTER_H

/* Cycles' pixel filters for camera samples (capi's dwv_pixel_filter_t): each axis' offset from the
 * pixel's centre is drawn from the filter's inverse cumulative distribution, tabulated at
 * DWVB_PIXEL_FILTER_TABLE + 1 levels and interpolated linearly (Cycles tabulates it too, at 1024
 * levels: film.cpp's filter_table). */

#define DWVB_PIXEL_FILTER_TABLE 1024u

typedef struct dwvb_pixel_filter {
    /* The box of one pixel: the sample lies at x + u, bit for bit as before pixel filters. */
    int unit_box;
    double radius; /* pixels: the offsets lie in [-radius, radius] */
    /* offsets[i]: the offset below which a share i / DWVB_PIXEL_FILTER_TABLE of the samples lie */
    double offsets[DWVB_PIXEL_FILTER_TABLE + 1u];
} dwvb_pixel_filter;

/* The filter's half extent in pixels: w / 2 (box), 1.5 w (Gaussian), w (Blackman-Harris). */
double dwvb_pixel_filter_radius(int kind, double width);
/* The filter's shape at offset x (capi's formulas, unnormalised, 1 at the centre, 0 beyond the
 * radius). */
double dwvb_pixel_filter_shape(int kind, double width, double x);
/* The table of `kind` (DWV_PIXEL_FILTER_*) of width `width` pixels (0: one pixel). */
void dwvb_pixel_filter_init(dwvb_pixel_filter *filter, int kind, double width);
/* The offset from the pixel's centre of uniform number u in [0, 1). */
double dwvb_pixel_filter_sample(const dwvb_pixel_filter *filter, double u);
/* The density dwvb_pixel_filter_sample draws offsets x with (constant between table levels: the
 * shape normalised, to the table's resolution). */
double dwvb_pixel_filter_pdf(const dwvb_pixel_filter *filter, double x);

#endif
