#include "softgl/pipeline/draw_rollback.h"

#include <algorithm>
#include <cstring>

namespace softgl {

namespace {

// Kept between draws on the calling thread, like the draw's other scratch (pipeline/draw.cpp):
// the copies only grow, so a repeated draw allocates nothing.
struct RollbackScratch {
    std::vector<uint8_t> saved;
    std::vector<std::vector<uint8_t>> copies;
    std::vector<TileRect> rects;
};

RollbackScratch& rollback_scratch() {
    thread_local RollbackScratch scratch;
    return scratch;
}

}  // namespace

uint64_t rollback_scratch_bytes() {
    const RollbackScratch& s = rollback_scratch();
    return capacity_bytes(s.saved) + capacity_bytes(s.copies) + capacity_bytes(s.rects);
}

uint64_t fragment_work_estimate(uint64_t pairs, uint64_t pixels, uint64_t instructions_bound) {
    constexpr uint64_t kMax = ~uint64_t(0);
    const uint64_t per_pixel = instructions_bound > kMax - kFragmentWorkUnits ? kMax : instructions_bound + kFragmentWorkUnits;
    if (pixels && per_pixel > kMax / pixels) return kMax;
    const uint64_t fragments = pixels * per_pixel;
    if (pairs > (kMax - fragments) / kTilePrimitiveWorkUnits) return kMax;
    return fragments + pairs * kTilePrimitiveWorkUnits;
}

bool rollback_needed(bool several_batches, uint64_t fragment_work_estimate, uint64_t budget_left) {
    return several_batches || fragment_work_estimate > std::min(kRollbackWorkThreshold, budget_left);
}

template <class T>
void DrawRollback::add_image_plane(std::vector<T>& storage, const Image& img, size_t offset, size_t per_texel) {
    if (storage.empty()) return;
    const size_t pixel = size_t(img.samples) * per_texel * sizeof(T);
    planes_.push_back({reinterpret_cast<uint8_t*>(storage.data() + offset * per_texel), pixel, size_t(img.width) * pixel});
}

DrawRollback::DrawRollback(RenderTarget& target, const TileGrid& grid)
    : saved_(rollback_scratch().saved), copies_(rollback_scratch().copies), rects_(rollback_scratch().rects) {
    saved_.assign(grid.count(), 0);
    if (copies_.size() < grid.count()) copies_.resize(grid.count());
    if (rects_.size() < grid.count()) rects_.resize(grid.count());
    const size_t samples = size_t(target.config().samples);
    if (DefaultFramebuffer* fb = target.default_framebuffer()) {
        const size_t w = size_t(fb->width());
        if (fb->is_float()) planes_.push_back({reinterpret_cast<uint8_t*>(fb->color_sample_f(0, 0, 0)), 16 * samples, 16 * samples * w});
        else planes_.push_back({fb->color_sample(0, 0, 0), 4 * samples, 4 * samples * w});
        if (uint32_t* d = fb->depth_samples(0, 0)) planes_.push_back({reinterpret_cast<uint8_t*>(d), 4 * samples, 4 * samples * w});
        if (uint8_t* s = fb->stencil_samples(0, 0)) planes_.push_back({s, samples, samples * w});
        return;
    }
    // A framebuffer object: each colour image (one image may serve two outputs: once), the
    // depth and the stencil image (a depth-stencil image: both of its stores).
    std::vector<const Image*> seen;
    auto add_image = [&](Image* img, size_t offset) {
        if (!img) return;
        for (const Image* s : seen)
            if (s == img) return;
        seen.push_back(img);
        add_image_plane(img->color, *img, offset, size_t(img->color_channels()));
        add_image_plane(img->packed, *img, offset, size_t(img->packed_size));
        add_image_plane(img->rgba8, *img, offset, 1);   // 8-bit unorm images: their only storage
        add_image_plane(img->narrow, *img, offset, size_t(Image::narrow_bytes(img->format)));
        add_image_plane(img->integer, *img, offset, size_t(Image::integer_bytes(img->format)));
        add_image_plane(img->depth_words, *img, offset, 1);
        add_image_plane(img->stencil, *img, offset, 1);
    };
    for (int i = 0; i < RenderTarget::kMaxColors; ++i) add_image(target.color_attachment(i).image, target.color_attachment(i).offset);
    add_image(target.depth_image(), target.depth_offset());
    add_image(target.stencil_image(), target.stencil_offset());
}

uint64_t DrawRollback::bytes_bound(RenderTarget& target) {
    const TileGrid none;
    DrawRollback planes(target, none);
    uint64_t bytes = 0;
    for (const Plane& p : planes.planes_) bytes += uint64_t(p.pixel_bytes) * uint64_t(target.width()) * uint64_t(target.height());
    return bytes;
}

void DrawRollback::save_tile(size_t tile, const TileRect& r) {
    size_t bytes = 0;
    for (const Plane& p : planes_) bytes += size_t(r.x1 - r.x0) * p.pixel_bytes * size_t(r.y1 - r.y0);
    std::vector<uint8_t>& copy = copies_[tile];
    if (copy.size() < bytes) copy.resize(bytes);
    uint8_t* out = copy.data();
    for (const Plane& p : planes_) {
        const size_t row = size_t(r.x1 - r.x0) * p.pixel_bytes;
        for (int32_t y = r.y0; y < r.y1; ++y, out += row)
            std::memcpy(out, p.base + size_t(y) * p.pitch + size_t(r.x0) * p.pixel_bytes, row);
    }
    rects_[tile] = r;
    saved_[tile] = 1;
}

void DrawRollback::restore() {
    for (size_t tile = 0; tile < saved_.size(); ++tile) {
        if (!saved_[tile]) continue;
        const TileRect& r = rects_[tile];
        const uint8_t* in = copies_[tile].data();
        for (const Plane& p : planes_) {
            const size_t row = size_t(r.x1 - r.x0) * p.pixel_bytes;
            for (int32_t y = r.y0; y < r.y1; ++y, in += row)
                std::memcpy(p.base + size_t(y) * p.pitch + size_t(r.x0) * p.pixel_bytes, in, row);
        }
    }
}

size_t DrawRollback::bytes_saved() const {
    size_t bytes = 0;
    for (size_t tile = 0; tile < saved_.size(); ++tile) {
        if (!saved_[tile]) continue;
        const TileRect& r = rects_[tile];
        for (const Plane& p : planes_) bytes += size_t(r.x1 - r.x0) * p.pixel_bytes * size_t(r.y1 - r.y0);
    }
    return bytes;
}

}  // namespace softgl
