#include "softgl/pipeline/clip.h"

namespace softgl {

Clipper::Clipper(const Viewport& vp) {
    const double sx = vp.scale_x(), ox = vp.offset_x(), sy = vp.scale_y(), oy = vp.offset_y();
    const double g = kGuardBand;
    auto set = [&](int i, double a, double b, double c, double d) {
        plane_[i][0] = a; plane_[i][1] = b; plane_[i][2] = c; plane_[i][3] = d;
    };
    set(0, 0, 0, 0, 1);            // w >= 0 (implied by near, far; first: later planes see w >= 0)
    set(1, 0, 0, 1, 1);            // z + w >= 0         (ES 3.0 §2.17: -w <= z)
    set(2, 0, 0, -1, 1);           // w - z >= 0         (z <= w)
    // Window x = sx * x/w + ox >= -g  <=>  sx*x + (ox + g)*w >= 0 (for w > 0; w is clipped first).
    set(3, sx, 0, 0, ox + g);
    set(4, -sx, 0, 0, g - ox);     // sx*x/w + ox <= g
    set(5, 0, sy, 0, oy + g);
    set(6, 0, -sy, 0, g - oy);
}

namespace {

// An exact sum of products (Shewchuk's expansion arithmetic: the sum is kept as non-overlapping
// doubles, built with Knuth's TwoSum and Dekker's TwoProduct), rounded once at the end. Plain double
// operations: the same result on every CPU. Cancellation between the terms costs nothing, whatever
// their magnitudes (float32 positions span 2^-149 .. 2^128). Room for 16 doubles: a clip plane has
// at most two non-zero coefficients, so intersect() adds at most four triple products.
class ExactSum {
public:
    void add_product(double a, double b) {
        const double p = a * b;
        add(p);
        add(product_error(a, b, p));
    }
    void add_product(double n, double a, double b) {   // n * a * b
        const double p = a * b;
        const double e = product_error(a, b, p);
        add_product(n, p);
        add_product(n, e);
    }
    double value() const {   // the components grow in magnitude: sum the smallest first
        double v = 0;
        for (int i = 0; i < count_; ++i) v += part_[i];
        return v;
    }

private:
    void add(double x) {   // Grow-Expansion with zero elimination
        if (x == 0) return;   // most product errors: products of float32 values are exact
        int m = 0;
        for (int i = 0; i < count_; ++i) {
            const double s = x + part_[i];
            const double bv = s - x;
            const double err = (x - (s - bv)) + (part_[i] - bv);
            x = s;
            if (err != 0) part_[m++] = err;
        }
        if (x != 0) part_[m++] = x;
        count_ = m;
    }
    static double product_error(double a, double b, double p) {   // a * b - p, exactly
        double ah, al, bh, bl;
        split(a, ah, al);
        split(b, bh, bl);
        return ((ah * bh - p) + ah * bl + al * bh) + al * bl;
    }
    static void split(double a, double& hi, double& lo) {   // Veltkamp: 26 + 26 bits
        const double c = 134217729.0 * a;   // 2^27 + 1
        hi = c - (c - a);
        lo = a - hi;
    }
    double part_[16];
    int count_ = 0;
};

// Distance of v to the plane (coefficients p), exact and rounded once: its sign is exact.
double exact_distance(const double* p, const Vec4d& v) {
    const double c[4] = {v.x, v.y, v.z, v.w};
    ExactSum d;
    for (int j = 0; j < 4; ++j)
        if (p[j] != 0) d.add_product(p[j], c[j]);
    return d.value();
}

// The point where the segment from `in` (distance din >= 0) to `out` (dout < 0) crosses the plane
// n: P = (din * out - dout * in) / (din - dout), a combination of the two with weights in [0, 1].
// Always computed from the inside vertex, from those two alone: see the watertightness note in
// clip.h. No parameter t is involved, so nothing needs clamping.
//
// The numerator is evaluated as sum_j n_j (in_j out_k - in_k out_j) (the segment's Plucker
// coordinates), exactly (ExactSum), and so are the distances: P is the exact crossing of the two
// (double) endpoints up to three roundings per coordinate. Interpolating in + t (out - in) instead
// leaves an error of about 2^-53 of the larger endpoint, which is more than the point itself when
//  - the crossing lies next to a tiny vertex (w = -1e-6 behind the eye) and the other has w = 1,
//  - or the edge joins two vertices at, say, +-1e30 and crosses a guard-band plane near 0.
// On a plane the constrained coordinate cancels exactly: the crossing of w = 0 has w = 0.
ClipVertex intersect(const ClipVertex& in, double din, const ClipVertex& out, double dout,
                     const double* plane) {
    const double a[4] = {in.position.x, in.position.y, in.position.z, in.position.w};
    const double b[4] = {out.position.x, out.position.y, out.position.z, out.position.w};
    double p[4];
    for (int k = 0; k < 4; ++k) {
        ExactSum sum;
        for (int j = 0; j < 4; ++j) {
            if (plane[j] == 0 || j == k) continue;
            sum.add_product(plane[j], a[j], b[k]);
            sum.add_product(-plane[j], a[k], b[j]);
        }
        p[k] = sum.value();
    }
    // din - dout >= max(din, -dout) > 0 even rounded: the weights stay in [0, 1].
    const double scale = 1.0 / (din - dout);
    ClipVertex r;
    r.position = {p[0] * scale, p[1] * scale, p[2] * scale, p[3] * scale};
    for (int k = 0; k < 3; ++k) r.weight[k] = (din * out.weight[k] - dout * in.weight[k]) * scale;
    return r;
}

// Removes the vertices at the clip-space origin (w < kMinClippedW, see clip.h) from polygon
// v[0..n-1]; returns the number left, or 0 when fewer than 3 are.
int drop_origin(ClipVertex* v, int n) {
    int m = 0;
    for (int i = 0; i < n; ++i)
        if (v[i].position.w >= kMinClippedW) v[m++] = v[i];
    return m < 3 ? 0 : m;
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
    if (planes == 0) return drop_origin(out, 3);

    ClipVertex buffer[kMaxClipVertices];
    ClipVertex* src = out;
    ClipVertex* dst = buffer;
    int n = 3;
    for (int p = 0; p < kClipPlaneCount; ++p) {   // fixed order: w >= 0, near, far, guard band
        if (!(planes & (1u << p))) continue;
        double d[kMaxClipVertices];
        for (int i = 0; i < n; ++i) d[i] = exact_distance(plane_[p], src[i].position);
        int m = 0;
        for (int i = 0; i < n; ++i) {
            const int j = i + 1 == n ? 0 : i + 1;
            const bool in_i = d[i] >= 0, in_j = d[j] >= 0;
            if (in_i) dst[m++] = src[i];
            if (in_i && !in_j) dst[m++] = intersect(src[i], d[i], src[j], d[j], plane_[p]);
            if (!in_i && in_j) dst[m++] = intersect(src[j], d[j], src[i], d[i], plane_[p]);
        }
        n = m;
        if (n < 3) return 0;
        ClipVertex* t = src; src = dst; dst = t;
    }
    if (src != out)
        for (int i = 0; i < n; ++i) out[i] = src[i];
    return drop_origin(out, n);
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
    for (int p = 0; planes != 0 && p < kClipPlaneCount; ++p) {
        if (!(planes & (1u << p))) continue;
        const double d0 = exact_distance(plane_[p], out[0].position);
        const double d1 = exact_distance(plane_[p], out[1].position);
        const bool in0 = d0 >= 0, in1 = d1 >= 0;
        if (!in0 && !in1) return false;
        if (in0 && !in1) out[1] = intersect(out[0], d0, out[1], d1, plane_[p]);
        if (!in0 && in1) out[0] = intersect(out[1], d1, out[0], d0, plane_[p]);
    }
    // A segment with an end at the origin (see clip.h) divides to a single point: nothing to draw.
    return out[0].position.w >= kMinClippedW && out[1].position.w >= kMinClippedW;
}

}  // namespace softgl
