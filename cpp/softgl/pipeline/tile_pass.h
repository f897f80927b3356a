// The tile pass: a batch's binned primitives to pixels, per screen tile on the thread pool
// (docs/architecture.md, "Life of a draw call"). Each tile sees its primitives in draw order and
// runs them through named steps:
//
//   hidden_surface_first_pass   where primitives pile up, find each pixel's last surviving fragment
//   raster                      quads of the primitive in the tile (area coverage; whole blocks
//                               blended in place with a blend table)
//   early_tests                 depth/stencil before shading (or the pixels the first pass kept)
//   shade                       the fragment batch, then the shader (or its copy, or its constant)
//   write                       the colour kernels on a chunk of lanes
// and, lane by lane where the colour kernels do not apply (discard, late tests, FBOs, blend lab):
//   coverage_ops, late_tests, coverage, fog, blend.
//
// Which steps run and how is the draw plan's (pipeline/draw_plan.h). The blend lab's hooks are a
// compile-time parameter (WithSink): a draw without them has no hook code in its loops.
#pragma once
#include <cstdint>
#include <vector>

#include "softgl/pipeline/bin.h"
#include "softgl/pipeline/chunk_pixels.h"
#include "softgl/pipeline/depth_stencil.h"
#include "softgl/pipeline/draw_inputs.h"
#include "softgl/pipeline/draw_plan.h"
#include "softgl/pipeline/draw_stats.h"
#include "softgl/pipeline/early_depth.h"
#include "softgl/pipeline/fog.h"
#include "softgl/pipeline/fragment_ops.h"
#include "softgl/pipeline/setup.h"
#include "softgl/surface/blend.h"

namespace softgl {

class FragmentSink;
class DrawRollback;

// The batch's set-up primitives: number k is record k & mask of chunk k >> shift (no per-primitive
// table: the chunk's base address is in a few hot cache lines).
struct PrimitiveTable {
    std::vector<const PrimitiveSetup*> chunk;
    unsigned shift = 0;
    uint32_t mask = 0;
    const PrimitiveSetup& operator[](uint32_t k) const { return chunk[k >> shift][k & mask]; }
};

// What one batch gives the tile pass.
struct TileBatch {
    const Bins& bins;
    const PrimitiveTable& prims;
    const VertexShaderOutputs& vertices;   // instance i's vertex v at i * n + v
    const std::vector<uint32_t>& tiles;    // the tiles with work, in the order they go to the pool
};

// Heap bytes of the tile pass's scratch kept between draws on the calling thread (every
// worker's; charged with the draw's other scratch: pipeline/draw.cpp).
uint64_t tile_pass_scratch_bytes();

class TilePass {
public:
    // Per draw. `plan` gets its second step (plan_shading) at the first batch.
    TilePass(const DrawInputs& in, const FragmentOps& ops, const TileGrid& grid, DrawPlan& plan);
    // The batch's tiles, on the pool (or on the caller when they hold little work).
    void run(const TileBatch& batch, DrawStats& stats);
    // Once at the end of the draw: the workers' counters.
    void add_counters(DrawStats& stats) const;
    // Each tile's pixels are kept here before the draw first writes them (pipeline/draw_rollback).
    void set_rollback(DrawRollback* rollback) { rollback_ = rollback; }

    struct Scratch;   // per worker (tile_pass.cpp)

private:
    struct Tile;
    struct Primitive;
    struct Chunk;
    struct Colors;

    void prepare(DrawStats& stats);
    bool small(size_t tile_count) const;
    bool hides(const Tile& t) const;
    template <bool WithSink> void tile(size_t index, unsigned worker);
    void hidden_surface_first_pass(Tile& t);
    void prefetch_ahead(const Tile& t, size_t entry) const;
    void raster(Tile& t, const PrimitiveSetup& p);
    template <bool WithSink> void draw_primitive(Tile& t, const PrimitiveSetup& p, size_t entry);
    void prepare_varyings(Tile& t, Primitive& prim);
    template <bool WithSink> size_t early_tests(Tile& t, const Primitive& prim, Chunk& c);
    template <bool WithSink> size_t early_tests_per_sample(const Primitive& prim, Chunk& c);
    void write_copied_varying(Tile& t, const Primitive& prim, const Chunk& c);
    Colors shade(Tile& t, const Primitive& prim, const Chunk& c);
    Colors flat_colors(Tile& t, Primitive& prim, const Chunk& c);
    Colors run_shader(Tile& t);
    void build_fragment_batch(Tile& t, const Primitive& prim, const Chunk& c);
    void fill_builtins(const PrimitiveSetup& p, FragmentBatch& b, size_t lane, size_t stride, int32_t x, int32_t y) const;
    void gather_quads(Tile& t, const Primitive& prim, const Chunk& c);
    void gather_pixels(Tile& t, const Primitive& prim, const Chunk& c);
    void flush(Tile& t);
    void write(Tile& t, const Chunk& c, const Colors& col);
    template <bool WithSink>
    void per_lane(Tile& t, const Primitive& prim, const Chunk& c, const Colors& col, size_t first, size_t end);
    template <bool WithSink>
    uint16_t coverage_ops(const PrimitiveSetup& p, const Colors& col, size_t lane, int32_t x, int32_t y,
                          uint16_t mask) const;
    template <bool WithSink>
    uint16_t late_tests(Tile& t, const Primitive& prim, size_t lane, int32_t x, int32_t y, uint16_t mask);
    template <bool WithSink>
    void blend(Tile& t, const Primitive& prim, const Colors& col, size_t lane, int32_t x, int32_t y, uint16_t mask,
               const float (*colors)[4]);

    const DrawInputs& in_;
    DrawRollback* rollback_ = nullptr;
    DrawPlan& plan_;
    const State& state_;
    RenderTarget& fb_;
    const FragmentShader& fs_;
    DefaultFramebuffer* const drawing_buffer_;   // the RGBA8 drawing buffer (the blend lab's sink), or null
    uint8_t* const color_bytes_;                 // RenderTarget::color_rgba8 (colour kernels), or null
    FragmentSink* const sink_;                   // the blend lab's hooks when plan_.blend_lab, else null
    const BlendOp blend_;
    const DepthStencilOp ds_;
    const FogOp fog_;
    const SamplePattern& pattern_;
    const TileGrid& grid_;
    const int samples_;
    const int words_;                            // varying words per vertex
    const uint32_t builtins_;                    // FragmentShader::builtins_read
    const uint32_t coverage_mask_;               // SAMPLE_COVERAGE's mask (all ones without it)
    const bool shader_depth_;                    // the shader writes gl_FragDepth
    const float* const unorm8_table_;
    const size_t pitch_;                         // pixels from one row to the next
    const ChunkPixels buffer_pixels_;            // the drawing buffer's pixels as chunks move them
    EarlyDepth quad_depth_test_;                 // plan_.quad_depth's test (prim unset)
    const uint32_t* color_pixels_ = nullptr;     // prefetched pixels: colour (S == 1, written) ...
    const uint32_t* depth_pixels_ = nullptr;     // ... and depth (the quad depth test's), or null
    const FragmentCopies* const copies_;         // plan_.fragment_copies: what the shader copies
    Scratch* scratch_ = nullptr;                 // per worker (prepared at the first batch)
    const BlendTable* blend_table_ = nullptr;    // plan_.blend_table
    const float* constant_color_ = nullptr;      // plan_.constant_color: [c * kChunkLanes + lane]
    const std::vector<int>* smooth_words_ = nullptr;   // the varying words the shader reads,
    const std::vector<int>* flat_words_ = nullptr;     // interpolated and flat
    bool prepared_ = false;
    bool flat_primitives_ = false;               // FragmentShader::run_flat for primitives with equal varyings
    bool texel_words_ = false;                   // plan_.texel_words: FragmentShader::run_words into the pixels
    // Shade full batches (plan_.fragment_batches, decided at prepare): gather the tile's fragments;
    // as single pixels (plan_.no_helper_lanes); a pixel at most once per batch when the write step
    // gathers pixels (colour kernels that read the destination).
    bool gather_ = false, single_pixels_ = false, exclusive_pixels_ = false;
    // The current batch.
    const Bins* bins_ = nullptr;
    const PrimitiveTable* prims_ = nullptr;
    const VertexShaderOutputs* vertices_ = nullptr;
    const std::vector<uint32_t>* tiles_ = nullptr;
};

}  // namespace softgl
