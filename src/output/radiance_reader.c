/* Radiance RGBE pictures, after the format's description ("The RADIANCE Picture File Format",
 * G. Ward, Radiance reference notes): a text header ending at an empty line, a resolution line,
 * then scanlines of 4-byte RGBE texels, each scanline either flat (with the old format's
 * repeat markers 1 1 1 n) or, for widths 8 to 32767, "new" run-length encoded: 2 2 w_hi w_lo,
 * then the four components one after another, each as runs (a count byte > 128: count - 128
 * copies of the next byte; else that many literal bytes). */
#include "radiance_reader.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int dwvo_file_is_radiance(const char *path)
{
    char head[2];
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    size_t got = fread(head, 1, sizeof head, f);
    fclose(f);
    return got == 2u && head[0] == '#' && head[1] == '?';
}

/* Reads one header line (without its newline) into `line`; -1 at the end of the file or on a
 * line longer than the buffer. */
static int read_line(FILE *f, char *line, size_t size)
{
    if (!fgets(line, (int)size, f)) return -1;
    size_t n = strlen(line);
    if (n == 0u || line[n - 1u] != '\n') return -1;
    line[n - 1u] = '\0';
    return 0;
}

/* One scanline of `width` RGBE texels into `rgbe` (4 bytes a texel); 0 or -1 for a damaged one. */
static int read_scanline(FILE *f, unsigned char *rgbe, uint32_t width)
{
    unsigned char head[4];
    if (fread(head, 1, 4, f) != 4u) return -1;
    if (width >= 8u && width <= 0x7fffu && head[0] == 2u && head[1] == 2u && !(head[2] & 0x80u)) {
        if (((uint32_t)head[2] << 8 | head[3]) != width) return -1;
        for (int c = 0; c < 4; ++c)
            for (uint32_t x = 0; x < width;) {
                int count = fgetc(f);
                if (count == EOF || count == 0) return -1;
                if (count > 128) {
                    int value = fgetc(f);
                    count -= 128;
                    if (value == EOF || (uint32_t)count > width - x) return -1;
                    for (int k = 0; k < count; ++k) rgbe[4u * x++ + (uint32_t)c] = (unsigned char)value;
                } else {
                    if ((uint32_t)count > width - x) return -1;
                    for (int k = 0; k < count; ++k) {
                        int value = fgetc(f);
                        if (value == EOF) return -1;
                        rgbe[4u * x++ + (uint32_t)c] = (unsigned char)value;
                    }
                }
            }
        return 0;
    }
    /* Flat texels; 1 1 1 n repeats the previous texel n << shift times (shift grows by 8 for
     * consecutive markers). */
    int shift = 0, head_used = 0;
    for (uint32_t x = 0; x < width;) {
        unsigned char *t = rgbe + 4u * x;
        if (!head_used) {
            memcpy(t, head, 4);
            head_used = 1;
        } else if (fread(t, 1, 4, f) != 4u) {
            return -1;
        }
        if (t[0] == 1u && t[1] == 1u && t[2] == 1u) {
            if (x == 0u || shift > 16) return -1;
            uint64_t repeat = (uint64_t)t[3] << shift;
            if (repeat > width - x) return -1;
            for (uint64_t k = 0; k < repeat; ++k) memcpy(rgbe + 4u * (x + k), rgbe + 4u * (x - 1u), 4);
            x += (uint32_t)repeat;
            shift += 8;
        } else {
            shift = 0;
            ++x;
        }
    }
    return 0;
}

dwv_result_t dwvo_read_radiance(const char *path, uint32_t max_side, uint64_t max_texels, uint32_t *width,
                                uint32_t *height, float **pixels, char *message, size_t size)
{
    *pixels = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(message, size, "cannot read Radiance picture '%s': %s", path, strerror(errno));
        return DWV_ERROR_IO;
    }
    char line[512];
    const char *problem = NULL;
    if (read_line(f, line, sizeof line) || line[0] != '#' || line[1] != '?') problem = "no '#?' first line";
    while (!problem) {
        if (read_line(f, line, sizeof line)) problem = "its header does not end (no empty line)";
        else if (line[0] == '\0') break;
        else if (strncmp(line, "FORMAT=", 7) == 0 && strcmp(line + 7, "32-bit_rle_rgbe") != 0)
            problem = "its FORMAT is not 32-bit_rle_rgbe (XYZE pictures are not read)";
    }
    long long h = 0, w = 0;
    char tail = 0;
    if (!problem && (read_line(f, line, sizeof line) || sscanf(line, "-Y %lld +X %lld%c", &h, &w, &tail) != 2))
        problem = "its resolution line is not \"-Y height +X width\" (the standard orientation; others are not read)";
    if (problem) {
        fclose(f);
        snprintf(message, size, "cannot read Radiance picture '%s': %s", path, problem);
        return DWV_ERROR_FORMAT;
    }
    if (w < 1 || h < 1 || w > (long long)max_side || h > (long long)max_side ||
        (uint64_t)w * (uint64_t)h > max_texels) {
        fclose(f);
        snprintf(message, size, "Radiance picture '%s' is %lld x %lld pixels (1 to %u a side, at most %llu in all)",
                 path, w, h, max_side, (unsigned long long)max_texels);
        return DWV_ERROR_FORMAT;
    }
    float *data = malloc((size_t)w * (size_t)h * 3u * sizeof *data);
    unsigned char *scan = malloc((size_t)w * 4u);
    if (!data || !scan) {
        fclose(f);
        free(data);
        free(scan);
        snprintf(message, size, "no memory for Radiance picture '%s' (%lld x %lld)", path, w, h);
        return DWV_ERROR_OUT_OF_MEMORY;
    }
    for (long long y = 0; y < h; ++y) {
        if (read_scanline(f, scan, (uint32_t)w)) {
            fclose(f);
            free(data);
            free(scan);
            snprintf(message, size, "cannot read Radiance picture '%s': scanline %lld of %lld is damaged or missing",
                     path, y, h);
            return DWV_ERROR_FORMAT;
        }
        /* The file's first scanline is the top row (-Y): it is row h - 1 here. */
        float *row = data + (size_t)(h - 1 - y) * (size_t)w * 3u;
        for (long long x = 0; x < w; ++x) {
            const unsigned char *t = scan + 4 * x;
            float scale = t[3] == 0u ? 0.0f : ldexpf(1.0f, (int)t[3] - 136);
            for (int c = 0; c < 3; ++c) row[3 * x + c] = t[3] == 0u ? 0.0f : ((float)t[c] + 0.5f) * scale;
        }
    }
    fclose(f);
    free(scan);
    *width = (uint32_t)w;
    *height = (uint32_t)h;
    *pixels = data;
    return DWV_SUCCESS;
}
