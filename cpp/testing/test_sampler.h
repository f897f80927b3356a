// A simple glsl::TextureSampler for testing shaders without the pipeline: 2D RGBA float images per
// texture unit, REPEAT wrapping, bilinear filtering (or nearest), no mipmaps (the LOD is
// ignored), texelFetch and textureSize. Shadow, 3D, cube and array samplers are not
// supported and raise ExecutionError (never wrong values).
#pragma once
#include <map>
#include <vector>

#include "softgl/glsl/executor.h"

namespace softgl::testing {

struct TestImage {
    int width = 0;
    int height = 0;
    std::vector<float> rgba;  // row 0 first (t = 0), 4 floats per texel
    bool nearest = false;
};

class TestSampler : public glsl::TextureSampler {
public:
    std::map<int, TestImage> units;
    void sample(const glsl::TextureQuery& query) override;
};

}  // namespace softgl::testing
