#include "clearance.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Cell visits the marking may take per cell of the grid before the grid is given up (a mesh of
 * many long slanted triangles, whose bounding boxes cover much of the grid each). */
#define MARK_VISITS_PER_CELL 64.0
/* Slack in cell units for rounding in the cell ranges and centres (computed in double from float
 * positions: errors near 1e-16 relative). */
#define CELL_SLACK 1e-6
/* Cells within BAND_CELLS cells of a triangle's bounding box get their centre's exact distance,
 * unless that takes more than BAND_VISITS_PER_CELL distance computations per cell. */
#define BAND_CELLS 2.0
#define BAND_VISITS_PER_CELL 8.0

/* The barycentrics (u, v) of the point of triangle abc closest to p (Ericson, Real-Time
 * Collision Detection, Sec. 5.1.5: Voronoi regions of the vertices, edges and face in turn). */
void dwvg_closest_on_triangle(dwvu_vec3 p, dwvu_vec3 a, dwvu_vec3 b, dwvu_vec3 c, double *u, double *v)
{
    dwvu_vec3 ab = dwvu_sub(b, a), ac = dwvu_sub(c, a), ap = dwvu_sub(p, a);
    double d1 = dwvu_dot(ab, ap), d2 = dwvu_dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) { *u = 0.0; *v = 0.0; return; }
    dwvu_vec3 bp = dwvu_sub(p, b);
    double d3 = dwvu_dot(ab, bp), d4 = dwvu_dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) { *u = 1.0; *v = 0.0; return; }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) { *u = d1 / (d1 - d3); *v = 0.0; return; }
    dwvu_vec3 cp = dwvu_sub(p, c);
    double d5 = dwvu_dot(ab, cp), d6 = dwvu_dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) { *u = 0.0; *v = 1.0; return; }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) { *u = 0.0; *v = d2 / (d2 - d6); return; }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        *u = 1.0 - w;
        *v = w;
        return;
    }
    double inv = 1.0 / (va + vb + vc);
    *u = vb * inv;
    *v = vc * inv;
}

/* The distance from p to segment ab. */
static double segment_distance(dwvu_vec3 p, dwvu_vec3 a, dwvu_vec3 b)
{
    dwvu_vec3 ab = dwvu_sub(b, a);
    double length2 = dwvu_dot(ab, ab);
    double s = length2 > 0.0 ? dwvu_dot(dwvu_sub(p, a), ab) / length2 : 0.0;
    s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
    return dwvu_length(dwvu_sub(p, dwvu_add(a, dwvu_scale(ab, s))));
}

double dwvg_triangle_distance(dwvu_vec3 p, dwvu_vec3 a, dwvu_vec3 b, dwvu_vec3 c)
{
    dwvu_vec3 ab = dwvu_sub(b, a), ac = dwvu_sub(c, a);
    dwvu_vec3 n = dwvu_v(ab.y * ac.z - ab.z * ac.y, ab.z * ac.x - ab.x * ac.z, ab.x * ac.y - ab.y * ac.x);
    double area2 = dwvu_dot(n, n);
    if (!(area2 > 0.0 && isfinite(area2)))
        return fmin(segment_distance(p, a, b), fmin(segment_distance(p, b, c), segment_distance(p, c, a)));
    double u, v;
    dwvg_closest_on_triangle(p, a, b, c, &u, &v);
    dwvu_vec3 x = dwvu_add(a, dwvu_add(dwvu_scale(ab, u), dwvu_scale(ac, v)));
    return dwvu_length(dwvu_sub(p, x));
}

/* The largest float not above x (x finite). */
static float float_below(double x)
{
    float f = (float)x;
    return (double)f > x ? nextafterf(f, -INFINITY) : f;
}

static int finite_triangle(const dwvg_mesh *mesh, uint32_t t, double lo[3], double hi[3])
{
    const uint32_t *i = mesh->indices + 3u * (size_t)t;
    for (int a = 0; a < 3; ++a) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    for (int k = 0; k < 3; ++k) {
        const float *p = mesh->positions + 3u * (size_t)i[k];
        for (int a = 0; a < 3; ++a) {
            if (!isfinite(p[a])) return 0;
            lo[a] = fmin(lo[a], p[a]);
            hi[a] = fmax(hi[a], p[a]);
        }
    }
    return 1;
}

/* The cells [first, last] along axis a that coordinates lo..hi touch, widened by the slack. */
static void cell_range(const dwvg_clearance *grid, int a, double lo, double hi, uint32_t *first, uint32_t *last)
{
    double f = floor((lo - grid->origin[a]) / grid->cell - CELL_SLACK);
    double l = floor((hi - grid->origin[a]) / grid->cell + CELL_SLACK);
    double top = (double)grid->n[a] - 1.0;
    *first = (uint32_t)fmax(0.0, fmin(f, top));
    *last = (uint32_t)fmax(0.0, fmin(l, top));
}

/* Squared distances along one line of n samples with stride `stride`: d(q) = min_p (q - p)^2 + f(p)
 * (Felzenszwalb and Huttenlocher 2012, Algorithm 1), in place. f = INFINITY marks no sample; the
 * first finite one starts the lower envelope, so no infinity is ever subtracted. */
static void distance_line(double *values, size_t stride, uint32_t n, double *f, uint32_t *v, double *z)
{
    for (uint32_t q = 0; q < n; ++q) f[q] = values[q * stride];
    int k = -1;
    for (uint32_t q = 0; q < n; ++q) {
        if (f[q] == INFINITY) continue;
        if (k < 0) {
            k = 0;
            v[0] = q;
            z[0] = -INFINITY;
            z[1] = INFINITY;
            continue;
        }
        double s;
        for (;;) {
            double p = v[k];
            s = ((f[q] + (double)q * q) - (f[v[k]] + p * p)) / (2.0 * q - 2.0 * p);
            if (s > z[k] || k == 0) break;
            --k;
        }
        /* k == 0 with s <= z[0] = -inf cannot happen: the envelope keeps its first parabola. */
        ++k;
        v[k] = q;
        z[k] = s;
        z[k + 1] = INFINITY;
    }
    if (k < 0) return; /* no marked sample on the line: all stay infinite */
    k = 0;
    for (uint32_t q = 0; q < n; ++q) {
        while (z[k + 1] < q) ++k;
        double d = (double)q - v[k];
        values[q * stride] = d * d + f[v[k]];
    }
}

/* Cell visits of marking every triangle's bounding box grown by `grow`. */
static double cell_visits(const dwvg_clearance *grid, const dwvg_mesh *mesh, double grow)
{
    double visits = 0.0;
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        double tlo[3], thi[3];
        if (!finite_triangle(mesh, t, tlo, thi)) continue;
        double span = 1.0;
        for (int a = 0; a < 3; ++a) {
            uint32_t first, last;
            cell_range(grid, a, tlo[a] - grow, thi[a] + grow, &first, &last);
            span *= (double)(last - first + 1u);
        }
        visits += span;
    }
    return visits;
}

/* Triangle t's corners into p and its unit normal (p1 - p0) x (p2 - p0) / |...| into *n; returns
 * |(p1 - p0) x (p2 - p0)| (twice the area), or 0 with *n = 0 where that is zero or not finite (no
 * plane). */
static double triangle_plane(const dwvg_mesh *mesh, uint32_t t, dwvu_vec3 p[3], dwvu_vec3 *n)
{
    const uint32_t *corner = mesh->indices + 3u * (size_t)t;
    for (int k = 0; k < 3; ++k) {
        const float *q = mesh->positions + 3u * (size_t)corner[k];
        p[k] = dwvu_v(q[0], q[1], q[2]);
    }
    dwvu_vec3 e1 = dwvu_sub(p[1], p[0]), e2 = dwvu_sub(p[2], p[0]);
    dwvu_vec3 c = dwvu_v(e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x);
    double length = dwvu_length(c);
    int flat = length > 0.0 && isfinite(length);
    *n = flat ? dwvu_scale(c, 1.0 / length) : dwvu_v(0.0, 0.0, 0.0);
    return flat ? length : 0.0;
}

/* Lowers grid->lower to the centres' distances to triangle t, over its bounding box grown by
 * `band`. */
static void exact_near(dwvg_clearance *grid, const dwvg_mesh *mesh, uint32_t t, double band)
{
    double tlo[3], thi[3];
    if (!finite_triangle(mesh, t, tlo, thi)) return;
    /* The distance to a triangle is at least that to its plane: a cheap test first. */
    dwvu_vec3 p[3], n;
    int flat = triangle_plane(mesh, t, p, &n) > 0.0;
    uint32_t first[3], last[3];
    for (int a = 0; a < 3; ++a) cell_range(grid, a, tlo[a] - band, thi[a] + band, &first[a], &last[a]);
    for (uint32_t iz = first[2]; iz <= last[2]; ++iz)
        for (uint32_t iy = first[1]; iy <= last[1]; ++iy)
            for (uint32_t ix = first[0]; ix <= last[0]; ++ix) {
                float *cell = &grid->lower[((size_t)iz * grid->n[1] + iy) * grid->n[0] + ix];
                dwvu_vec3 centre = dwvg_clearance_centre(grid, ix, iy, iz);
                if (flat && fabs(dwvu_dot(dwvu_sub(centre, p[0]), n)) >= *cell) continue;
                double d = dwvg_triangle_distance(centre, p[0], p[1], p[2]);
                if (d < *cell) *cell = float_below(d);
            }
}

/* The planes of the mesh's triangles into grid->planes, if there are at most
 * DWVG_CLEARANCE_MAX_PLANES of them and every triangle has one (finite corners, area > 0): 1, else
 * 0 with none kept. A plane is kept once; a triangle whose computed plane equals a kept one, or
 * its reverse, bit for bit, lies in that very plane. */
static int find_planes(dwvg_clearance *grid, const dwvg_mesh *mesh)
{
    uint32_t count = 0;
    double area[DWVG_CLEARANCE_MAX_PLANES];
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        double lo[3], hi[3];
        if (!finite_triangle(mesh, t, lo, hi)) return 0;
        dwvu_vec3 p[3], n;
        double length = triangle_plane(mesh, t, p, &n);
        if (!(length > 0.0)) return 0;
        double d = dwvu_dot(n, p[0]);
        uint32_t known = count;
        for (uint32_t i = 0; i < count && known == count; ++i) {
            const double *q = grid->planes[i];
            if ((q[0] == n.x && q[1] == n.y && q[2] == n.z && q[3] == d) ||
                (q[0] == -n.x && q[1] == -n.y && q[2] == -n.z && q[3] == -d))
                known = i;
        }
        if (known == count) {
            if (count == DWVG_CLEARANCE_MAX_PLANES) return 0;
            double *q = grid->planes[count];
            q[0] = n.x;
            q[1] = n.y;
            q[2] = n.z;
            q[3] = d;
            area[count++] = 0.0;
        }
        area[known] += 0.5 * length;
    }
    if (count == 0) return 0;
    /* Largest area first (insertion sort, stable): a walk is most often nearest those. */
    for (uint32_t i = 1; i < count; ++i)
        for (uint32_t j = i; j > 0 && area[j] > area[j - 1]; --j) {
            double a = area[j], q[4];
            area[j] = area[j - 1];
            area[j - 1] = a;
            memcpy(q, grid->planes[j], sizeof q);
            memcpy(grid->planes[j], grid->planes[j - 1], sizeof q);
            memcpy(grid->planes[j - 1], q, sizeof q);
        }
    grid->plane_count = count;
    grid->largest = INFINITY;
    return 1;
}

int dwvg_clearance_build(dwvg_clearance *grid, const dwvg_mesh *mesh, double cell_size, double largest_cell)
{
    memset(grid, 0, sizeof *grid);
    if (find_planes(grid, mesh)) return 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        double tlo[3], thi[3];
        if (!finite_triangle(mesh, t, tlo, thi)) continue;
        for (int a = 0; a < 3; ++a) {
            lo[a] = fmin(lo[a], tlo[a]);
            hi[a] = fmax(hi[a], thi[a]);
        }
    }
    if (!(lo[0] <= hi[0]) || !(cell_size > 0.0) || !isfinite(cell_size)) return 1;
    /* One cell of padding on each side, so that points just outside the mesh are on the grid. */
    double h = cell_size, cells;
    for (;;) {
        cells = 1.0;
        for (int a = 0; a < 3; ++a) cells *= floor((hi[a] - lo[a]) / h) + 3.0;
        if (cells <= DWVG_CLEARANCE_MAX_CELLS) break;
        h *= 1.0594630943592953; /* 2^(1/12): a twelfth of the way to half the cells */
    }
    if (!(h <= largest_cell)) return 1;
    grid->cell = h;
    grid->inverse_cell = 1.0 / h;
    for (int a = 0; a < 3; ++a) {
        grid->n[a] = (uint32_t)(floor((hi[a] - lo[a]) / h) + 3.0);
        grid->cells[a] = grid->n[a];
        grid->origin[a] = lo[a] - h;
    }
    size_t count = (size_t)grid->n[0] * grid->n[1] * grid->n[2];
    double band = BAND_CELLS * h;
    int near_exact = cell_visits(grid, mesh, band) <= BAND_VISITS_PER_CELL * (double)count;
    if (!near_exact && cell_visits(grid, mesh, 0.0) > MARK_VISITS_PER_CELL * (double)count) {
        memset(grid, 0, sizeof *grid);
        return 1;
    }
    uint32_t longest = grid->n[0] > grid->n[1] ? grid->n[0] : grid->n[1];
    longest = longest > grid->n[2] ? longest : grid->n[2];
    double *squared = malloc(count * sizeof *squared);
    double *f = malloc(longest * sizeof *f), *z = malloc((longest + 1u) * sizeof *z);
    uint32_t *v = malloc(longest * sizeof *v);
    grid->lower = malloc(count * sizeof *grid->lower);
    if (!squared || !f || !z || !v || !grid->lower) {
        free(squared);
        free(f);
        free(z);
        free(v);
        dwvg_clearance_free(grid);
        return -1;
    }
    const uint32_t nx = grid->n[0], ny = grid->n[1], nz = grid->n[2];
    /* A cell that meets a triangle has its centre within h sqrt(3)/2 of it. */
    double half_diagonal = h * (0.8660254037844387 + 2.0 * CELL_SLACK);
    if (near_exact) {
        /* The centres' exact distances near the surface: min(band, the distance to each triangle
         * whose bounding box grown by the band holds the centre; the others are farther). Cells
         * whose centre lies within half a diagonal of the surface are the marked ones. */
        for (size_t i = 0; i < count; ++i) grid->lower[i] = float_below(band);
        for (uint32_t t = 0; t < mesh->triangle_count; ++t) exact_near(grid, mesh, t, band);
        for (size_t i = 0; i < count; ++i) squared[i] = grid->lower[i] <= half_diagonal ? 0.0 : INFINITY;
    } else {
        /* Every point of a triangle lies in its bounding box, whose cells are all marked. */
        for (size_t i = 0; i < count; ++i) {
            squared[i] = INFINITY;
            grid->lower[i] = 0.0f;
        }
        for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
            double tlo[3], thi[3];
            if (!finite_triangle(mesh, t, tlo, thi)) continue;
            uint32_t first[3], last[3];
            for (int a = 0; a < 3; ++a) cell_range(grid, a, tlo[a], thi[a], &first[a], &last[a]);
            for (uint32_t iz = first[2]; iz <= last[2]; ++iz)
                for (uint32_t iy = first[1]; iy <= last[1]; ++iy)
                    for (uint32_t ix = first[0]; ix <= last[0]; ++ix) squared[((size_t)iz * ny + iy) * nx + ix] = 0.0;
        }
    }
    for (uint32_t iz = 0; iz < nz; ++iz)
        for (uint32_t iy = 0; iy < ny; ++iy) distance_line(&squared[((size_t)iz * ny + iy) * nx], 1u, nx, f, v, z);
    for (uint32_t iz = 0; iz < nz; ++iz)
        for (uint32_t ix = 0; ix < nx; ++ix) distance_line(&squared[(size_t)iz * ny * nx + ix], nx, ny, f, v, z);
    for (uint32_t iy = 0; iy < ny; ++iy)
        for (uint32_t ix = 0; ix < nx; ++ix) distance_line(&squared[(size_t)iy * nx + ix], (size_t)nx * ny, nz, f, v, z);
    /* The bound at a centre: the larger of the transform's, D - h sqrt(3)/2 (the farthest a surface
     * point in a marked cell is from that cell's centre), and the exact distance (to rounding: the
     * slack covers the centre's own), rounded down to float. */
    double slack = CELL_SLACK * h;
    for (size_t i = 0; i < count; ++i)
        grid->lower[i] = fmaxf(float_below(sqrt(squared[i]) * h - half_diagonal), float_below((double)grid->lower[i] - slack));
    grid->largest = 0.0;
    for (size_t i = 0; i < count; ++i) grid->largest = fmax(grid->largest, (double)grid->lower[i]);
    free(squared);
    free(f);
    free(z);
    free(v);
    return 0;
}

void dwvg_clearance_free(dwvg_clearance *grid)
{
    free(grid->lower);
    memset(grid, 0, sizeof *grid);
}
