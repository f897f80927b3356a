#include "softgl/pipeline/introspection.h"

#include <algorithm>
#include <map>

#include <tuple>

#include "softgl/pipeline/abuffer.h"
#include "softgl/pipeline/bin.h"

namespace softgl {

void IntrospectionLog::configure(int32_t width, int32_t height) {
    width_ = width;
    height_ = height;
    tiles_x_ = (width + kTileSize - 1) / kTileSize;
    // New vectors, not assign(): assigning an empty vector keeps the old one's capacity, so a
    // full clear would free nothing (the ledger charges what is held: api/draw_calls.cpp).
    std::vector<std::vector<FragmentEvent>>(size_t(tiles_x_) * size_t((height + kTileSize - 1) / kTileSize)).swap(tiles_);
    decltype(draws_)().swap(draws_);
    first_draw_ = 0;
    stored_ = 0;
    attempted_ = 0;
}

size_t IntrospectionLog::tile_of(uint32_t pixel) const {
    const uint32_t x = pixel % uint32_t(width_), y = pixel / uint32_t(width_);
    return size_t(y / kTileSize) * size_t(tiles_x_) + x / kTileSize;
}

void IntrospectionLog::describe_draw(uint32_t draw, const DrawDescription& d) {
    if (draws_.empty()) first_draw_ = draw;
    draws_.resize(size_t(draw - first_draw_) + 1);
    draws_.back() = d;
}

bool IntrospectionLog::push(const FragmentEvent& e) {
    // As in the A-buffer: a running count against the limit, independent of the thread count.
    const uint64_t n = attempted_.fetch_add(1) + 1;
    if (n * sizeof(FragmentEvent) > limit_) return false;
    std::vector<FragmentEvent>& v = tiles_[tile_of(e.pixel)];
    if (v.size() == v.capacity()) v.reserve(v.size() + std::max<size_t>(256, v.size() / 2));
    v.push_back(e);
    stored_.fetch_add(1);
    return true;
}

void IntrospectionLog::mark() {
    mark_sizes_.resize(tiles_.size());
    for (size_t t = 0; t < tiles_.size(); ++t) mark_sizes_[t] = tiles_[t].size();
    mark_draws_ = draws_.size();
    mark_first_draw_ = first_draw_;
    mark_stored_ = stored_.load();
    mark_attempted_ = attempted_.load();
}

void IntrospectionLog::roll_back() {
    for (size_t t = 0; t < tiles_.size() && t < mark_sizes_.size(); ++t) tiles_[t].resize(mark_sizes_[t]);
    draws_.resize(mark_draws_);
    first_draw_ = mark_first_draw_;
    stored_ = mark_stored_;
    attempted_ = mark_attempted_;
}

FragmentEvent* IntrospectionLog::last(uint32_t pixel) {
    std::vector<FragmentEvent>& v = tiles_[tile_of(pixel)];
    return v.empty() || v.back().pixel != pixel ? nullptr : &v.back();
}

void IntrospectionLog::clear(Rect r) {
    if (r.x <= 0 && r.y <= 0 && int64_t(r.x) + r.width >= width_ && int64_t(r.y) + r.height >= height_) {
        configure(width_, height_);
        return;
    }
    uint64_t removed = 0;
    for (auto& v : tiles_) {
        const size_t before = v.size();
        v.erase(std::remove_if(v.begin(), v.end(), [&](const FragmentEvent& e) {
                    const int32_t x = int32_t(e.pixel % uint32_t(width_)), y = int32_t(e.pixel / uint32_t(width_));
                    return x >= r.x && y >= r.y && int64_t(x) < int64_t(r.x) + r.width && int64_t(y) < int64_t(r.y) + r.height;
                }), v.end());
        removed += before - v.size();
    }
    stored_ -= removed;
    attempted_ -= removed;
}

std::vector<FragmentReport> IntrospectionLog::fragments(int32_t x, int32_t y) const {
    std::vector<FragmentReport> out;
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return out;
    const uint32_t pixel = uint32_t(y) * uint32_t(width_) + uint32_t(x);
    // One report per (draw, primitive, sample), in the order the samples first appear, which is
    // submission order: a tile processes its primitives in order.
    std::map<std::tuple<uint32_t, uint32_t, int>, size_t> index;
    auto report = [&](const FragmentEvent& e, int s) -> FragmentReport& {
        auto [it, added] = index.emplace(std::make_tuple(e.draw, e.primitive, s), out.size());
        if (added) {
            FragmentReport r;
            r.draw = e.draw;
            r.primitive = e.primitive;
            r.sample = s;
            r.depth = e.depth;
            if (e.draw >= first_draw_ && e.draw - first_draw_ < draws_.size()) {
                r.description = &draws_[e.draw - first_draw_];
                // The rasterizer clips to the scissor box, so every logged fragment passed it.
                r.scissor = r.description->scissor_test ? 1 : -1;
            }
            out.push_back(r);
        }
        return out[it->second];
    };
    const std::vector<FragmentEvent>& v = tiles_[tile_of(pixel)];
    for (const FragmentEvent& e : v) {
        if (e.pixel != pixel) continue;
        switch (e.kind) {
            case FragmentEvent::DepthStencil: {
                FragmentReport& r = report(e, __builtin_ctz(e.mask));
                r.depth = e.depth;
                r.coverage |= e.mask;
                r.early_tests = e.early;
                r.stencil = e.stencil_pass;
                r.depth_test = e.depth_pass;
                break;
            }
            case FragmentEvent::Discarded:
            case FragmentEvent::Shaded:
                for (int s = 0; s < 16; ++s) {
                    if (!(e.mask & (1u << s))) continue;
                    FragmentReport& r = report(e, s);
                    r.discard = e.kind == FragmentEvent::Discarded ? 0 : 1;
                    if (e.kind == FragmentEvent::Shaded) r.shaded = true, std::copy_n(e.color, 4, r.shader_color);
                    r.coverage |= e.mask;
                }
                break;
            case FragmentEvent::CoverageOps:
                for (int s = 0; s < 16; ++s)
                    if (e.mask & (1u << s)) report(e, s).coverage_ops = (e.mask_after >> s) & 1u;
                break;
            case FragmentEvent::Blend:
            case FragmentEvent::Captured: {
                FragmentReport& r = report(e, __builtin_ctz(e.mask));
                r.depth = e.depth;
                std::copy_n(e.color, 4, r.src);
                if (e.kind == FragmentEvent::Captured) {
                    r.captured = true;
                    break;
                }
                r.blended = true;
                std::copy_n(e.dst, 4, r.dst);
                std::copy_n(e.out, 4, r.out);
                if (r.description) {
                    const double src[4] = {e.color[0], e.color[1], e.color[2], e.color[3]};
                    const double dst[4] = {e.dst[0] / 255.0, e.dst[1] / 255.0, e.dst[2] / 255.0, e.dst[3] / 255.0};
                    double unused[4];
                    blend_f64(r.description->blend, src, dst, unused, r.src_factor, r.dst_factor);
                }
                break;
            }
        }
    }
    for (FragmentReport& r : out) {
        if (r.discard == 0) r.fate = "discarded by the fragment shader";
        else if (r.coverage_ops == 0) r.fate = "removed by alpha-to-coverage / sample coverage";
        else if (r.stencil == 0) r.fate = std::string("failed the stencil test") + (r.early_tests ? " (early)" : "");
        else if (r.depth_test == 0) r.fate = std::string("failed the depth test") + (r.early_tests ? " (early)" : "");
        else if (r.captured) r.fate = "kept in the A-buffer (exact transparency)";
        else if (r.blended) r.fate = r.description && !r.description->blend.is_plain_write() ? "blended" : "written";
        else r.fate = "passed, color not written (color mask)";
    }
    return out;
}

}  // namespace softgl
