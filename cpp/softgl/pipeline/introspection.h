// "Explain a pixel" (SOFTGL_introspection): a log of what happened to every fragment sample
// since the last clear, kept per screen tile in submission order, queried per pixel with
// gl.fragments(x, y). The log is written by the FragmentSink hooks of the tile pass
// (pipeline/tile_pass.cpp) and costs nothing when introspection is off (the hooks are not called).
#pragma once
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "softgl/core/capacity_bytes.h"

#include "softgl/surface/blend.h"
#include "softgl/pipeline/depth_stencil.h"
#include "softgl/surface/framebuffer.h"

namespace softgl {

// One step of one fragment (a pixel of a primitive) or of one of its samples.
struct FragmentEvent {
    enum Kind : uint8_t { DepthStencil, Discarded, Shaded, CoverageOps, Blend, Captured };
    uint32_t pixel, draw, primitive;
    uint16_t mask, mask_after;        // samples concerned (bit s = sample s); coverage ops: after
    uint8_t kind, early;
    int8_t stencil_pass, depth_pass;  // DepthStencil: 1 passed, 0 failed, -1 not tested
    uint32_t depth_stored;            // DepthStencil: the depth buffer before the test
    uint8_t stencil_stored;
    double depth;                     // window z (sample position; pixel centre for masks)
    float color[4];                   // Shaded: shader output; Blend/Captured: after fog
    uint8_t dst[4], out[4];           // Blend: destination before and after
};

// What the draw that made a fragment had set, as far as explaining the fragment needs.
struct DrawDescription {
    BlendOp blend;
    DepthStencilOp depth_stencil;
    bool scissor_test = false;
    bool coverage_ops = false;        // alpha-to-coverage or sample coverage active (multisample)
    bool fog = false;
    bool captured = false;            // exact transparency kept its fragments instead of blending
};

// The story of one fragment sample, as gl.fragments(x, y) reports it.
struct FragmentReport {
    uint32_t draw = 0, primitive = 0;
    int sample = 0;
    double depth = 0;                 // window z at the sample
    uint32_t coverage = 0;            // the fragment's samples in this pixel that reached shading or a test
    bool shaded = false;
    float shader_color[4] = {0, 0, 0, 0};
    // 1 passed, 0 failed, -1 not performed
    int scissor = -1, coverage_ops = -1, stencil = -1, depth_test = -1, discard = -1;
    bool early_tests = false;
    bool blended = false, captured = false;
    float src[4] = {0, 0, 0, 0};      // blend source: shader color after fog
    uint8_t dst[4] = {0, 0, 0, 0}, out[4] = {0, 0, 0, 0};
    double src_factor[4] = {0, 0, 0, 0}, dst_factor[4] = {0, 0, 0, 0};
    const DrawDescription* description = nullptr;
    std::string fate;
};

class IntrospectionLog {
public:
    static constexpr uint64_t kDefaultLimit = uint64_t(256) << 20;   // 256 MiB of events

    void configure(int32_t width, int32_t height);
    void set_limit(uint64_t bytes) { limit_ = bytes; }
    uint64_t limit() const { return limit_; }
    uint64_t bytes_stored() const { return stored_.load() * sizeof(FragmentEvent); }
    bool overflowed() const { return attempted_.load() > stored_.load(); }
    // Heap bytes held (events, their tiles' arrays, draw descriptions without their strings,
    // marks), charged to the context's memory ledger (api/draw_calls.cpp).
    uint64_t capacity_bytes() const {
        return softgl::capacity_bytes(tiles_) + softgl::capacity_bytes(draws_) + softgl::capacity_bytes(mark_sizes_);
    }

    void describe_draw(uint32_t draw, const DrawDescription& d);
    // From the worker owning the event's tile; false when over the limit (not stored).
    bool push(const FragmentEvent& e);
    FragmentEvent* last(uint32_t pixel);   // the tile's newest event (to complete a Blend event)
    void clear(Rect region);               // forget the pixels in region; full clear: everything
    // A draw that stops part-way (work budget, Ctrl-C, no memory) leaves no record: mark() at
    // its start remembers where every tile's records end, roll_back() drops what came after
    // (docs/reliability.md, "Work budget and Ctrl-C").
    void mark();
    void roll_back();
    std::vector<FragmentReport> fragments(int32_t x, int32_t y) const;

private:
    size_t tile_of(uint32_t pixel) const;
    int32_t width_ = 0, height_ = 0, tiles_x_ = 0;
    uint64_t limit_ = kDefaultLimit;
    std::vector<std::vector<FragmentEvent>> tiles_;
    std::vector<DrawDescription> draws_;
    uint32_t first_draw_ = 0;             // draws_[k] describes draw first_draw_ + k
    std::atomic<uint64_t> stored_{0}, attempted_{0};
    std::vector<size_t> mark_sizes_;      // mark(): per tile
    size_t mark_draws_ = 0;
    uint32_t mark_first_draw_ = 0;
    uint64_t mark_stored_ = 0, mark_attempted_ = 0;
};

}  // namespace softgl
