#include "softgl/pipeline/coverage.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace softgl {

namespace {

constexpr double kPi = 3.14159265358979323846;

// The tie rule of setup.cpp's make_edge: left edges (a > 0) and bottom edges (a == 0, b > 0).
bool included(int64_t a, int64_t b) { return a > 0 || (a == 0 && b > 0); }

// Exact edge value a*X + b*Y + c + area_offset at a fixed-point position (X, Y). The integer part is
// exact in int64; near the edge (where it matters) it is below 2^40 and so exact in double too.
inline double edge_value(const PrimitiveSetup& p, int i, int64_t X, int64_t Y) {
    return double(p.a[i] * X + p.b[i] * Y + p.c[i]) + p.area_offset[i];
}

struct Vertex2 {
    double u, v;   // pixel-local coordinates, [0, 1]
};

// Area of the convex polygon ∩ the pixel square at fixed-point corner (X0, Y0).
double polygon_pixel_area(const PrimitiveSetup& p, int64_t X0, int64_t Y0) {
    Vertex2 buf[2][12];
    Vertex2* poly = buf[0];
    Vertex2* next = buf[1];
    int n = 4;
    poly[0] = {0, 0}; poly[1] = {1, 0}; poly[2] = {1, 1}; poly[3] = {0, 1};
    bool clipped = false;
    for (int i = 0; i < p.edge_count; ++i) {
        const double e00 = edge_value(p, i, X0, Y0);
        const double A = double(p.a[i] * kSubPixel), B = double(p.b[i] * kSubPixel);
        // Corner values: sums of integers below 2^53 and the offset, as exact as e00.
        const double e10 = e00 + A, e01 = e00 + B, e11 = e00 + A + B;
        const double emin = std::min(std::min(e00, e10), std::min(e01, e11));
        const double emax = std::max(std::max(e00, e10), std::max(e01, e11));
        if (emin >= 0) continue;       // the whole square is inside this edge
        if (emax <= 0) return 0.0;     // outside (at most touching)
        // Sutherland-Hodgman against e(u, v) = e00 + A u + B v >= 0. An intersection point depends
        // only on the two end values (t = e0 / (e0 - e1)), so the two triangles of a shared edge,
        // whose values are exact negatives, cut the square at bit-identical points.
        double e[12];
        for (int k = 0; k < n; ++k) e[k] = e00 + A * poly[k].u + B * poly[k].v;
        int m = 0;
        for (int k = 0; k < n; ++k) {
            const int k1 = k + 1 == n ? 0 : k + 1;
            if (e[k] >= 0) next[m++] = poly[k];
            if ((e[k] > 0 && e[k1] < 0) || (e[k] < 0 && e[k1] > 0)) {
                const double t = e[k] / (e[k] - e[k1]);
                next[m++] = {poly[k].u + t * (poly[k1].u - poly[k].u),
                             poly[k].v + t * (poly[k1].v - poly[k].v)};
            }
        }
        std::swap(poly, next);
        n = m;
        clipped = true;
        if (n < 3) return 0.0;
    }
    if (!clipped) return 1.0;
    double twice = 0;   // shoelace
    for (int k = 0; k < n; ++k) {
        const int k1 = k + 1 == n ? 0 : k + 1;
        twice += poly[k].u * poly[k1].v - poly[k1].u * poly[k].v;
    }
    return std::min(1.0, std::max(0.0, 0.5 * twice));
}

// ∫_{-r}^{t} sqrt(r^2 - s^2) ds, t in [-r, r].
double circle_integral(double t, double r) {
    const double q = std::max(0.0, r * r - t * t);
    const double ratio = std::min(1.0, std::max(-1.0, t / r));
    return 0.5 * (t * std::sqrt(q) + r * r * std::asin(ratio)) + 0.25 * kPi * r * r;
}

// G(x, y) = ∫_{-r}^{x} clamp(y, -s(t), s(t)) dt with s(t) = sqrt(r^2 - t^2) (circle centred at 0):
// the area of the disk ∩ {X <= x, Y <= y} minus the area of the half disk ∩ {X <= x, Y <= 0}
// (odd in y). Differences of G over the corners of a rectangle give the disk ∩ rectangle.
double disk_corner_integral(double x, double y, double r) {
    x = std::min(r, std::max(-r, x));
    const double sign = y < 0 ? -1.0 : 1.0;
    y = std::fabs(y);
    if (y >= r) return sign * circle_integral(x, r);
    // min(y, s(t)) is s(t) for |t| >= w and y for |t| < w.
    const double w = std::sqrt(r * r - y * y);
    double h;
    if (x <= -w) h = circle_integral(x, r);
    else if (x <= w) h = circle_integral(-w, r) + y * (x + w);
    else h = circle_integral(-w, r) + 2 * w * y + (circle_integral(x, r) - circle_integral(w, r));
    return sign * h;
}

struct DiskFixed {
    int64_t cx, cy, r;   // fixed point (1/256 px); r = size/2 exactly (setup snaps size to 1/128)
};
DiskFixed disk_of(const PrimitiveSetup& p) {
    return {p.origin_x, p.origin_y, int64_t(std::llround(double(p.point_size) * (kSubPixel / 2)))};
}

// Squared distances (fixed point) from the disk centre to the nearest and farthest points of the
// rectangle [X0, X1] x [Y0, Y1].
void rect_distances(const DiskFixed& d, int64_t X0, int64_t Y0, int64_t X1, int64_t Y1,
                    int64_t& near2, int64_t& far2) {
    const int64_t nx = d.cx < X0 ? X0 - d.cx : (d.cx > X1 ? d.cx - X1 : 0);
    const int64_t ny = d.cy < Y0 ? Y0 - d.cy : (d.cy > Y1 ? d.cy - Y1 : 0);
    const int64_t fx = std::max(d.cx - X0, X1 - d.cx), fy = std::max(d.cy - Y0, Y1 - d.cy);
    near2 = nx * nx + ny * ny;
    far2 = fx * fx + fy * fy;
}

double disk_pixel_area(const DiskFixed& d, int64_t X0, int64_t Y0) {
    int64_t near2, far2;
    rect_distances(d, X0, Y0, X0 + kSubPixel, Y0 + kSubPixel, near2, far2);
    if (near2 >= d.r * d.r) return 0.0;
    if (far2 <= d.r * d.r) return 1.0;
    const double inv = 1.0 / kSubPixel;
    // Pixel-local coordinates relative to the centre, in pixels (exact: 8 fractional bits).
    const double x0 = double(X0 - d.cx) * inv, y0 = double(Y0 - d.cy) * inv;
    const double a = disk_rect_area(0, 0, double(d.r) * inv, x0, y0, x0 + 1, y0 + 1);
    return std::min(1.0, std::max(0.0, a));
}

bool valid_grid(int g) { return g >= 1 && g <= 128 && (g & (g - 1)) == 0; }

// Sampled estimate for a polygon: the per-edge integer thresholds make the sample test exact
// (E_int >= t  <=>  E_int + area_offset > 0, or == 0 on an edge the tie rule includes).
struct SampledPolygon {
    int64_t threshold[4];
    explicit SampledPolygon(const PrimitiveSetup& p) {
        for (int i = 0; i < p.edge_count; ++i) {
            const double off = p.area_offset[i];
            if (off == std::floor(off))
                threshold[i] = -int64_t(off) + (included(p.a[i], p.b[i]) ? 0 : 1);
            else
                threshold[i] = int64_t(std::ceil(-off));
        }
    }
    // Only edges that cross the pixel square can reject a sample (an edge >= 0 at all four corners
    // is > 0 at every interior sample), so the count tests those, stepping the edge values
    // incrementally (exact integers).
    int count(const PrimitiveSetup& p, int64_t X0, int64_t Y0, int g) const {
        const int64_t step = kSubPixel / g, first = step / 2;
        int m = 0;
        int64_t e0[4], dx[4], dy[4], t[4];
        for (int i = 0; i < p.edge_count; ++i) {
            const int64_t a = p.a[i], b = p.b[i];
            const int64_t emin = a * (a > 0 ? X0 : X0 + kSubPixel) +
                                 b * (b > 0 ? Y0 : Y0 + kSubPixel) + p.c[i];
            if (double(emin) + p.area_offset[i] >= 0) continue;
            e0[m] = a * (X0 + first) + b * (Y0 + first) + p.c[i];
            dx[m] = a * step;
            dy[m] = b * step;
            t[m] = threshold[i];
            ++m;
        }
        int hits = 0;
        for (int j = 0; j < g; ++j) {
            int64_t e[4];
            for (int i = 0; i < m; ++i) e[i] = e0[i] + j * dy[i];
            for (int k = 0; k < g; ++k) {
                bool in = true;
                for (int i = 0; i < m; ++i) in &= e[i] + k * dx[i] >= t[i];
                hits += in;
            }
        }
        return hits;
    }
};

int disk_sample_count(const DiskFixed& d, int64_t X0, int64_t Y0, int g) {
    const int64_t step = kSubPixel / g, first = step / 2, r2 = d.r * d.r;
    int hits = 0;
    for (int j = 0; j < g; ++j) {
        const int64_t dy = Y0 + first + j * step - d.cy;
        for (int k = 0; k < g; ++k) {
            const int64_t dx = X0 + first + k * step - d.cx;
            hits += dx * dx + dy * dy < r2;   // strictly inside
        }
    }
    return hits;
}

// Block classification over the pixel squares [X0, X1] x [Y0, Y1]: -1 outside (zero area),
// 1 entirely inside, 0 partial. Exact for the area shape, and valid for the sampled estimate too (a
// linear function >= 0 at the corners is > 0 inside; samples are interior points).
int classify(const PrimitiveSetup& p, const DiskFixed& d, int64_t X0, int64_t Y0, int64_t X1,
             int64_t Y1) {
    if (p.area_shape == AreaShape::Disk) {
        int64_t near2, far2;
        rect_distances(d, X0, Y0, X1, Y1, near2, far2);
        if (near2 >= d.r * d.r) return -1;
        return far2 <= d.r * d.r ? 1 : 0;
    }
    bool inside = true;
    for (int i = 0; i < p.edge_count; ++i) {
        const int64_t a = p.a[i], b = p.b[i];
        const int64_t imax = a * (a > 0 ? X1 : X0) + b * (b > 0 ? Y1 : Y0) + p.c[i];
        const int64_t imin = a * (a > 0 ? X0 : X1) + b * (b > 0 ? Y0 : Y1) + p.c[i];
        if (double(imax) + p.area_offset[i] <= 0) return -1;
        if (double(imin) + p.area_offset[i] < 0) inside = false;
    }
    return inside ? 1 : 0;
}

}  // namespace

double disk_rect_area(double cx, double cy, double r, double x0, double y0, double x1, double y1) {
    if (!(r > 0) || !(x1 > x0) || !(y1 > y0)) return 0.0;
    x0 -= cx; x1 -= cx; y0 -= cy; y1 -= cy;
    const double a = disk_corner_integral(x1, y1, r) - disk_corner_integral(x1, y0, r) -
                     disk_corner_integral(x0, y1, r) + disk_corner_integral(x0, y0, r);
    return std::max(0.0, a);
}

double sampled_error_bound(int grid, int edges) {
    const double n = grid;
    const double cells = edges < 0 ? 4 * n + 4 : edges * (2 * n - 1);
    return std::min(1.0, cells / (n * n));
}

double pixel_area(const PrimitiveSetup& p, int32_t px, int32_t py) {
    const int64_t X0 = int64_t(px) * kSubPixel, Y0 = int64_t(py) * kSubPixel;
    if (p.area_shape == AreaShape::Disk) return disk_pixel_area(disk_of(p), X0, Y0);
    return polygon_pixel_area(p, X0, Y0);
}

double pixel_area_sampled(const PrimitiveSetup& p, int32_t px, int32_t py, int grid) {
    if (!valid_grid(grid)) throw std::invalid_argument("grid must be a power of two in 1..128");
    const int64_t X0 = int64_t(px) * kSubPixel, Y0 = int64_t(py) * kSubPixel;
    const int hits = p.area_shape == AreaShape::Disk
                         ? disk_sample_count(disk_of(p), X0, Y0, grid)
                         : SampledPolygon(p).count(p, X0, Y0, grid);
    return double(hits) / double(grid * grid);
}

void rasterize_area(const PrimitiveSetup& p, const TileRect& tile, const SamplePattern& pattern,
                    const AreaOptions& opt, std::vector<Quad>& quads,
                    std::vector<QuadArea>& areas, RasterStats& stats) {
    if (opt.sampled && !valid_grid(opt.grid))
        throw std::invalid_argument("grid must be a power of two in 1..128");
    const int32_t x0 = std::max(p.x0, tile.x0), y0 = std::max(p.y0, tile.y0);
    const int32_t x1 = std::min(p.x1, tile.x1), y1 = std::min(p.y1, tile.y1);
    if (x0 >= x1 || y0 >= y1) return;
    const uint64_t full_pixel = pattern.count == 16 ? 0xFFFFu : ((uint64_t(1) << pattern.count) - 1);
    const bool disk = p.area_shape == AreaShape::Disk;
    const DiskFixed d = disk ? disk_of(p) : DiskFixed{0, 0, 0};
    const SampledPolygon sp(p);
    const int g = opt.grid;
    const double inv_samples = 1.0 / double(g * g);

    auto fraction = [&](int32_t px, int32_t py) -> double {
        const int64_t X0 = int64_t(px) * kSubPixel, Y0 = int64_t(py) * kSubPixel;
        if (opt.sampled) {
            // Shortcut whole pixels (exact, see classify), then count samples.
            const int k = classify(p, d, X0, Y0, X0 + kSubPixel, Y0 + kSubPixel);
            if (k != 0) return k > 0 ? 1.0 : 0.0;
            const int hits = disk ? disk_sample_count(d, X0, Y0, g) : sp.count(p, X0, Y0, g);
            return double(hits) * inv_samples;
        }
        return disk ? disk_pixel_area(d, X0, Y0) : polygon_pixel_area(p, X0, Y0);
    };

    for (int32_t by = y0 & ~(kBlockSize - 1); by < y1; by += kBlockSize) {
        const int32_t cy0 = std::max(by, y0), cy1 = std::min(by + kBlockSize, y1);
        for (int32_t bx = x0 & ~(kBlockSize - 1); bx < x1; bx += kBlockSize) {
            const int32_t cx0 = std::max(bx, x0), cx1 = std::min(bx + kBlockSize, x1);
            // The block's pixel squares (not its sample hull: area reaches the pixel borders).
            const int k = classify(p, d, int64_t(cx0) * kSubPixel, int64_t(cy0) * kSubPixel,
                                   int64_t(cx1) * kSubPixel, int64_t(cy1) * kSubPixel);
            if (k < 0) { ++stats.blocks_rejected; continue; }
            if (k > 0) ++stats.blocks_accepted;
            else ++stats.blocks_partial;
            for (int32_t qy = cy0 & ~1; qy < cy1; qy += 2) {
                for (int32_t qx = cx0 & ~1; qx < cx1; qx += 2) {
                    QuadArea qa{{0, 0, 0, 0}};
                    uint64_t cov = 0;
                    for (int j = 0; j < 4; ++j) {
                        const int32_t px = qx + (j & 1), py = qy + (j >> 1);
                        if (px < cx0 || px >= cx1 || py < cy0 || py >= cy1) continue;
                        const double f = k > 0 ? 1.0 : fraction(px, py);
                        if (f > 0) {
                            qa.fraction[j] = f;
                            cov |= full_pixel << (kQuadPixelBits * j);
                        }
                    }
                    if (cov) {
                        quads.push_back(Quad{qx, qy, cov});
                        areas.push_back(qa);
                        ++stats.quads;
                    }
                }
            }
        }
    }
}

}  // namespace softgl
