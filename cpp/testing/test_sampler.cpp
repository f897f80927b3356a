#include "testing/test_sampler.h"

#include <cmath>

namespace softgl::testing {

using namespace glsl;   // the executor's query types

void TestSampler::sample(const TextureQuery& q) {
    if (q.dim != SamplerDim::Tex2D || q.shadow) throw ExecutionError("the test sampler supports only 2D colour textures");
    for (int l = 0; l < q.lane_count; ++l) {
        float texel[4] = {0, 0, 0, 1};
        auto it = units.find(q.unit[l].i);
        if (it != units.end() && it->second.width > 0 && it->second.height > 0) {
            const TestImage& img = it->second;
            auto at = [&](int x, int y, int c) {
                x = ((x % img.width) + img.width) % img.width;
                y = ((y % img.height) + img.height) % img.height;
                return img.rgba[(static_cast<size_t>(y) * img.width + x) * 4 + c];
            };
            if (q.kind == TextureKind::Size) {
                q.out[0][l].i = img.width;
                q.out[1][l].i = img.height;
                continue;
            }
            if (q.kind == TextureKind::Fetch) {
                int x = q.coord[0][l].i + q.offset[0], y = q.coord[1][l].i + q.offset[1];
                for (int c = 0; c < 4; ++c) texel[c] = (x >= 0 && y >= 0 && x < img.width && y < img.height) ? at(x, y, c) : 0.0f;
            } else {
                float u = q.coord[0][l].f * img.width - 0.5f + q.offset[0];
                float v = q.coord[1][l].f * img.height - 0.5f + q.offset[1];
                if (img.nearest) {
                    int x = static_cast<int>(std::floor(u + 0.5f)), y = static_cast<int>(std::floor(v + 0.5f));
                    for (int c = 0; c < 4; ++c) texel[c] = at(x, y, c);
                } else {
                    int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
                    float fx = u - std::floor(u), fy = v - std::floor(v);
                    for (int c = 0; c < 4; ++c) {
                        float top = at(x0, y0, c) * (1 - fx) + at(x0 + 1, y0, c) * fx;
                        float bottom = at(x0, y0 + 1, c) * (1 - fx) + at(x0 + 1, y0 + 1, c) * fx;
                        texel[c] = top * (1 - fy) + bottom * fy;
                    }
                }
            }
        } else if (q.kind == TextureKind::Size) {
            q.out[0][l].i = 0;
            q.out[1][l].i = 0;
            continue;
        }
        for (int c = 0; c < 4; ++c) {
            if (!q.out[c]) continue;
            if (q.result == BaseType::Float) q.out[c][l].f = texel[c];
            else q.out[c][l].i = static_cast<int32_t>(texel[c]);
        }
    }
}

}  // namespace softgl::testing
