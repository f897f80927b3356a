// The blend lab's window into a draw: hooks that the tile pass (pipeline/tile_pass.cpp) calls at
// the points where a fragment is tested, discarded, shaded and blended. A draw gets a sink only
// when the context has exact transparency (A-buffer) or introspection enabled; the tile pass's
// steps take it as a compile-time parameter (WithSink), so a draw without it runs no hook code.
//
// Threading: the tile pass runs the per-fragment work per screen tile on the thread pool, batch of
// primitives after batch; within a batch each tile is owned by one worker, and it sees the
// draw's primitives in order. Implementations
// keep their records per tile (kTileSize squares), so no locks are needed and the records are in
// submission order within each tile, for any thread count.
#pragma once
#include <cstdint>

#include "softgl/pipeline/depth_stencil.h"
#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/setup.h"
#include "softgl/surface/framebuffer.h"

namespace softgl {

class FragmentSink {
public:
    virtual ~FragmentSink() = default;
    // Once per draw call that reaches the pipeline, before anything else (single-threaded).
    virtual void begin_draw(const State& state, const DefaultFramebuffer& fb) = 0;
    // Before the stencil/depth test of sample s (early: before shading). `depth24` is the
    // fragment's depth as tested; the buffers still hold their values from before the test.
    virtual void before_depth_stencil(const DepthStencilOp& op, const PrimitiveSetup& p, int32_t x,
                                      int32_t y, int s, uint32_t depth24, const uint32_t* depth_buffer,
                                      const uint8_t* stencil_buffer, bool early) = 0;
    // The shader discarded the fragment (pixel j of `quad`) with these samples still alive.
    virtual void discarded(const PrimitiveSetup& p, const Quad& quad, int j, uint32_t mask) = 0;
    // The fragment was shaded: `color` is the shader's output, `mask` its surviving samples.
    virtual void shaded(const PrimitiveSetup& p, int32_t x, int32_t y, uint32_t mask, const float color[4]) = 0;
    // Alpha-to-coverage / SAMPLE_COVERAGE changed the sample mask from `before` to `after`.
    virtual void coverage_ops(const PrimitiveSetup& p, int32_t x, int32_t y, uint32_t before, uint32_t after) = 0;
    // Sample s is about to be blended with `color` (after fog) into `dst`. Returning true means
    // the sink took the sample (the A-buffer keeps it) and the draw must not blend it.
    // `shader_depth` is gl_FragDepth clamped to [0, 1], or negative when the shader does not write it.
    virtual bool before_blend(const PrimitiveSetup& p, int32_t x, int32_t y, int s, const float color[4],
                              const uint8_t dst[4], float shader_depth) = 0;
    // Sample s has been blended; `dst` holds the new value.
    virtual void after_blend(int32_t x, int32_t y, int s, const uint8_t dst[4]) = 0;
};

}  // namespace softgl
