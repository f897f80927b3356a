#include "softgl/pipeline/clip.h"

namespace softgl {

Clipper::Clipper(const Viewport& vp) {
    const double sx = vp.scale_x(), ox = vp.offset_x(), sy = vp.scale_y(), oy = vp.offset_y();
    const double g = kGuardBand;
    auto set = [&](int i, double a, double b, double c, double d) {
        plane_[i][0] = a; plane_[i][1] = b; plane_[i][2] = c; plane_[i][3] = d;
    };
    set(0, 0, 0, 0, 1);            // w >= kClipEpsilon (the constant is subtracted in distance())
    set(1, 0, 0, 1, 1);            // z + w >= 0         (ES 3.0 §2.17: -w <= z)
    set(2, 0, 0, -1, 1);           // w - z >= 0         (z <= w)
    // Window x = sx * x/w + ox >= -g  <=>  sx*x + (ox + g)*w >= 0 (for w > 0; w is clipped first).
    set(3, sx, 0, 0, ox + g);
    set(4, -sx, 0, 0, g - ox);     // sx*x/w + ox <= g
    set(5, 0, sy, 0, oy + g);
    set(6, 0, -sy, 0, g - oy);
}

double Clipper::distance(int i, const Vec4d& v) const {
    const double* p = plane_[i];
    double d = p[0] * v.x + p[1] * v.y + p[2] * v.z + p[3] * v.w;
    return i == 0 ? d - kClipEpsilon : d;
}

uint32_t Clipper::outcode(const Vec4d& v) const {
    uint32_t code = 0;
    for (int i = 0; i < kClipPlaneCount; ++i)
        if (!(distance(i, v) >= 0)) code |= 1u << i;
    return code;
}

namespace {

// The point where the segment from `in` (distance din >= 0) to `out` (dout < 0) crosses the plane.
// Always computed from the inside vertex: see the watertightness note in clip.h.
//
// z, w and the weights are interpolated with t, which is accurate, and they are bounded (|z| <= w
// after near/far, weights in [0, 1]). x and y are not: for a guard-band plane and an edge between
// two vertices at, say, +-1e30, in + t * (out - in) cancels catastrophically and the point lands
// nowhere near the band. For those planes x and y come instead from the intersection of the edge's
// line with the plane's line in homogeneous (x, y, w) space (cross products, no cancellation unless
// the input itself is ill-conditioned), scaled to the interpolated w.
ClipVertex intersect(const ClipVertex& in, double din, const ClipVertex& out, double dout,
                     const double* plane, bool use_line) {
    const double t = din / (din - dout);
    ClipVertex r;
    r.position.x = in.position.x + t * (out.position.x - in.position.x);
    r.position.y = in.position.y + t * (out.position.y - in.position.y);
    r.position.z = in.position.z + t * (out.position.z - in.position.z);
    r.position.w = in.position.w + t * (out.position.w - in.position.w);
    for (int k = 0; k < 3; ++k) r.weight[k] = in.weight[k] + t * (out.weight[k] - in.weight[k]);
    if (use_line) {
        const Vec4d& a = in.position;
        const Vec4d& b = out.position;
        // Edge line L = a x b, plane line M = (px, py, pw); their intersection P = L x M.
        const double l0 = a.y * b.w - a.w * b.y, l1 = a.w * b.x - a.x * b.w, l2 = a.x * b.y - a.y * b.x;
        const double m0 = plane[0], m1 = plane[1], m2 = plane[3];
        const double px = l1 * m2 - l2 * m1, py = l2 * m0 - l0 * m2, pw = l0 * m1 - l1 * m0;
        const double s = r.position.w / pw;
        const double x = px * s, y = py * s;
        if (pw != 0 && (x - x) == 0 && (y - y) == 0) {
            r.position.x = x;
            r.position.y = y;
        }
    }
    return r;
}

}  // namespace

int Clipper::clip_triangle(const Vec4d v[3], ClipVertex out[kMaxClipVertices]) const {
    if (!finite_vertex(v[0]) || !finite_vertex(v[1]) || !finite_vertex(v[2])) return 0;
    const uint32_t c0 = outcode(v[0]), c1 = outcode(v[1]), c2 = outcode(v[2]);
    for (int i = 0; i < 3; ++i) {
        out[i].position = v[i];
        out[i].weight[0] = i == 0; out[i].weight[1] = i == 1; out[i].weight[2] = i == 2;
    }
    if (c0 & c1 & c2) return 0;      // all three outside one plane
    const uint32_t planes = c0 | c1 | c2;
    if (planes == 0) return 3;

    ClipVertex buffer[kMaxClipVertices];
    ClipVertex* src = out;
    ClipVertex* dst = buffer;
    int n = 3;
    for (int p = 0; p < kClipPlaneCount; ++p) {   // fixed order: w, near, far, guard band
        if (!(planes & (1u << p))) continue;
        double d[kMaxClipVertices];
        for (int i = 0; i < n; ++i) d[i] = distance(p, src[i].position);
        int m = 0;
        for (int i = 0; i < n; ++i) {
            const int j = i + 1 == n ? 0 : i + 1;
            const bool in_i = d[i] >= 0, in_j = d[j] >= 0;
            if (in_i) dst[m++] = src[i];
            if (in_i && !in_j) dst[m++] = intersect(src[i], d[i], src[j], d[j], plane_[p], p >= 3);
            if (!in_i && in_j) dst[m++] = intersect(src[j], d[j], src[i], d[i], plane_[p], p >= 3);
        }
        n = m;
        if (n < 3) return 0;
        ClipVertex* t = src; src = dst; dst = t;
    }
    if (src != out)
        for (int i = 0; i < n; ++i) out[i] = src[i];
    return n;
}

bool Clipper::clip_line(const Vec4d v[2], ClipVertex out[2]) const {
    if (!finite_vertex(v[0]) || !finite_vertex(v[1])) return false;
    for (int i = 0; i < 2; ++i) {
        out[i].position = v[i];
        out[i].weight[0] = i == 0; out[i].weight[1] = i == 1; out[i].weight[2] = 0;
    }
    const uint32_t c0 = outcode(v[0]), c1 = outcode(v[1]);
    if (c0 & c1) return false;
    const uint32_t planes = c0 | c1;
    for (int p = 0; p < kClipPlaneCount; ++p) {
        if (!(planes & (1u << p))) continue;
        const double d0 = distance(p, out[0].position), d1 = distance(p, out[1].position);
        const bool in0 = d0 >= 0, in1 = d1 >= 0;
        if (!in0 && !in1) return false;
        if (in0 && !in1) out[1] = intersect(out[0], d0, out[1], d1, plane_[p], p >= 3);
        if (!in0 && in1) out[0] = intersect(out[1], d1, out[0], d0, plane_[p], p >= 3);
    }
    return true;
}

}  // namespace softgl
