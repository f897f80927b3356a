#include "softgl/pipeline/chunk_pixels.h"

namespace softgl {

void load_chunk_pixels(const ChunkPixels buffer, const Quad* q, const uint16_t* masks, size_t n, uint32_t* lanes,
                       uint64_t skip) {
    const size_t row_bytes = 4 * buffer.pitch;
    for (size_t i = 0; i < n;) {
        if (skip >> i & 1) {
            i += 4;
            continue;
        }
        const uint8_t* const px = buffer.at(q[i]);
        uint32_t* const l = lanes + 4 * i;
        if (i + 4 <= n && buffer.row_of_four(q + i)) {
            for (int k = 0; k < 4; ++k) std::memcpy(l + 4 * k, px + 8 * k, 8), std::memcpy(l + 4 * k + 2, px + row_bytes + 8 * k, 8);
            i += 4;
            continue;
        }
        if (buffer.inside(q[i])) {
            std::memcpy(l, px, 8), std::memcpy(l + 2, px + row_bytes, 8);
        } else {
            for (size_t j = 0; j < 4; ++j)
                if (masks[4 * i + j]) std::memcpy(l + j, px + 4 * ((j >> 1) * buffer.pitch + (j & 1)), 4);
        }
        ++i;
    }
}

uint64_t store_chunk_pixels(const ChunkPixels buffer, const Quad* q, const uint16_t* masks, size_t n,
                            const uint32_t* lanes, uint64_t skip) {
    const size_t row_bytes = 4 * buffer.pitch;
    uint64_t written = 0;
    for (size_t i = 0; i < n;) {
        if (skip >> i & 1) {   // written already, whole
            written += 16;
            i += 4;
            continue;
        }
        uint8_t* const px = buffer.at(q[i]);
        const uint32_t* const l = lanes + 4 * i;
        uint64_t m4;
        std::memcpy(&m4, masks + 4 * i, 8);
        if (i + 4 <= n) {
            // Masks of 0 or 1: four whole quads when the AND is whole. Tested first: partial quads
            // (edges, lines) fail here, predictably, before the positions are compared.
            uint64_t m1, m2, m3;
            std::memcpy(&m1, masks + 4 * i + 4, 8), std::memcpy(&m2, masks + 4 * i + 8, 8), std::memcpy(&m3, masks + 4 * i + 12, 8);
            if ((m4 & m1 & m2 & m3) == kWholeQuad && buffer.row_of_four(q + i)) {
                for (int k = 0; k < 4; ++k) std::memcpy(px + 8 * k, l + 4 * k, 8), std::memcpy(px + row_bytes + 8 * k, l + 4 * k + 2, 8);
                written += 16;
                i += 4;
                continue;
            }
        }
        written += (m4 * 0x0001000100010001u) >> 48;   // the sum of four masks of 0 or 1
        if (buffer.inside(q[i])) {
            uint8_t* const rows[2] = {px, px + row_bytes};
            if (m4 == kWholeQuad) {
                std::memcpy(rows[0], l, 8), std::memcpy(rows[1], l + 2, 8);
            } else {
                for (int row = 0; row < 2; ++row) {
                    const uint64_t left = (m4 >> (32 * row)) & 0xFFFFu, right = (m4 >> (32 * row + 16)) & 0xFFFFu;
                    const uint64_t keep_new = ((uint64_t(0) - (left != 0)) & 0xFFFFFFFFu) | ((uint64_t(0) - (right != 0)) << 32);
                    uint64_t fresh, old;
                    std::memcpy(&fresh, l + 2 * row, 8);
                    std::memcpy(&old, rows[row], 8);
                    const uint64_t merged = (fresh & keep_new) | (old & ~keep_new);
                    std::memcpy(rows[row], &merged, 8);
                }
            }
        } else {
            for (size_t j = 0; j < 4; ++j)
                if (masks[4 * i + j]) std::memcpy(px + 4 * ((j >> 1) * buffer.pitch + (j & 1)), l + j, 4);
        }
        ++i;
    }
    return written;
}

}  // namespace softgl
