#include "softgl/pipeline/bin.h"

#include <algorithm>

namespace softgl {

TileGrid::TileGrid(int32_t w, int32_t h)
    : width(w), height(h), tiles_x((w + kTileSize - 1) / kTileSize),
      tiles_y((h + kTileSize - 1) / kTileSize) {}

TileRect TileGrid::rect(size_t tile) const {
    const int32_t tx = int32_t(tile % size_t(tiles_x)), ty = int32_t(tile / size_t(tiles_x));
    TileRect r;
    r.x0 = tx * kTileSize;
    r.y0 = ty * kTileSize;
    r.x1 = std::min(r.x0 + kTileSize, width);
    r.y1 = std::min(r.y0 + kTileSize, height);
    return r;
}

void Bins::reset(const TileGrid& grid) {
    for (uint32_t t : occupied_) lists_[t].clear();
    occupied_.clear();
    grid_ = grid;
    if (lists_.size() != grid.count()) lists_.resize(grid.count()), lists_changed_ = true;
    tiles_skipped = 0;
    quad_pixels_bound = 0;
}

void Bins::begin_gather(const TileGrid& grid, const Bins* parts, size_t count) {
    reset(grid);
    lists_changed_ = true;   // gather_tile resizes the occupied tiles' lists
    marks_.resize(grid.count());
    for (size_t i = 0; i < count; ++i)
        for (uint32_t t : parts[i].occupied_)
            if (!marks_[t]) marks_[t] = 1, occupied_.push_back(t);
    for (uint32_t t : occupied_) marks_[t] = 0;
}

void Bins::checkerboard_order(std::vector<uint32_t>& out) const {
    out.clear();
    const size_t tiles_x = size_t(grid_.tiles_x), tiles_y = size_t(grid_.tiles_y);
    if (occupied_.size() * 8 < grid_.count()) {
        // Few tiles (small draws): sort them by (parity, tile), a division each.
        for (uint32_t t : occupied_) out.push_back(uint32_t((t / tiles_x + t % tiles_x) & 1) << 31 | t);
        std::sort(out.begin(), out.end());
        for (uint32_t& t : out) t &= ~(uint32_t(1) << 31);
        return;
    }
    // Row by row, every other tile (no division per tile).
    for (size_t parity = 0; parity < 2; ++parity)
        for (size_t ty = 0; ty < tiles_y; ++ty)
            for (size_t t = ty * tiles_x + ((ty + parity) & 1); t < (ty + 1) * tiles_x; t += 2)
                if (!lists_[t].empty()) out.push_back(uint32_t(t));
}

void Bins::add(const std::vector<PrimitiveSetup>& prims, size_t first) {
    if (first < prims.size()) add(prims.data() + first, prims.size() - first, uint32_t(first));
}

void Bins::gather_tile(size_t t, const Bins* parts, size_t count, const uint32_t* index_base) {
    std::vector<uint32_t>& list = lists_[t];
    size_t total = 0;
    for (size_t i = 0; i < count; ++i) total += parts[i].lists_[t].size();
    list.resize(total);   // every element is written below (total > 0: an occupied tile)
    uint32_t* dst = list.data();
    for (size_t i = 0; i < count; ++i) {
        const std::vector<uint32_t>& part = parts[i].lists_[t];
        const uint32_t base = index_base[i];
        for (size_t k = 0; k < part.size(); ++k) dst[k] = base + part[k];
        dst += part.size();
    }
}

void Bins::add(const PrimitiveSetup* prims, size_t count, uint32_t index_base) {
    for (size_t i = 0; i < count; ++i) {
        const PrimitiveSetup& p = prims[i];
        const uint32_t n = index_base + uint32_t(i);
        quad_pixels_bound += uint64_t(p.x1 - p.x0 + 2) * uint64_t(p.y1 - p.y0 + 2);
        // Boxes lie inside the target (0 <= x0 < x1): shifts, not signed divisions.
        const int32_t tx0 = int32_t(uint32_t(p.x0) / kTileSize), tx1 = int32_t(uint32_t(p.x1 - 1) / kTileSize);
        const int32_t ty0 = int32_t(uint32_t(p.y0) / kTileSize), ty1 = int32_t(uint32_t(p.y1 - 1) / kTileSize);
        if (tx0 == tx1 && ty0 == ty1) {   // the common case: a small primitive in one tile
            append(size_t(ty0) * grid_.tiles_x + tx0, n);
            continue;
        }
        for (int32_t ty = ty0; ty <= ty1; ++ty) {
            for (int32_t tx = tx0; tx <= tx1; ++tx) {
                // Reject the tile if its part of the bounding box is outside one edge (same exact
                // corner test as the rasterizer's blocks).
                const int64_t X0 = int64_t(std::max(tx * kTileSize, p.x0)) * kSubPixel;
                const int64_t X1 = int64_t(std::min((tx + 1) * kTileSize, p.x1)) * kSubPixel;
                const int64_t Y0 = int64_t(std::max(ty * kTileSize, p.y0)) * kSubPixel;
                const int64_t Y1 = int64_t(std::min((ty + 1) * kTileSize, p.y1)) * kSubPixel;
                bool outside = false;
                for (int i = 0; i < p.edge_count && !outside; ++i) {
                    const int64_t a = p.a[i], b = p.b[i];
                    outside = a * (a > 0 ? X1 : X0) + b * (b > 0 ? Y1 : Y0) + p.c[i] < 0;
                }
                if (outside) { ++tiles_skipped; continue; }
                append(size_t(ty) * grid_.tiles_x + tx, n);
            }
        }
    }
}

}  // namespace softgl
