// Primitive setup: viewport transform, snapping to fixed point, edge functions with the tie rule,
// face determination and culling, polygon offset, and the screen-linear planes the rasterizer and
// the fragment stage evaluate (depth, perspective-correct barycentrics).
//
// Fixed point: window coordinates snap to 1/256 pixel, rounding to nearest (floor(x*256 + 0.5), so
// that moving a primitive by whole pixels never changes its coverage pattern). Edge functions are
// exact int64 (ranges in viewport.h).
//
// Tie rule (a sample exactly on an edge): measured against WebGL in Chromium (SwiftShader), see
// tests/pipeline/reference/coverage_chromium.json. In GL window coordinates (y up, pixel centres at
// +0.5) a sample on an edge is covered when the edge is a "left" edge (interior to its right) or a
// horizontal "bottom" edge (interior above it). This is D3D/Vulkan's top-left rule seen in a y-down
// framebuffer. A sample on a vertex is covered only if both edges through it are included.
//
// Primitives are convex polygons of 3 (triangles) or 4 (points, lines) edges, all with the same
// representation, so one rasterizer serves all of them. Single-sample diamond-exit lines keep only
// their 2 band edges: their bounding box is exactly their major-axis extent (see Setup::line).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "softgl/pipeline/clip.h"
#include "softgl/core/simd.h"
#include "softgl/pipeline/viewport.h"

namespace softgl {

// Which pixels at the two ends of a non-antialiased line are produced (single-sample targets).
//  DiamondExit: ES 3.0 §3.5.1 exactly (a fragment for every diamond the segment exits; the start
//    pixel's diamond counts when the start point is inside it, the end pixel's does not when the end
//    point is inside it; the spec's (eps, eps^2) perturbation resolved exactly).
//  HalfOpen: the pixels whose centre's major coordinate is in [start, end) by the tie rule -- what
//    WebGL in Chromium (SwiftShader) does (tests/pipeline/reference/coverage_chromium.json: it
//    differs from DiamondExit by one end pixel on 11 of 36 lines). Also allowed by §3.5.1's
//    "other line segment rasterization algorithms" clause.
// Both agree on every pixel between the ends (and on the rows/columns within the line's width).
enum class LineRule : uint8_t { DiamondExit, HalfOpen };

// Fixed-function state that setup and raster read (the lead fills it from the context State).
struct RasterState {
    int32_t width = 0, height = 0;              // render target size in pixels
    // Pixels outside [x0, x1) x [y0, y1) are never covered: framebuffer ∩ scissor (ES 3.0 §4.1.2).
    int32_t clip_x0 = 0, clip_y0 = 0, clip_x1 = 0, clip_y1 = 0;
    Viewport viewport;
    bool cull_face = false;
    uint32_t cull_face_mode = 0x405;            // GL BACK
    uint32_t front_face = 0x901;                // GL CCW
    bool polygon_offset_fill = false;
    double polygon_offset_factor = 0, polygon_offset_units = 0;
    int depth_bits = 24;                        // unorm depth bits; 0 = 32-bit float depth
    int samples = 1;                            // 1, 2, 4, 8 or 16
    double point_size_min = 1, point_size_max = 1023;   // ALIASED_POINT_SIZE_RANGE (Chromium: 1..1023)
    double line_width = 1;                      // already clamped to ALIASED_LINE_WIDTH_RANGE
                                                // (or the smooth range when line_smooth)
    LineRule line_rule = LineRule::DiamondExit;   // single-sample aliased lines, see LineRule
    // softgl's SOFTGL_smooth extension (OpenGL 1.x LINE_SMOOTH / POINT_SMOOTH semantics; POLYGON_SMOOTH
    // needs no setup change). These only change the primitive's *shape*; the fraction of each pixel
    // it covers comes from pipeline/coverage (rasterize_area).
    //  line_smooth: the line is the exact rectangle of width line_width (not rounded) and the
    //    segment's length, centred on it (GL 1.5 §3.4.2), instead of the diamond-exit parallelogram.
    //  point_smooth: the point's area shape is a disk of diameter size (point_smooth_square: keep
    //    the square). Sample coverage (rasterize) still sees the enclosing square.
    bool line_smooth = false;
    bool point_smooth = false;
    bool point_smooth_square = false;
    // With samples == 1, triangles that need only their samples (no SOFTGL_smooth polygon
    // area): a triangle's bounding box spans only the pixels whose centre lies within the
    // triangle's extent, and a triangle that covers no centre is dropped at setup (counted as
    // outside) when that box is empty or has at most 4 pixels: most triangles under a pixel across
    // cover no centre.
    bool sample_bounds = false;

    // Convenience: whole framebuffer, viewport = framebuffer, no scissor.
    static RasterState for_target(int32_t width, int32_t height);
    void set_scissor(int32_t x, int32_t y, int32_t w, int32_t h);   // intersect with the target
};

// value(x, y) = c + a * dx + b * dy, with (dx, dy) the pixel-unit offset of (x, y) from the
// primitive's origin (a snapped vertex). Relative evaluation keeps precision far from 0.
struct Plane {
    double a = 0, b = 0, c = 0;
};

enum class PrimitiveKind : uint8_t { Triangle, Line, Point };

// The shape whose exact area pipeline/coverage integrates: the convex polygon of the edges, or (smooth
// points) the disk of diameter point_size centred on (origin_x, origin_y).
enum class AreaShape : uint8_t { Polygon, Disk };

// One record is five whole cache lines: the tile pass reads most of every binned record, and with
// many tiny primitives these reads dominate.
struct alignas(64) PrimitiveSetup {
    // Setup writes every field; records are built in place in large arrays, not zero-filled first.
    PrimitiveSetup() {}

    // Coverage: a sample at fixed-point window position (X, Y) (units of 1/256 pixel) is inside when
    // a[i]*X + b[i]*Y + c[i] >= 0 for every edge i < edge_count (the tie rule is folded into c)
    // and its pixel is inside the bounding box.
    int64_t a[4], b[4], c[4];
    // Pixel bounding box [x0, x1) x [y0, y1), already inside the RasterState clip rectangle.
    int32_t x0, y0, x1, y1;
    int64_t origin_x, origin_y;      // fixed-point origin of the planes
    Plane depth;                      // window z (ES 3.0 §2.12.1), linear in screen space (§3.6.1)
    double depth_offset;              // polygon offset o (ES 3.0 §3.6.5), 0 when disabled
    // Perspective-correct barycentrics relative to the ORIGINAL primitive's vertices (ES 3.0
    // §3.6.1 eq. 3.9): weight_k(x, y) = weight[k](x, y) / inv_w(x, y). These planes interpolate
    // weight_k / w_clip and 1 / w_clip linearly in screen space. inv_w is also gl_FragCoord.w.
    Plane weight[3];
    Plane inv_w;
    uint32_t vertex[3];               // indices of the original primitive's vertices (flat: vertex[2]
                                      // for triangles, vertex[1] for lines: the provoking vertex)
    uint32_t primitive;               // the primitive's number in the draw
    PrimitiveKind kind;
    uint8_t edge_count;               // 2, 3 or 4
    bool front_facing;                // gl_FrontFacing (points and lines: true)
    AreaShape area_shape;             // see area_offset
    float point_x, point_y, point_size;   // points: window centre and size, for gl_PointCoord
    // Area geometry (pipeline/coverage): the exact half-plane of edge i is
    //   a[i]*X + b[i]*Y + c[i] + area_offset[i] >= 0.
    // c[i] has the tie rule folded in (an excluded edge has c one less), so for triangles, aliased
    // points and lines area_offset[i] is 1 on tie-excluded edges and 0 otherwise: the area shape is
    // exactly the snapped polygon. Smooth lines' sides are irrational: c = floor(C) (so the integer
    // test is exact at every fixed-point position, and bins/blocks stay exact) and area_offset =
    // C - floor(C) in [0, 1) carries the exact width.
    double area_offset[4];

    // Depth at a fixed-point sample position: plane + offset, clamped to [0, 1] (ES 3.0 §3.6.5).
    double depth_at(int64_t X, int64_t Y) const {
        double z = eval(depth, X, Y) + depth_offset;
        return z < 0 ? 0 : (z > 1 ? 1 : z);
    }
    double eval(const Plane& p, int64_t X, int64_t Y) const {
        return p.c + p.a * (double(X - origin_x) * (1.0 / kSubPixel)) +
               p.b * (double(Y - origin_y) * (1.0 / kSubPixel));
    }
    // Perspective-correct weights of the original vertices at (X, Y).
    void weights_at(int64_t X, int64_t Y, double out[3]) const {
        const double q = 1.0 / eval(inv_w, X, Y);
        for (int k = 0; k < 3; ++k) out[k] = eval(weight[k], X, Y) * q;
    }
    // gl_PointCoord for the fragment of pixel (px, py) (ES 3.0 §3.4.1: evaluated at the centre).
    void point_coord(int32_t px, int32_t py, float out[2]) const {
        out[0] = 0.5f + (float(px) + 0.5f - point_x) / point_size;
        out[1] = 0.5f - (float(py) + 0.5f - point_y) / point_size;
    }
};

static_assert(sizeof(PrimitiveSetup) == 5 * 64);

struct SetupStats {
    uint64_t primitives = 0;   // primitives given to setup
    uint64_t invalid = 0;      // dropped: NaN or infinite coordinate
    uint64_t outside = 0;      // dropped: outside the clip volume or the framebuffer/scissor rectangle
                               // (or, with sample_bounds, a small triangle covering no pixel centre)
    uint64_t clipped = 0;      // needed clipping (near/far/w/guard band) and survived
    uint64_t culled = 0;       // dropped by cullFace
    uint64_t zero_area = 0;    // dropped: no area after snapping
    uint64_t emitted = 0;      // PrimitiveSetup records produced (a clipped triangle may give several)
    void add(const SetupStats& o);
};

// A vertex projected and snapped once for all the triangles that use it (Setup::project_vertices).
// inv_w is 0 when the vertex fails the per-vertex part of Clipper::accepts (the other fields are
// then meaningless): a triangle with such a vertex goes to the clipper.
struct WindowPosition {
    int64_t X, Y;      // snapped window position, 1/256 pixel
    double z, inv_w;   // window z, 1 / w_clip (> 0 when set)
};

// Viewport::scale_x() etc., computed once (ES 3.0 §2.12.1).
struct ViewportTransform {
    double scale_x, offset_x, scale_y, offset_y, scale_z, offset_z;
};

// The diamond-exit rule (ES 3.0 §3.5.1) for the width-1 segment from (ax, ay) to (bx, by) (fixed
// point, not both equal): the first and last major-axis pixel index with a fragment (every one
// between has one). False: no fragment. Auto decides a segment of |slope| != 1 from its end points
// and scans a slope of +-1 column by column; Scan scans every segment (tests compare the two).
enum class DiamondExitMethod : uint8_t { Auto, Scan };
bool diamond_exit_span(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t& first, int64_t& last,
                       DiamondExitMethod method = DiamondExitMethod::Auto);

class Setup {
public:
    explicit Setup(const RasterState& state);

    // Each call appends zero or more PrimitiveSetup records to `out`. Positions are clip coordinates
    // (x, y, z, w) as the vertex shader wrote gl_Position; i0.. are the vertex indices recorded for
    // varying interpolation; `primitive` is the primitive's number in the draw.
    void triangle(const float* p0, const float* p1, const float* p2, uint32_t i0, uint32_t i1,
                  uint32_t i2, uint32_t primitive, std::vector<PrimitiveSetup>& out);
    // The same for vertices project_vertices has projected: vertex k's clip position is
    // positions[4 * vertex[k]...], its window position window[vertex[k]].
    void triangle(const float* positions, const WindowPosition* window, const uint32_t vertex[3],
                  uint32_t primitive, std::vector<PrimitiveSetup>& out);
    // Triangles k < count, of vertices vertices[3k .. 3k + 2] (as above) and primitive numbers
    // first_primitive + k: the same records and counters as calling the overload above for each
    // in turn (the reference, tests/pipeline/test_setup_triangles.py), with less work per
    // triangle: facing and culling straight from the projected vertices, no vertex copies.
    // Facing and culling run 4 triangles at a time at the AVX2 level and above (same classes), and
    // so do the records of triangles with no vertex to clip (same bits).
    void triangles(const float* positions, const WindowPosition* window, const uint32_t* vertices,
                   size_t count, uint32_t first_primitive, std::vector<PrimitiveSetup>& out,
                   SimdLevel level = best_simd_level());
    // Projects positions[0 .. 4 * count) (clip coordinates) to out[0 .. count), vertex by vertex,
    // exactly as triangle() does; every level gives the same bits (AVX-512 and AVX2 kernels, 8 and
    // 4 vertices at a time; SSE2 runs the scalar code).
    void project_vertices(const float* positions, size_t count, WindowPosition* out,
                          SimdLevel level = best_simd_level()) const;
    // A point of gl_PointSize `size` (clamped to the point size range), ES 3.0 §3.4.
    void point(const float* p, float size, uint32_t index, uint32_t primitive,
               std::vector<PrimitiveSetup>& out);
    // A line segment of RasterState::line_width, ES 3.0 §3.5 (see setup.cpp for the rule used).
    void line(const float* p0, const float* p1, uint32_t i0, uint32_t i1, uint32_t primitive,
              std::vector<PrimitiveSetup>& out);
    // The same for vertices project_vertices has projected (as triangle() above).
    void line(const float* positions, const WindowPosition* window, const uint32_t vertex[2], uint32_t primitive,
              std::vector<PrimitiveSetup>& out);

    SetupStats stats;

private:
    struct WindowVertex {
        int64_t X, Y;        // snapped, 1/256 pixel
        double z, inv_w;     // window z, 1/w_clip
        double weight[3];
    };
    WindowVertex project(const Vec4d& position, const double weight[3]) const;
    void triangle(const float* const p[3], const WindowPosition* const w[3], const uint32_t vertex[3],
                  uint32_t primitive, std::vector<PrimitiveSetup>& out);
    void line(const float* p0, const float* p1, const WindowPosition& w0, const WindowPosition& w1, uint32_t i0,
              uint32_t i1, uint32_t primitive, std::vector<PrimitiveSetup>& out);
    bool culled(bool front) const;   // by cullFace (ES 3.0 §3.6.1)
    void unclipped_triangle(const WindowVertex w[3], const uint32_t vertex[3], uint32_t primitive,
                            std::vector<PrimitiveSetup>& out);
    // V: WindowVertex, or a projected vertex with its weights implied (setup.cpp, UnitCorner).
    template <class V>
    void emit_triangle(const V& v0, const V& v1, const V& v2, int64_t area2, bool front,
                       const uint32_t vertex[3], uint32_t primitive, std::vector<PrimitiveSetup>& out);
    // Setup::triangles' loop over a block at the AVX2 level and above (setup.cpp): cls and area2
    // from the block's classification.
    void emit_block_avx2(const float* positions, const WindowPosition* window, const uint32_t* vertices, size_t count,
                         uint32_t first_primitive, const uint8_t* cls, const int64_t* area2,
                         std::vector<PrimitiveSetup>& out);
    bool finish_bbox(PrimitiveSetup& s, int64_t xmin, int64_t ymin, int64_t xmax, int64_t ymax);
    double resolvable_difference(double max_abs_z) const;

    RasterState state_;
    // culled(front) as a table: bit 1 culls front faces, bit 0 back faces.
    uint8_t cull_bits_;
    bool ccw_is_front_;
    Clipper clipper_;
    ViewportTransform transform_;
};

}  // namespace softgl
