// Area coverage for softgl's SOFTGL_smooth extension (OpenGL 1.x POLYGON_SMOOTH, LINE_SMOOTH,
// POINT_SMOOTH semantics, GL 1.5 §3.3-3.5 "antialiasing"): for every pixel square [px, px+1] x
// [py, py+1] that the primitive's area meets, the fraction of the square it covers. The fragment
// stage multiplies the fragment's alpha by it (GL 1.5 §3.12: "coverage ... multiplies alpha").
//
// Geometry: the area shape of a PrimitiveSetup (setup.h) is the convex polygon of its *snapped*
// edges (triangles, aliased points and lines), the exact rectangle of a smooth line, or the disk of
// a smooth point. Using the snapped vertices keeps area and sample coverage describing one shape and
// makes shared edges identical in both triangles, so a mesh's fractions add up to 1 per pixel (to
// rounding, ~1e-15) exactly where its sample coverage is watertight.
//
// Exact mode (hint NICEST): triangle ∩ square by clipping the square against each crossing edge
// (Sutherland-Hodgman) in double precision, edge values evaluated exactly in int64 at the square's
// corners; disk ∩ square by the closed-form integral of the circle's chord length.
// Sampled mode (hint FASTEST): the fraction of an n x n regular grid of samples ((i + 1/2)/n,
// (j + 1/2)/n) inside the shape, with the tie rule on edges (so meshes stay watertight per sample).
// Error bound (sampled_error_bound): only grid cells that a boundary passes through can be
// misclassified, each by at most its area 1/n^2; a straight edge passes through at most 2n - 1 cells
// of the n x n grid and a circle through at most 4n + 4 (it crosses each of the n + 1 vertical and
// n + 1 horizontal grid lines at most twice). So |sampled - exact| <= k (2n - 1) / n^2 for a pixel
// crossed by k edges, <= (4n + 4) / n^2 for a disk: O(1/n), 0.23 per edge for n = 8, 0.03 for n = 64
// (worst case; typical errors are far smaller since per-cell errors cancel along an edge).
//
// The raster side is conservative: rasterize_area emits every pixel (of tile ∩ bounding box) whose
// fraction is > 0, including pixels whose centre is outside the primitive, as 2x2 quads in the same
// order and format as rasterize() (raster.h), with the fractions alongside.
#pragma once
#include <cstdint>
#include <vector>

#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/setup.h"

namespace softgl {

struct AreaOptions {
    bool sampled = false;   // false: exact (POLYGON_SMOOTH_HINT NICEST / DONT_CARE); true: FASTEST
    int grid = 8;           // sampled: grid x grid samples per pixel; a power of two, 1..128 (the
                            // samples then lie on the 1/256 fixed-point grid, so the test is exact)
};

// Fractions of the four pixels of the Quad with the same index (pixel i = dx + 2*dy, as Quad).
struct QuadArea {
    double fraction[4];
};

// Exact area of (primitive ∩ [px, px+1] x [py, py+1]), in pixels (0..1).
double pixel_area(const PrimitiveSetup& prim, int32_t px, int32_t py);
// Sampled estimate: covered samples / grid^2.
double pixel_area_sampled(const PrimitiveSetup& prim, int32_t px, int32_t py, int grid);
// Worst-case |sampled - exact| for one pixel crossed by `edges` straight edges, or (edges < 0) by a
// circle; see above.
double sampled_error_bound(int grid, int edges);

// Area of the disk (centre (cx, cy), radius r) ∩ the rectangle [x0, x1] x [y0, y1], closed form.
double disk_rect_area(double cx, double cy, double r, double x0, double y0, double x1, double y1);

// Appends the quads of `prim` inside `tile` whose pixels have a positive fraction, and their
// fractions to `areas` (same index). Each pixel with a positive fraction gets every sample of
// `pattern` in its mask; pixels with fraction 0 get mask 0 (helper pixels for derivatives).
// Stats count blocks (8x8) fully covered, rejected or partial, as rasterize() does.
void rasterize_area(const PrimitiveSetup& prim, const TileRect& tile, const SamplePattern& pattern,
                    const AreaOptions& options, std::vector<Quad>& quads,
                    std::vector<QuadArea>& areas, RasterStats& stats);

}  // namespace softgl
