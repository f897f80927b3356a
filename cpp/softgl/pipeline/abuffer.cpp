#include "softgl/pipeline/abuffer.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "softgl/pipeline/bin.h"
#include "softgl/pipeline/depth_stencil.h"

namespace softgl {

namespace {

double clamp01d(double v) { return v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0; }   // NaN -> 0, as clamp01


uint32_t unorm24(double z) { return uint32_t(std::floor(clamp01d(z) * 16777215.0 + 0.5)); }
uint8_t unorm8(double v) { return uint8_t(std::floor(clamp01d(v) * 255.0 + 0.5)); }

}  // namespace

void blend_f64(const BlendOp& op, const double src[4], const double dst[4], double out[4],
               double src_factor[4], double dst_factor[4]) {
    double s[4], d[4];
    for (int c = 0; c < 4; ++c) s[c] = clamp01d(src[c]), d[c] = clamp01d(dst[c]);
    const double k[4] = {op.constant[0], op.constant[1], op.constant[2], op.constant[3]};
    if (!op.has_alpha) d[3] = 1.0;
    for (int c = 0; c < 4; ++c) {
        const bool alpha = c == 3;
        double sf = 1.0, df = 0.0, v = s[c];
        if (!op.is_plain_write()) {
            sf = blend_factor<double>(alpha ? op.src_alpha : op.src_rgb, c, s, d, k);
            df = blend_factor<double>(alpha ? op.dst_alpha : op.dst_rgb, c, s, d, k);
            v = blend_equation<double>(alpha ? op.eq_alpha : op.eq_rgb, s[c], sf, d[c], df);
        }
        if (src_factor) src_factor[c] = sf;
        if (dst_factor) dst_factor[c] = df;
        out[c] = op.write[size_t(c)] ? clamp01d(v) : d[c];
    }
    if (!op.has_alpha) out[3] = 1.0;
}

double wboit_weight(int equation, double alpha, double z, double d) {
    z = std::fabs(z);
    double w;
    switch (equation) {
        case 8: w = 10.0 / (1e-5 + std::pow(z / 10.0, 3.0) + std::pow(z / 200.0, 6.0)); break;
        case 9: w = 0.03 / (1e-5 + std::pow(z / 200.0, 4.0)); break;
        case 10: w = 3e3 * std::pow(1.0 - d, 3.0); break;
        default: w = 10.0 / (1e-5 + std::pow(z / 5.0, 2.0) + std::pow(z / 200.0, 6.0)); break;   // eq. 7
    }
    return alpha * std::clamp(w, 1e-2, 3e3);
}

void ABuffer::configure(int32_t width, int32_t height, int32_t samples) {
    width_ = width;
    height_ = height;
    samples_ = samples;
    tiles_x_ = (width + kTileSize - 1) / kTileSize;
    // New vectors, not assign(): assigning an empty vector keeps the old one's capacity, so a
    // full clear would free nothing (the ledger charges what is held: api/draw_calls.cpp).
    std::vector<std::vector<CapturedFragment>>(size_t(tiles_x_) * size_t((height + kTileSize - 1) / kTileSize)).swap(tiles_);
    decltype(draws_)().swap(draws_);
    stored_ = 0;
    attempted_ = 0;
}

void ABuffer::reset() { configure(width_, height_, samples_); }

void ABuffer::mark() {
    mark_sizes_.resize(tiles_.size());
    for (size_t t = 0; t < tiles_.size(); ++t) mark_sizes_[t] = tiles_[t].size();
    mark_draws_ = draws_.size();
    mark_stored_ = stored_.load();
    mark_attempted_ = attempted_.load();
}

void ABuffer::roll_back() {
    for (size_t t = 0; t < tiles_.size() && t < mark_sizes_.size(); ++t) tiles_[t].resize(mark_sizes_[t]);
    draws_.resize(mark_draws_);
    stored_ = mark_stored_;
    attempted_ = mark_attempted_;
}

size_t ABuffer::tile_of(uint32_t pixel) const {
    const uint32_t x = pixel % uint32_t(width_), y = pixel / uint32_t(width_);
    return size_t(y / kTileSize) * size_t(tiles_x_) + x / kTileSize;
}

uint32_t ABuffer::add_draw(const CapturedDraw& d) {
    draws_.push_back(d);
    return uint32_t(draws_.size() - 1);
}

bool ABuffer::push(const CapturedFragment& f) {
    // The limit is on record bytes, checked on a running count, so whether a scene fits does not
    // depend on the thread count. Past it, fragments are only counted (for the error message).
    const uint64_t n = attempted_.fetch_add(1) + 1;
    if (n * sizeof(CapturedFragment) > limit_) return false;
    std::vector<CapturedFragment>& v = tiles_[tile_of(f.pixel)];
    // Grow by half (not double) so spare capacity stays below half of what is stored.
    if (v.size() == v.capacity()) v.reserve(v.size() + std::max<size_t>(256, v.size() / 2));
    v.push_back(f);
    stored_.fetch_add(1);
    return true;
}

void ABuffer::clear(Rect r) {
    if (r.x <= 0 && r.y <= 0 && int64_t(r.x) + r.width >= width_ && int64_t(r.y) + r.height >= height_) {
        reset();
        return;
    }
    uint64_t removed = 0;
    for (auto& v : tiles_) {
        const size_t before = v.size();
        v.erase(std::remove_if(v.begin(), v.end(), [&](const CapturedFragment& f) {
                    const int32_t x = int32_t(f.pixel % uint32_t(width_)), y = int32_t(f.pixel / uint32_t(width_));
                    return x >= r.x && y >= r.y && int64_t(x) < int64_t(r.x) + r.width && int64_t(y) < int64_t(r.y) + r.height;
                }), v.end());
        removed += before - v.size();
    }
    // Records dropped by the limit cannot be located any more; the overflow stays until a full clear.
    stored_ -= removed;
    attempted_ -= removed;
}

template <class Fn>
void ABuffer::for_each_sample(size_t tile, const DefaultFramebuffer& fb, Fn&& fn) const {
    const std::vector<CapturedFragment>& v = tiles_[tile];
    if (v.empty()) return;
    std::vector<uint32_t> order(v.size());
    std::iota(order.begin(), order.end(), 0u);
    // Back to front: larger window z first; ties in submission order (draw, then primitive).
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        const CapturedFragment &p = v[a], &q = v[b];
        if (p.pixel != q.pixel) return p.pixel < q.pixel;
        if (p.sample != q.sample) return p.sample < q.sample;
        if (p.depth != q.depth) return p.depth > q.depth;
        if (p.draw != q.draw) return p.draw < q.draw;
        return p.primitive < q.primitive;
    });
    std::vector<const CapturedFragment*> group;
    for (size_t i = 0; i < order.size();) {
        const CapturedFragment& head = v[order[i]];
        const int32_t x = int32_t(head.pixel % uint32_t(width_)), y = int32_t(head.pixel / uint32_t(width_));
        const uint32_t stored_depth = fb.depth_sample(x, y, int32_t(head.sample));
        const bool has_depth = fb.config().depth;
        group.clear();
        size_t j = i;
        for (; j < order.size() && v[order[j]].pixel == head.pixel && v[order[j]].sample == head.sample; ++j) {
            const CapturedFragment& f = v[order[j]];
            const CapturedDraw& d = draws_[f.draw];
            if (has_depth && d.retest_depth && !compare(d.depth_func, unorm24(f.depth), stored_depth)) continue;
            group.push_back(&f);
        }
        fn(x, y, int(head.sample), group);
        i = j;
    }
}

void ABuffer::resolve(const ResolveOptions& o, DefaultFramebuffer& fb, ThreadPool& pool, bool write,
                      double* image) const {
    const int S = samples_;
    if (image) {
        // Pixels without fragments show the background.
        for (int32_t y = 0; y < height_; ++y)
            for (int32_t x = 0; x < width_; ++x)
                for (int c = 0; c < 4; ++c) {
                    double sum = 0;
                    for (int s = 0; s < S; ++s) {
                        double v = fb.color_sample(x, y, s)[c] / 255.0;
                        if (c == 3 && !fb.config().alpha) v = 1.0;
                        sum += v;
                    }
                    image[(size_t(y) * size_t(width_) + size_t(x)) * 4 + size_t(c)] = sum / S;
                }
    }
    const bool has_alpha = fb.config().alpha;
    pool.parallel_for(tiles_.size(), [&](size_t tile, unsigned) {
        for_each_sample(tile, fb, [&](int32_t x, int32_t y, int s, const std::vector<const CapturedFragment*>& g) {
            uint8_t* px = fb.color_sample(x, y, s);
            double c[4];
            for (int k = 0; k < 4; ++k) c[k] = px[k] / 255.0;
            if (!has_alpha) c[3] = 1.0;
            const double bg[4] = {c[0], c[1], c[2], c[3]};
            if (o.mode == TransparencyResolve::WeightedBlended) {
                double accum[4] = {0, 0, 0, 0}, reveal = 1.0;
                for (const CapturedFragment* f : g) {
                    const double a = clamp01d(f->color[3]);
                    // Premultiplied-alpha draws (source factor ONE) already carry C·α.
                    const bool premultiplied = draws_[f->draw].blend.src_rgb == gl::ONE;
                    const double w = wboit_weight(o.weight, a, f->view_depth, f->depth);
                    for (int k = 0; k < 3; ++k)
                        accum[k] += clamp01d(f->color[k]) * (premultiplied ? 1.0 : a) * w;
                    accum[3] += a * w;
                    reveal *= 1.0 - a;
                }
                if (!g.empty()) {
                    // The paper's composite pass: blendFunc(ONE_MINUS_SRC_ALPHA, SRC_ALPHA) of
                    // (accum.rgb / clamp(accum.a, 1e-4, 5e4), revealage) over the background.
                    const double norm = std::clamp(accum[3], 1e-4, 5e4);
                    for (int k = 0; k < 3; ++k) c[k] = clamp01d(accum[k] / norm * (1.0 - reveal) + bg[k] * reveal);
                    if (has_alpha) c[3] = clamp01d(reveal * (1.0 - reveal) + bg[3] * reveal);
                }
            } else {
                size_t first = 0;
                if (o.mode == TransparencyResolve::DepthPeeling && g.size() > size_t(std::max(0, o.layers)))
                    first = g.size() - size_t(std::max(0, o.layers));   // the nearest `layers` only
                for (size_t i = first; i < g.size(); ++i) {
                    const CapturedFragment& f = *g[i];
                    const double src[4] = {f.color[0], f.color[1], f.color[2], f.color[3]};
                    blend_f64(draws_[f.draw].blend, src, c, c);
                }
            }
            if (write)
                for (int k = 0; k < 4; ++k)
                    if (k < 3 || has_alpha) px[k] = unorm8(c[k]);
            if (image) {
                // Replace this sample's background share of the mean by its composite.
                double* out = image + (size_t(y) * size_t(width_) + size_t(x)) * 4;
                for (int k = 0; k < 4; ++k) out[k] += (c[k] - bg[k]) / S;
            }
        });
    });
}

void ABuffer::depth_complexity(const DefaultFramebuffer& fb, ThreadPool& pool, uint32_t* out) const {
    std::fill(out, out + size_t(width_) * size_t(height_), 0u);
    pool.parallel_for(tiles_.size(), [&](size_t tile, unsigned) {
        for_each_sample(tile, fb, [&](int32_t x, int32_t y, int, const std::vector<const CapturedFragment*>& g) {
            uint32_t& o = out[size_t(y) * size_t(width_) + size_t(x)];
            o = std::max(o, uint32_t(g.size()));
        });
    });
}

}  // namespace softgl
