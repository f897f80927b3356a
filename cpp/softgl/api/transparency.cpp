// The blend lab's context side: SOFTGL_exact_transparency (A-buffer capture and resolve) and
// SOFTGL_introspection (the fragment log behind gl.fragments). See api/blendlab.h.
#include <algorithm>

#include "softgl/api/blendlab.h"
#include "softgl/api/context.h"

namespace softgl {

// ---------------------------------------------------------------------------- Context side

BlendLab& Context::blendlab() {
    if (!blendlab_) blendlab_ = std::make_shared<BlendLab>(errors_, framebuffer_);
    return *blendlab_;
}

FragmentSink* Context::blendlab_sink() { return blendlab_ ? blendlab_->sink_for_draw() : nullptr; }

void Context::charge_blend_lab() {
    // Records already held (their own limits, setMemoryLimit, bound them): forced past the budget.
    if (blendlab_) blendlab_memory_.force(blendlab_->capacity_bytes());
}

// ---------------------------------------------------------------------------- BlendLab

BlendLab::BlendLab(ErrorState& errors, const DefaultFramebuffer& fb) : errors_(errors) { on_present(fb); }

bool* BlendLab::capability(GLenum cap) {
    if (cap == gl::EXACT_TRANSPARENCY_SOFTGL && ext_exact) return &exact_transparency;
    if (cap == gl::INTROSPECTION_SOFTGL && ext_introspection) return &introspection;
    return nullptr;
}

FragmentSink* BlendLab::sink_for_draw() {
    draw_ = next_draw_++;
    return exact_transparency || introspection ? this : nullptr;
}

void BlendLab::on_present(const DefaultFramebuffer& fb) {
    // The drawing buffer was replaced (or made): start from nothing.
    width_ = fb.width();
    pattern_ = &sample_pattern(fb.config().samples);
    abuffer_.configure(fb.width(), fb.height(), fb.config().samples);
    log_.configure(fb.width(), fb.height());
    next_draw_ = 0;
    abuffer_overflow_reported_ = log_overflow_reported_ = false;
}

void BlendLab::on_clear(Rect region, uint32_t mask, const DefaultFramebuffer& fb) {
    // A color clear overwrites what the captured and logged fragments contributed to.
    if (!(mask & gl::COLOR_BUFFER_BIT)) return;
    abuffer_.clear(region);
    log_.clear(region);
    const bool full = region.x <= 0 && region.y <= 0 && int64_t(region.x) + region.width >= fb.width() &&
                      int64_t(region.y) + region.height >= fb.height();
    if (full) next_draw_ = 0, abuffer_overflow_reported_ = log_overflow_reported_ = false;
}

void BlendLab::abort_draw() {
    if (began_) {
        abuffer_.roll_back();
        log_.roll_back();
    }
    began_ = false;
    next_draw_ = draw_;
}

void BlendLab::end_draw() {
    began_ = false;
    // Reported once per overflow (until the next full clear), never silently.
    if (abuffer_.overflowed() && !abuffer_overflow_reported_) {
        abuffer_overflow_reported_ = true;
        errors_.record(gl::OUT_OF_MEMORY, "draw (SOFTGL_exact_transparency)",
                       "the A-buffer needs " + std::to_string(abuffer_.bytes_needed()) +
                           " bytes for its fragments, over its limit of " + std::to_string(abuffer_.limit()) +
                           " bytes; fragments past the limit were not kept, so resolve() will refuse. "
                           "Clear, raise the limit with setMemoryLimit(bytes) and draw again");
    }
    if (log_.overflowed() && !log_overflow_reported_) {
        log_overflow_reported_ = true;
        errors_.record(gl::OUT_OF_MEMORY, "draw (SOFTGL_introspection)",
                       "the fragment log is over its limit of " + std::to_string(log_.limit()) +
                           " bytes; fragments(x, y) refuses until the next clear. Raise the limit with "
                           "setMemoryLimit(bytes), or draw less");
    }
}

bool BlendLab::resolve(GLenum mode, int layers, int weight, DefaultFramebuffer& fb, ThreadPool& pool, double* image) {
    const char* call = "resolve";
    if (!ext_exact) {
        errors_.record(gl::INVALID_OPERATION, call, "the SOFTGL_exact_transparency extension is not enabled");
        return false;
    }
    ResolveOptions o;
    if (mode == gl::TRANSPARENCY_EXACT_SOFTGL) o.mode = TransparencyResolve::Exact;
    else if (mode == gl::DEPTH_PEELING_SOFTGL) o.mode = TransparencyResolve::DepthPeeling;
    else if (mode == gl::WEIGHTED_BLENDED_SOFTGL) o.mode = TransparencyResolve::WeightedBlended;
    else {
        errors_.record(gl::INVALID_ENUM, call, enum_name(mode) + " is not a resolve mode");
        return false;
    }
    if (o.mode == TransparencyResolve::DepthPeeling && layers < 1) {
        errors_.record(gl::INVALID_VALUE, call, "depth peeling needs layers >= 1");
        return false;
    }
    if (o.mode == TransparencyResolve::WeightedBlended && (weight < 7 || weight > 10)) {
        errors_.record(gl::INVALID_VALUE, call, "the weight function is McGuire & Bavoil's equation 7, 8, 9 or 10");
        return false;
    }
    if (abuffer_.overflowed()) {
        errors_.record(gl::INVALID_OPERATION, call,
                       "the A-buffer overflowed its memory limit (" + std::to_string(abuffer_.bytes_needed()) +
                           " bytes needed, limit " + std::to_string(abuffer_.limit()) +
                           "); nothing was composited. Clear, raise the limit and draw again");
        return false;
    }
    o.layers = layers;
    o.weight = weight;
    abuffer_.resolve(o, fb, pool, true, image);
    abuffer_.reset();
    return true;
}

bool BlendLab::depth_complexity(const DefaultFramebuffer& fb, ThreadPool& pool, uint32_t* out) {
    if (!ext_exact) {
        errors_.record(gl::INVALID_OPERATION, "depthComplexity", "the SOFTGL_exact_transparency extension is not enabled");
        return false;
    }
    abuffer_.depth_complexity(fb, pool, out);
    return true;
}

bool BlendLab::fragments(int32_t x, int32_t y, std::vector<FragmentReport>& out) {
    if (!ext_introspection) {
        errors_.record(gl::INVALID_OPERATION, "fragments", "the SOFTGL_introspection extension is not enabled");
        return false;
    }
    if (log_.overflowed()) {
        errors_.record(gl::OUT_OF_MEMORY, "fragments",
                       "the fragment log went over its limit of " + std::to_string(log_.limit()) +
                           " bytes since the last clear, so it is incomplete");
        return false;
    }
    out = log_.fragments(x, y);
    return true;
}

// ---------------------------------------------------------------------------- the hooks

double BlendLab::sample_depth(const PrimitiveSetup& p, int32_t x, int32_t y, int s) const {
    return p.depth_at(int64_t(x) * kSubPixel + pattern_->x[s], int64_t(y) * kSubPixel + pattern_->y[s]);
}

FragmentEvent BlendLab::event(FragmentEvent::Kind kind, const PrimitiveSetup& p, int32_t x, int32_t y) const {
    FragmentEvent e{};
    e.kind = kind;
    e.pixel = uint32_t(y) * uint32_t(width_) + uint32_t(x);
    e.draw = draw_;
    e.primitive = p.primitive;
    e.stencil_pass = e.depth_pass = -1;
    e.depth = p.depth_at(int64_t(x) * kSubPixel + kSubPixel / 2, int64_t(y) * kSubPixel + kSubPixel / 2);
    return e;
}

void BlendLab::begin_draw(const State& state, const DefaultFramebuffer& fb) {
    const BlendOp blend = BlendOp::from_state(state, fb.config().alpha);
    const DepthStencilOp ds = DepthStencilOp::from_state(state, fb.config().depth, fb.config().stencil);
    abuffer_.mark();
    log_.mark();
    began_ = true;
    // Only draws that blend are captured: the others are opaque and write the buffer as usual.
    capture_ = exact_transparency && !blend.is_plain_write();
    if (capture_) {
        CapturedDraw d;
        d.blend = blend;
        d.retest_depth = ds.depth_test && !ds.depth_write;
        d.depth_func = ds.depth_func;
        capture_draw_ = abuffer_.add_draw(d);
    }
    log_draw_ = introspection;
    if (log_draw_) {
        DrawDescription d;
        d.blend = blend;
        d.depth_stencil = ds;
        d.scissor_test = state.scissor_test;
        d.coverage_ops = fb.config().samples > 1 && (state.sample_alpha_to_coverage || state.sample_coverage);
        d.fog = state.fog.enabled;
        d.captured = capture_;
        log_.describe_draw(draw_, d);
    }
}

void BlendLab::before_depth_stencil(const DepthStencilOp& op, const PrimitiveSetup& p, int32_t x, int32_t y, int s,
                                    uint32_t depth24, const uint32_t* depth_buffer, const uint8_t* stencil_buffer,
                                    bool early) {
    if (!log_draw_) return;
    FragmentEvent e = event(FragmentEvent::DepthStencil, p, x, y);
    e.mask = uint16_t(1u << s);
    e.early = early;
    e.depth = depth24 / 16777215.0;
    // The same tests as depth_stencil_test (ES 3.0 §4.1.5-4.1.6), evaluated separately on the
    // values from before the test so that the log can say which one failed.
    const StencilFace& face = p.front_facing ? op.front : op.back;
    bool pass = true;
    if (op.stencil_test && stencil_buffer) {
        const uint32_t m = face.value_mask & 0xFFu;
        pass = compare(face.func, uint32_t(face.ref) & m, uint32_t(*stencil_buffer) & m);
        e.stencil_pass = pass ? 1 : 0;
        e.stencil_stored = *stencil_buffer;
    }
    if (pass && op.depth_test && depth_buffer) {
        e.depth_pass = compare(op.depth_func, depth24, *depth_buffer) ? 1 : 0;
        e.depth_stored = *depth_buffer;
    }
    log_.push(e);
}

void BlendLab::discarded(const PrimitiveSetup& p, const Quad& quad, int j, uint32_t mask) {
    if (!log_draw_) return;
    FragmentEvent e = event(FragmentEvent::Discarded, p, quad.x + (j & 1), quad.y + (j >> 1));
    e.mask = uint16_t(mask);
    log_.push(e);
}

void BlendLab::shaded(const PrimitiveSetup& p, int32_t x, int32_t y, uint32_t mask, const float color[4]) {
    if (!log_draw_) return;
    FragmentEvent e = event(FragmentEvent::Shaded, p, x, y);
    e.mask = uint16_t(mask);
    std::copy_n(color, 4, e.color);
    log_.push(e);
}

void BlendLab::coverage_ops(const PrimitiveSetup& p, int32_t x, int32_t y, uint32_t before, uint32_t after) {
    if (!log_draw_) return;
    FragmentEvent e = event(FragmentEvent::CoverageOps, p, x, y);
    e.mask = uint16_t(before);
    e.mask_after = uint16_t(after);
    log_.push(e);
}

bool BlendLab::before_blend(const PrimitiveSetup& p, int32_t x, int32_t y, int s, const float color[4],
                            const uint8_t dst[4], float shader_depth) {
    const double depth = shader_depth >= 0.0f ? double(shader_depth) : sample_depth(p, x, y, s);
    if (log_draw_) {
        FragmentEvent e = event(capture_ ? FragmentEvent::Captured : FragmentEvent::Blend, p, x, y);
        e.mask = uint16_t(1u << s);
        e.depth = depth;
        std::copy_n(color, 4, e.color);
        std::copy_n(dst, 4, e.dst);
        std::copy_n(dst, 4, e.out);
        log_.push(e);
    }
    if (!capture_) return false;
    CapturedFragment f;
    f.depth = depth;
    std::copy_n(color, 4, f.color);
    const int64_t X = int64_t(x) * kSubPixel + pattern_->x[s], Y = int64_t(y) * kSubPixel + pattern_->y[s];
    f.view_depth = float(1.0 / p.eval(p.inv_w, X, Y));
    f.pixel = uint32_t(y) * uint32_t(width_) + uint32_t(x);
    f.draw = capture_draw_;
    f.primitive = p.primitive;
    f.sample = uint32_t(s);
    abuffer_.push(f);   // over the limit: counted, reported by end_draw, resolve refuses
    return true;
}

void BlendLab::after_blend(int32_t x, int32_t y, int s, const uint8_t dst[4]) {
    if (!log_draw_) return;
    // The Blend event pushed by before_blend is the newest of this tile (same worker, no other
    // event in between); when the log is over its limit there is none and nothing is written.
    FragmentEvent* e = log_.last(uint32_t(y) * uint32_t(width_) + uint32_t(x));
    if (e && e->kind == FragmentEvent::Blend && e->mask == (1u << s)) std::copy_n(dst, 4, e->out);
}

}  // namespace softgl
