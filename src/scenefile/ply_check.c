/* A structural check of PLY files before Assimp reads them.
 *
 * Assimp 5.2's PLY reader trusts the file: a header without end_header, or a binary body shorter
 * than its header says, makes it read past its buffer (found by tests/fuzz/fuzz_mesh_file: a
 * segmentation fault, not an error). So the whole file is walked here first, by the PLY 1.0 rules
 * (Turk's format description, as Paul Bourke's page gives it): a header of "ply", "format",
 * "element", "property", "comment"/"obj_info" lines up to "end_header"; then, for each element
 * instance in order, its properties: fixed-size scalars, or lists of a count followed by that many
 * items. Binary bodies must hold every byte the header implies; ASCII bodies one instance per line
 * with exactly its tokens, each a number. Only a file that passes goes to Assimp. */
#define _POSIX_C_SOURCE 200809L
#include "scenefile/ply_check.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/error.h"
#include "scenefile/mesh_file.h"

#define MAX_HEADER_BYTES (1u << 16)
#define MAX_ELEMENTS 16u
#define MAX_PROPERTIES 32u
#define MAX_LIST_ITEMS 1024u /* a polygon of more corners than this is refused */

enum { FORMAT_ASCII, FORMAT_LITTLE, FORMAT_BIG };

typedef struct property {
    int is_list;
    unsigned count_size; /* list: bytes of the count (an integer type) */
    unsigned item_size;  /* bytes of the scalar or of each list item */
} property;

typedef struct element {
    uint64_t count;
    unsigned property_count;
    property properties[MAX_PROPERTIES];
} element;

typedef struct header {
    int format;
    unsigned element_count;
    element elements[MAX_ELEMENTS];
    size_t body; /* offset of the first body byte */
} header;

/* Bytes of a PLY scalar type (both spellings of PLY 1.0), 0 if unknown; *integer says if it can
 * count a list. */
static unsigned type_size(const char *name, int *integer)
{
    static const struct {
        const char *name;
        unsigned size;
        int integer;
    } types[] = {{"char", 1, 1},  {"uchar", 1, 1},  {"short", 2, 1},   {"ushort", 2, 1},  {"int", 4, 1},
                 {"uint", 4, 1},  {"float", 4, 0},  {"double", 8, 0},  {"int8", 1, 1},    {"uint8", 1, 1},
                 {"int16", 2, 1}, {"uint16", 2, 1}, {"int32", 4, 1},   {"uint32", 4, 1},  {"float32", 4, 0},
                 {"float64", 8, 0}};
    for (size_t i = 0; i < sizeof types / sizeof types[0]; ++i)
        if (strcmp(name, types[i].name) == 0) {
            *integer = types[i].integer;
            return types[i].size;
        }
    return 0;
}

/* Splits a line (NUL-terminated, modified) into at most `max` tokens on spaces and tabs. */
static unsigned split(char *line, char **tokens, unsigned max)
{
    unsigned n = 0;
    char *save = NULL;
    for (char *t = strtok_r(line, " \t", &save); t && n < max; t = strtok_r(NULL, " \t", &save)) tokens[n++] = t;
    return n;
}

/* Element and property names: [A-Za-z_][A-Za-z0-9_]* (Assimp's reader reads numbers out of
 * names that begin with digits, and then asks for gigabytes: found by fuzzing). */
static int is_name(const char *s)
{
    if (!((*s >= 'A' && *s <= 'Z') || (*s >= 'a' && *s <= 'z') || *s == '_')) return 0;
    for (++s; *s; ++s)
        if (!((*s >= 'A' && *s <= 'Z') || (*s >= 'a' && *s <= 'z') || (*s >= '0' && *s <= '9') || *s == '_'))
            return 0;
    return 1;
}

static int parse_count(const char *s, uint64_t *out)
{
    if (!*s) return 0;
    uint64_t v = 0;
    for (; *s; ++s) {
        if (*s < '0' || *s > '9') return 0;
        v = 10u * v + (uint64_t)(*s - '0');
        if (v > DWVS_MESH_MAX_ELEMENTS) return 0;
    }
    *out = v;
    return 1;
}

static dwv_result_t read_header(const char *path, const unsigned char *text, size_t size, header *h)
{
    memset(h, 0, sizeof *h);
    h->format = -1;
    size_t limit = size < MAX_HEADER_BYTES ? size : MAX_HEADER_BYTES;
    size_t at = 0;
    unsigned line_number = 0;
    char line[256];
    while (at < limit) {
        size_t end = at;
        while (end < limit && text[end] != '\n') ++end;
        if (end == limit) break;
        size_t length = end - at;
        if (length && text[end - 1] == '\r') --length;
        ++line_number;
        if (length >= sizeof line)
            return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u is too long", path, line_number);
        memcpy(line, text + at, length);
        line[length] = '\0';
        at = end + 1;
        for (size_t i = 0; i < length; ++i)
            if ((unsigned char)line[i] < 0x20u && line[i] != '\t')
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u has a control character", path,
                                line_number);
        char *tokens[8];
        unsigned n = split(line, tokens, 8);
        if (line_number == 1) {
            if (n != 1 || strcmp(tokens[0], "ply") != 0)
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': not a PLY file (no 'ply' line)", path);
            continue;
        }
        if (n == 0) continue;
        if (strcmp(tokens[0], "comment") == 0 || strcmp(tokens[0], "obj_info") == 0) continue;
        if (strcmp(tokens[0], "format") == 0) {
            if (h->format >= 0 || n != 3 || strcmp(tokens[2], "1.0") != 0)
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u: bad 'format'", path, line_number);
            if (strcmp(tokens[1], "ascii") == 0) h->format = FORMAT_ASCII;
            else if (strcmp(tokens[1], "binary_little_endian") == 0) h->format = FORMAT_LITTLE;
            else if (strcmp(tokens[1], "binary_big_endian") == 0) h->format = FORMAT_BIG;
            else
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u: unknown format", path,
                                line_number);
            continue;
        }
        if (h->format < 0)
            return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u comes before 'format'", path,
                            line_number);
        if (strcmp(tokens[0], "element") == 0) {
            if (n != 3 || h->element_count >= MAX_ELEMENTS || !is_name(tokens[1]))
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u: bad 'element' (or more than %u)",
                                path, line_number, MAX_ELEMENTS);
            element *e = &h->elements[h->element_count++];
            if (!parse_count(tokens[2], &e->count))
                return dwv_fail(DWV_ERROR_FORMAT,
                                "mesh file '%s': PLY header line %u: the count '%.20s' is not a number up to %u", path,
                                line_number, tokens[2], DWVS_MESH_MAX_ELEMENTS);
            continue;
        }
        if (strcmp(tokens[0], "property") == 0) {
            if (h->element_count == 0)
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u: a property before any element",
                                path, line_number);
            element *e = &h->elements[h->element_count - 1u];
            if (e->property_count >= MAX_PROPERTIES)
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u: more than %u properties", path,
                                line_number, MAX_PROPERTIES);
            property *p = &e->properties[e->property_count++];
            int integer = 0;
            if (!is_name(tokens[n - 1u]))
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u: a property name must be a word",
                                path, line_number);
            if (n == 5 && strcmp(tokens[1], "list") == 0) {
                p->is_list = 1;
                p->count_size = type_size(tokens[2], &integer);
                if (!p->count_size || !integer)
                    return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u: a list count must be an integer type",
                                    path, line_number);
                p->item_size = type_size(tokens[3], &integer);
            } else if (n == 3) {
                p->item_size = type_size(tokens[1], &integer);
            } else {
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u: bad 'property'", path,
                                line_number);
            }
            if (!p->item_size)
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u: unknown property type", path,
                                line_number);
            continue;
        }
        if (strcmp(tokens[0], "end_header") == 0 && n == 1) {
            if (h->format < 0) return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': the PLY header has no 'format'", path);
            for (unsigned i = 0; i < h->element_count; ++i)
                if (h->elements[i].property_count == 0 && h->elements[i].count > 0)
                    return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': a PLY element has no properties", path);
            h->body = at;
            return DWV_SUCCESS;
        }
        return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': PLY header line %u: unknown keyword '%.20s'", path,
                        line_number, tokens[0]);
    }
    return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': no 'end_header' in the first %u bytes", path, MAX_HEADER_BYTES);
}

/* An unsigned list count of `size` bytes at p, in the file's byte order (negative signed counts
 * come out huge and are refused by the caller). */
static uint64_t read_count(const unsigned char *p, unsigned size, int big)
{
    uint64_t v = 0;
    for (unsigned i = 0; i < size; ++i) v |= (uint64_t)p[big ? size - 1u - i : i] << (8u * i);
    return v;
}

static dwv_result_t check_binary(const char *path, const unsigned char *text, size_t size, const header *h)
{
    size_t at = h->body;
    int big = h->format == FORMAT_BIG;
    for (unsigned i = 0; i < h->element_count; ++i) {
        const element *e = &h->elements[i];
        for (uint64_t k = 0; k < e->count; ++k)
            for (unsigned j = 0; j < e->property_count; ++j) {
                const property *p = &e->properties[j];
                uint64_t bytes = p->item_size;
                if (p->is_list) {
                    if (size - at < p->count_size) goto short_body;
                    uint64_t items = read_count(text + at, p->count_size, big);
                    at += p->count_size;
                    /* Empty lists too: Assimp 5.2 turns them into faces of no corners and crashes in
                     * its post-processing (found by fuzzing). */
                    if (items < 1u || items > MAX_LIST_ITEMS)
                        return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': a PLY list of %llu items (1 to %u allowed)",
                                        path, (unsigned long long)items, MAX_LIST_ITEMS);
                    bytes = items * p->item_size;
                }
                if (size - at < bytes) goto short_body;
                at += (size_t)bytes;
            }
    }
    return DWV_SUCCESS;
short_body:
    return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': the PLY body is shorter than its header says (%zu bytes)", path,
                    size);
}

/* Whether s (length n) is a number: an optional sign, then strtod's syntax over the whole token
 * (which takes "nan" and "inf": those reach the scene's check of finite coordinates). */
static int is_number(const unsigned char *s, size_t n)
{
    char token[64];
    if (n == 0 || n >= sizeof token) return 0;
    memcpy(token, s, n);
    token[n] = '\0';
    char *end = NULL;
    (void)strtod(token, &end);
    return end == token + n;
}

/* A list count in an ASCII body: digits only, at most MAX_LIST_ITEMS. */
static int parse_count_token(const unsigned char *s, size_t n, uint64_t *out)
{
    uint64_t v = 0;
    if (n == 0) return 0;
    for (size_t i = 0; i < n; ++i) {
        if (s[i] < '0' || s[i] > '9') return 0;
        v = 10u * v + (uint64_t)(s[i] - '0');
        if (v > MAX_LIST_ITEMS) return 0;
    }
    *out = v;
    return 1;
}

static dwv_result_t check_ascii(const char *path, const unsigned char *text, size_t size, const header *h)
{
    size_t at = h->body;
    uint64_t line = 0;
    for (unsigned i = 0; i < h->element_count; ++i) {
        const element *e = &h->elements[i];
        for (uint64_t k = 0; k < e->count; ++k) {
            /* one instance per line: skip blank lines, then read tokens up to the line's end */
            size_t end;
            for (;;) {
                if (at >= size)
                    return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': the PLY body ends before its last element",
                                    path);
                end = at;
                while (end < size && text[end] != '\n') ++end;
                ++line;
                size_t s = at;
                while (s < end && (text[s] == ' ' || text[s] == '\t' || text[s] == '\r')) ++s;
                if (s < end) break;
                at = end + 1;
            }
            size_t cursor = at;
            unsigned property_index = 0;
            uint64_t list_left = 0;
            int in_list = 0;
            for (;;) {
                while (cursor < end && (text[cursor] == ' ' || text[cursor] == '\t' || text[cursor] == '\r')) ++cursor;
                if (cursor >= end) break;
                size_t start = cursor;
                while (cursor < end && text[cursor] != ' ' && text[cursor] != '\t' && text[cursor] != '\r') ++cursor;
                if (!is_number(text + start, cursor - start))
                    return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': body line %llu of the PLY has a token that is not a number",
                                    path, (unsigned long long)line);
                if (in_list) {
                    if (--list_left == 0) in_list = 0, ++property_index;
                    continue;
                }
                if (property_index >= e->property_count)
                    return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': body line %llu of the PLY has too many values",
                                    path, (unsigned long long)line);
                if (e->properties[property_index].is_list) {
                    uint64_t items = 0;
                    if (!parse_count_token(text + start, cursor - start, &items) || items < 1u)
                        return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': body line %llu of the PLY: a list count "
                                        "that is not a whole number from 1 to %u", path, (unsigned long long)line,
                                        MAX_LIST_ITEMS);
                    in_list = 1, list_left = items;
                } else {
                    ++property_index;
                }
            }
            if (in_list || property_index != e->property_count)
                return dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': body line %llu of the PLY has too few values", path,
                                (unsigned long long)line);
            at = end < size ? end + 1 : end;
        }
    }
    return DWV_SUCCESS;
}

dwv_result_t dwvs_ply_check(const char *path)
{
    FILE *file = fopen(path, "rb");
    if (!file) return dwv_fail(DWV_ERROR_IO, "mesh file '%s': %s", path, strerror(errno));
    /* Read it all (Assimp will too), refusing files beyond the size limit without reading them. */
    size_t capacity = 1u << 16, size = 0;
    unsigned char *text = malloc(capacity);
    dwv_result_t r = DWV_SUCCESS;
    while (text) {
        if (size == capacity) {
            if (capacity >= DWVS_PLY_MAX_BYTES) {
                r = dwv_fail(DWV_ERROR_FORMAT, "mesh file '%s': larger than %llu bytes", path,
                             (unsigned long long)DWVS_PLY_MAX_BYTES);
                break;
            }
            unsigned char *bigger = realloc(text, capacity * 2u);
            if (!bigger) {
                free(text);
                text = NULL;
                break;
            }
            text = bigger;
            capacity *= 2u;
        }
        size_t got = fread(text + size, 1, capacity - size, file);
        size += got;
        if (got == 0) {
            if (ferror(file)) r = dwv_fail(DWV_ERROR_IO, "mesh file '%s': %s", path, strerror(errno));
            break;
        }
    }
    fclose(file);
    if (!text) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "mesh file '%s': no memory to read it", path);
    header h;
    if (r == DWV_SUCCESS) r = read_header(path, text, size, &h);
    if (r == DWV_SUCCESS) r = h.format == FORMAT_ASCII ? check_ascii(path, text, size, &h) : check_binary(path, text, size, &h);
    free(text);
    return r;
}
