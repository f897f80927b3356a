// The blend lab's context-side state: the SOFTGL_exact_transparency and SOFTGL_introspection
// extensions. A Context creates it on the first getExtension of either; until then, and
// whenever both capabilities are off, draws get no FragmentSink and run exactly as before.
#pragma once
#include <string>
#include <vector>

#include "softgl/api/errors.h"
#include "softgl/pipeline/abuffer.h"
#include "softgl/pipeline/fragment_sink.h"
#include "softgl/pipeline/fog.h"
#include "softgl/pipeline/introspection.h"

namespace softgl {

class BlendLab final : public FragmentSink {
public:
    BlendLab(ErrorState& errors, const DefaultFramebuffer& fb);

    bool ext_exact = false, ext_introspection = false;     // extensions enabled (getExtension)
    bool exact_transparency = false, introspection = false; // capabilities (enable/disable)
    bool* capability(GLenum cap);

    // The sink for the next draw (null when both capabilities are off); counts the draw.
    FragmentSink* sink_for_draw();
    // After the draw: reports a memory limit that the draw went over (OUT_OF_MEMORY).
    void end_draw();
    // After a draw that stopped part-way: its records go, as its pixels did (pipeline/draw_rollback.h),
    // and the next draw takes its number.
    void abort_draw();
    void on_clear(Rect region, uint32_t mask, const DefaultFramebuffer& fb);
    void on_present(const DefaultFramebuffer& fb);

    // SOFTGL_exact_transparency entry points. resolve writes into fb and empties the A-buffer;
    // `image` (width*height*4 doubles, may be null) receives the unrounded float64 result.
    bool resolve(GLenum mode, int layers, int weight, DefaultFramebuffer& fb, ThreadPool& pool, double* image);
    bool depth_complexity(const DefaultFramebuffer& fb, ThreadPool& pool, uint32_t* out);
    ABuffer& abuffer() { return abuffer_; }
    IntrospectionLog& log() { return log_; }
    // Heap bytes of the A-buffer and the fragment log (Context::charge_blend_lab).
    uint64_t capacity_bytes() const { return abuffer_.capacity_bytes() + log_.capacity_bytes(); }
    // SOFTGL_introspection: every logged sample of pixel (x, y). False (with an error) if unusable.
    bool fragments(int32_t x, int32_t y, std::vector<FragmentReport>& out);

    // FragmentSink
    void begin_draw(const State& state, const DefaultFramebuffer& fb) override;
    void before_depth_stencil(const DepthStencilOp& op, const PrimitiveSetup& p, int32_t x, int32_t y, int s,
                              uint32_t depth24, const uint32_t* depth_buffer, const uint8_t* stencil_buffer,
                              bool early) override;
    void discarded(const PrimitiveSetup& p, const Quad& quad, int j, uint32_t mask) override;
    void shaded(const PrimitiveSetup& p, int32_t x, int32_t y, uint32_t mask, const float color[4]) override;
    void coverage_ops(const PrimitiveSetup& p, int32_t x, int32_t y, uint32_t before, uint32_t after) override;
    bool before_blend(const PrimitiveSetup& p, int32_t x, int32_t y, int s, const float color[4],
                      const uint8_t dst[4], float shader_depth) override;
    void after_blend(int32_t x, int32_t y, int s, const uint8_t dst[4]) override;

private:
    FragmentEvent event(FragmentEvent::Kind kind, const PrimitiveSetup& p, int32_t x, int32_t y) const;
    double sample_depth(const PrimitiveSetup& p, int32_t x, int32_t y, int s) const;

    ErrorState& errors_;
    ABuffer abuffer_;
    IntrospectionLog log_;
    int32_t width_ = 0;
    const SamplePattern* pattern_ = nullptr;
    uint32_t draw_ = 0;              // index of the current draw since the last full color clear
    uint32_t next_draw_ = 0;
    bool capture_ = false;           // the current draw's blended samples go to the A-buffer
    bool log_draw_ = false;          // the current draw is logged for introspection
    uint32_t capture_draw_ = 0;      // the current draw in the A-buffer's table
    bool began_ = false;             // begin_draw marked the records (abort_draw rolls back to the mark)
    bool abuffer_overflow_reported_ = false, log_overflow_reported_ = false;
};

}  // namespace softgl
