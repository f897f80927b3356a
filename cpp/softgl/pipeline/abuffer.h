// The exact transparency reference (SOFTGL_exact_transparency): an A-buffer that keeps every
// blended fragment of every pixel sample instead of blending it, then resolves per sample by
// sorting on depth and compositing in float64 with each fragment's own draw-time blend state.
//
// What "exact" means here (docs/blend_lab.md has the long form):
// - Only draws that really blend (BLEND enabled and not ONE/ZERO/FUNC_ADD) are captured; all
//   other draws write the drawing buffer as usual and form the opaque background.
// - Everything before blending runs as in WebGL: the captured color is the shader's output after
//   fog, and only samples that passed scissor, coverage operations, stencil and depth are kept.
// - The resolve composites back to front (larger window z first; equal z in submission order,
//   i.e. draw then primitive) over the background sample, with ES 3.0 §4.1.7's unorm clamping of
//   source, destination, factors and result, but no rounding until the single final write.
// - A captured fragment of a draw that tested depth without writing it (the usual transparent
//   pass) is tested again at resolve time against the final depth buffer with its draw's depth
//   function, so opaque geometry drawn after the transparent one still hides it.
// - Memory: records are counted against an explicit limit; going over it marks the buffer as
//   overflowed (reported as OUT_OF_MEMORY by the API), and an overflowed buffer refuses to
//   resolve. Fragments are never dropped silently.
#pragma once
#include <atomic>
#include <cstdint>
#include <vector>

#include "softgl/core/capacity_bytes.h"

#include "softgl/surface/blend.h"
#include "softgl/runtime/thread_pool.h"
#include "softgl/surface/framebuffer.h"

namespace softgl {

// Blends in float64 as a unorm target would without rounding (ES 3.0 §4.1.7): src, dst, the
// constant color and the factors are clamped to [0, 1] and so is the result. Channels the color
// mask does not write keep dst. Optionally returns the factors used (for introspection).
void blend_f64(const BlendOp& op, const double src[4], const double dst[4], double out[4],
               double src_factor[4] = nullptr, double dst_factor[4] = nullptr);

// What the A-buffer knows about each captured draw.
struct CapturedDraw {
    BlendOp blend;
    bool retest_depth = false;      // depth test on, depth writes off: test again at resolve
    GLenum depth_func = gl::LESS;
};

struct CapturedFragment {
    double depth;          // window z of the sample in [0, 1]
    float color[4];        // shader output after fog
    float view_depth;      // clip w at the sample (the eye distance for perspective projections)
    uint32_t pixel;        // y * width + x
    uint32_t draw;         // index into the A-buffer's draw table
    uint32_t primitive;    // the primitive's number in its draw
    uint32_t sample;
};

enum class TransparencyResolve { Exact, DepthPeeling, WeightedBlended };

struct ResolveOptions {
    TransparencyResolve mode = TransparencyResolve::Exact;
    int layers = 0;         // depth peeling: composite only the `layers` nearest fragments
    int weight = 7;         // weighted blended OIT: McGuire & Bavoil 2013 equation 7, 8, 9 or 10
};

class ABuffer {
public:
    static constexpr uint64_t kDefaultLimit = uint64_t(1) << 30;   // 1 GiB of fragment records

    void configure(int32_t width, int32_t height, int32_t samples);
    void set_limit(uint64_t bytes) { limit_ = bytes; }
    uint64_t limit() const { return limit_; }
    // Bytes of the records stored, and of those that would be stored without the limit.
    uint64_t bytes_stored() const { return stored_.load() * sizeof(CapturedFragment); }
    uint64_t bytes_needed() const { return attempted_.load() * sizeof(CapturedFragment); }
    uint64_t fragment_count() const { return stored_.load(); }
    // Heap bytes held (records, their tiles' arrays, draws, marks), charged to the context's
    // memory ledger (api/draw_calls.cpp).
    uint64_t capacity_bytes() const {
        return softgl::capacity_bytes(draws_) + softgl::capacity_bytes(tiles_) + softgl::capacity_bytes(mark_sizes_);
    }
    bool overflowed() const { return attempted_.load() > stored_.load(); }

    uint32_t add_draw(const CapturedDraw& d);
    // Called from the worker owning the fragment's tile. False when over the limit (not stored).
    bool push(const CapturedFragment& f);
    // Drops the fragments of the pixels in `region` (a clear); a full clear also resets the
    // overflow state and frees memory.
    void clear(Rect region);
    void reset();
    // A draw that stops part-way (work budget, Ctrl-C, no memory) leaves no record: mark() at
    // its start remembers where every tile's records end, roll_back() drops what came after
    // (docs/reliability.md, "Work budget and Ctrl-C").
    void mark();
    void roll_back();

    // Composites every pixel sample that has fragments over its color in `fb`. With `write`, the
    // result is rounded into `fb` (and the buffer should then be reset). `image` (may be null)
    // receives the unrounded float64 RGBA per pixel, the mean over samples, rows bottom-up.
    void resolve(const ResolveOptions& options, DefaultFramebuffer& fb, ThreadPool& pool, bool write,
                 double* image) const;
    // Per pixel, the largest number of fragments that survive the resolve's depth re-test in one
    // of its samples (the depth complexity that depth peeling needs to be exact).
    void depth_complexity(const DefaultFramebuffer& fb, ThreadPool& pool, uint32_t* out) const;

private:
    size_t tile_of(uint32_t pixel) const;
    // Sorts the tile's fragments by (pixel, sample, back to front, submission) and calls
    // fn(pixel, sample, first, count) for each group, after the resolve-time depth test.
    template <class Fn> void for_each_sample(size_t tile, const DefaultFramebuffer& fb, Fn&& fn) const;

    int32_t width_ = 0, height_ = 0, samples_ = 1, tiles_x_ = 0;
    uint64_t limit_ = kDefaultLimit;
    std::vector<CapturedDraw> draws_;
    std::vector<std::vector<CapturedFragment>> tiles_;
    std::atomic<uint64_t> stored_{0}, attempted_{0};
    std::vector<size_t> mark_sizes_;   // mark(): per tile
    size_t mark_draws_ = 0;
    uint64_t mark_stored_ = 0, mark_attempted_ = 0;
};

// McGuire & Bavoil, "Weighted Blended Order-Independent Transparency", JCGT 2(2), 2013:
// the weight of a fragment of coverage `alpha` at eye distance `z` (equations 7-9) or window
// depth `d` (equation 10).
double wboit_weight(int equation, double alpha, double z, double d);

}  // namespace softgl
