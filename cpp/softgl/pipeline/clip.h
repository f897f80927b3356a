// Homogeneous clipping in clip space (ES 3.0 §2.17), before the perspective division.
//
// Triangles are clipped against w >= 0, the near and far planes (-w <= z <= w) and, only when a
// vertex lies outside it, the guard band (viewport.h): a rectangle of +-2^20 pixels in window space
// written as four planes in clip space. Inside the guard band x and y are not clipped: the
// rasterizer's bounding box and the framebuffer/scissor rectangle do that exactly, and clipping
// there would only add vertices and rounding. Lines are clipped against the same planes; points are
// handled by setup (not clipped by their centre in x/y, ES 3.0 §3.4 / WebGL clipping-wide-points).
//
// Near w = 0. Every plane passes through the clip-space origin, and together they admit no point
// with w = 0 but the origin (-w <= z <= w and the guard band force x = y = z = 0 there). The origin
// is no point of the projective plane and adds nothing to a picture (t*0 + (1-t)*Q divides to the
// same window position as Q), so it is dropped from the clipped polygon; no other epsilon is
// involved: any w > 0 is drawn, at any scale. The w >= 0 plane comes first so that every later
// plane sees only w >= 0, and an edge's crossing of w = 0 has w = 0 exactly (see clip.cpp).
//
// Every output vertex carries barycentric weights relative to the original primitive's vertices, so
// varyings are never clipped: the fragment stage interpolates the original vertices' varyings with
// perspective-correct weights built from these (see setup.h).
//
// Watertightness across clipped shared edges: an intersection is always computed from the inside
// vertex towards the outside vertex, from those two vertices alone, and planes are applied in a
// fixed order, so two triangles sharing an edge produce bit-identical clipped points.
//
// Primitives with a NaN or infinite coordinate are dropped.
#pragma once
#include <cstdint>

#include "softgl/pipeline/viewport.h"

namespace softgl {

struct Vec4d {
    double x, y, z, w;
};

struct ClipVertex {
    Vec4d position;     // clip coordinates
    double weight[3];   // barycentric weights relative to the original primitive's vertices
};

// Clipped vertices with a smaller w are dropped. Inside the clip volume only the origin has w = 0;
// a vertex rounding left with 0 < w < 2^-1022 (never an input: float32 positions have w = 0 or
// |w| >= 2^-149) is that origin up to cancellation. Every vertex kept has a finite 1/w, and x/w,
// y/w, z/w are never NaN (they exceed the guard band by rounding at most; setup's snap clamps).
inline constexpr double kMinClippedW = 0x1p-1022;

enum ClipPlaneBit : uint32_t {
    kClipW = 1u << 0,       // w >= 0
    kClipNear = 1u << 1,
    kClipFar = 1u << 2,
    kClipLeft = 1u << 3,    // guard band, window x >= -kGuardBand
    kClipRight = 1u << 4,   // guard band, window x <= +kGuardBand
    kClipBottom = 1u << 5,
    kClipTop = 1u << 6,
};
inline constexpr int kClipPlaneCount = 7;
// A triangle clipped by 7 planes has at most 3 + 7 vertices.
inline constexpr int kMaxClipVertices = 3 + kClipPlaneCount;

inline bool finite_vertex(const Vec4d& v);

class Clipper {
public:
    explicit Clipper(const Viewport& viewport);

    // Bit i set when finite v is outside plane i by its signed distance, a linear function of v
    // rounded (terms with a zero coefficient left out: they add +-0). Only used to pick the planes
    // to clip against; clipping recomputes distances exactly.
    uint32_t outcode(const Vec4d& v) const;
    // True when clip_triangle would return a triangle of these three vertices unchanged (weights
    // (1,0,0), (0,1,0), (0,0,1)) without clipping: every vertex finite, inside every plane by
    // outcode, with w >= kMinClippedW. The common case, tested first by setup.
    bool accepts(const Vec4d v[3]) const;
    // Plane i's coefficient on x, y, z or w (k = 0..3), for vectorised copies of outcode.
    double plane(int i, int k) const { return plane_[i][k]; }

    // Clips triangle v[0..2]. Returns the number of vertices of the clipped convex polygon written to
    // `out` (0: nothing left, or a non-finite coordinate), in the triangle's winding order; every
    // one has w >= kMinClippedW.
    int clip_triangle(const Vec4d v[3], ClipVertex out[kMaxClipVertices]) const;

    // Clips segment v[0..1] against w, near, far and the guard band. Returns false when nothing is
    // left; otherwise out[0..1] hold the clipped endpoints (weight[0..1] relative to v[0], v[1]),
    // both with w >= kMinClippedW.
    bool clip_line(const Vec4d v[2], ClipVertex out[2]) const;

private:
    double plane_[kClipPlaneCount][4];   // coefficients on x, y, z, w
};

inline bool finite_vertex(const Vec4d& v) {
    // x - x is 0 for finite x and NaN for NaN and +-Inf.
    return (v.x - v.x) == 0 && (v.y - v.y) == 0 && (v.z - v.z) == 0 && (v.w - v.w) == 0;
}

// Inline: setup calls these for every primitive.
inline uint32_t Clipper::outcode(const Vec4d& v) const {
    // Planes 0-2 have coefficients +-1 and 0 (their products are exact), planes 3-6 one coefficient
    // on x or y and one on w (see the constructor).
    const double(&p)[kClipPlaneCount][4] = plane_;
    return uint32_t(!(v.w >= 0)) << 0 | uint32_t(!(v.z + v.w >= 0)) << 1 |
           uint32_t(!(v.w - v.z >= 0)) << 2 |
           uint32_t(!(p[3][0] * v.x + p[3][3] * v.w >= 0)) << 3 |
           uint32_t(!(p[4][0] * v.x + p[4][3] * v.w >= 0)) << 4 |
           uint32_t(!(p[5][1] * v.y + p[5][3] * v.w >= 0)) << 5 |
           uint32_t(!(p[6][1] * v.y + p[6][3] * v.w >= 0)) << 6;
}

inline bool Clipper::accepts(const Vec4d v[3]) const {
    bool ok = true;
    for (int i = 0; i < 3; ++i)   // w >= kMinClippedW covers plane 0; & keeps it free of branches
        ok &= finite_vertex(v[i]) & (v[i].w >= kMinClippedW) & ((outcode(v[i]) & ~kClipW) == 0);
    return ok;
}

}  // namespace softgl
