// Fixed shaders written in C++: position from attribute 0, a color from attribute 1, passed
// through as a smooth varying. They let tests exercise the fixed-function pipeline (raster, tests,
// blending, threads) independently of the GLSL compiler.
#pragma once
#include "softgl/pipeline/shader_stage.h"

namespace softgl {

class PassthroughVertexShader : public VertexShader {
public:
    // point_size_location >= 0: gl_PointSize from that attribute's x.
    explicit PassthroughVertexShader(int point_size_location = -1);
    uint32_t used_attributes() const override;
    const VaryingLayout& varying_layout() const override { return layout_; }
    void run(const std::array<AttributeStream, kMaxVertexAttribs>& attribs, size_t count,
             const uint32_t* vertex_ids, const uint32_t* instance_ids, const VertexDestination& out) const override;

private:
    int point_size_location_;
    VaryingLayout layout_;
};

class ColorFragmentShader : public FragmentShader {
public:
    // discard_below >= 0: discard fragments whose alpha is below it. depth_from_red: gl_FragDepth
    // = the color's red component.
    ColorFragmentShader(float discard_below = -1.0f, bool depth_from_red = false)
        : discard_below_(discard_below), depth_from_red_(depth_from_red) {}
    bool may_discard() const override { return discard_below_ >= 0.0f; }
    bool reads_quad_neighbours() const override { return false; }
    bool writes_depth() const override { return depth_from_red_; }
    void run(const FragmentBatch& batch, FragmentResults& out, unsigned worker) const override;

private:
    float discard_below_;
    bool depth_from_red_;
};

}  // namespace softgl
