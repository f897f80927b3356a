#include "softgl/pipeline/draw.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <unordered_map>

#include "softgl/pipeline/assemble.h"
#include "softgl/pipeline/bin.h"
#include "softgl/pipeline/coverage.h"
#include "softgl/surface/blend.h"
#include "softgl/pipeline/depth_stencil.h"
#include "softgl/pipeline/early_depth.h"
#include "softgl/pipeline/fog.h"
#include "softgl/pipeline/fragment_ops.h"
#include "softgl/pipeline/fragment_sink.h"
#include "softgl/pipeline/interpolate.h"
#include "softgl/pipeline/sample_mask.h"
#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/whole_rect.h"
#include "softgl/pipeline/setup.h"
#include "softgl/surface/formats.h"

namespace softgl {

void DrawStats::add(const DrawStats& o) {
    draws += o.draws; vertices_shaded += o.vertices_shaded; primitives += o.primitives;
    primitives_culled += o.primitives_culled; primitives_clipped += o.primitives_clipped;
    primitives_outside += o.primitives_outside; primitives_invalid += o.primitives_invalid;
    primitives_zero_area += o.primitives_zero_area; primitives_rasterized += o.primitives_rasterized;
    tiles_touched += o.tiles_touched; quads += o.quads; blocks_accepted_whole += o.blocks_accepted_whole;
    fragments_shaded += o.fragments_shaded; fragments_killed_early += o.fragments_killed_early;
    fragments_killed_late += o.fragments_killed_late; fragments_discarded += o.fragments_discarded;
    fragments_hidden += o.fragments_hidden; primitives_depth_hidden += o.primitives_depth_hidden;
    samples_written += o.samples_written; samples_blended += o.samples_blended;
    draws_skipped_no_output += o.draws_skipped_no_output; draws_early_depth += o.draws_early_depth;
    draws_blend_table += o.draws_blend_table;
    texture_queries_fast += o.texture_queries_fast;
    draws_plain_write += o.draws_plain_write; seconds_vertex += o.seconds_vertex;
    seconds_setup += o.seconds_setup; seconds_fragment += o.seconds_fragment;
}

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
// Seconds since t0, and t0 becomes now: one clock read between two timed stages.
double lap(Clock::time_point& t0) {
    const Clock::time_point now = Clock::now();
    const double seconds = std::chrono::duration<double>(now - t0).count();
    t0 = now;
    return seconds;
}

float as_float(uint32_t bits) {
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

RasterState raster_state(const State& s, const RenderTarget& fb) {
    RasterState r = RasterState::for_target(fb.width(), fb.height());
    if (s.scissor_test) r.set_scissor(s.scissor.x, s.scissor.y, s.scissor.width, s.scissor.height);
    r.viewport.x = s.viewport.x;
    r.viewport.y = s.viewport.y;
    r.viewport.width = s.viewport.width;
    r.viewport.height = s.viewport.height;
    r.viewport.depth_near = s.depth_range[0];
    r.viewport.depth_far = s.depth_range[1];
    r.cull_face = s.cull_face;
    r.cull_face_mode = s.cull_face_mode;
    r.front_face = s.front_face;
    r.polygon_offset_fill = s.polygon_offset_fill;
    r.polygon_offset_factor = s.polygon_offset_factor;
    r.polygon_offset_units = s.polygon_offset_units;
    r.depth_bits = fb.depth_bits();
    r.samples = fb.config().samples;
    r.point_size_min = 1.0;
    r.point_size_max = 1024.0;   // ALIASED_POINT_SIZE_RANGE (api/context.h limits)
    r.line_width = std::clamp(double(s.line_width), 1.0, 256.0);
    // SOFTGL_smooth shapes (GL 1.5 §3.4-3.5); smoothing is ignored when multisampling (§3.2.1).
    r.line_smooth = s.smooth.line && r.samples == 1;
    r.point_smooth = s.smooth.point && r.samples == 1;
    r.sample_bounds = r.samples == 1 && !s.smooth.polygon;
    return r;
}

// Per-worker scratch, reused across primitives and draws. Each starts on its own cache line: one
// worker's counters must not share a line with the next worker's vectors (written per quad).
constexpr size_t kChunkQuads = 32;   // 128 lanes: the executor's batch
constexpr size_t kChunkLanes = 4 * kChunkQuads;

struct alignas(64) Scratch {
    std::vector<Quad> quads;          // the primitive's quads in this tile
    std::vector<QuadArea> areas;      // SOFTGL_smooth: covered fractions of the quads
    std::vector<float> values;        // the primitive's vertex values of the interpolated words
    std::vector<uint32_t> pixels;     // per lane of a chunk: the destination pixel (S == 1 colour path)
    std::vector<uint16_t> masks;      // per lane of a chunk: surviving sample mask
    std::vector<uint64_t> owners;     // hidden-surface removal: the tile's owner map (OwnerMap)
    std::vector<uint8_t> owns;        // ... and per entry of the tile's list, whether it owns a pixel
    DepthBounds depth_bounds;         // the tile's stored depth bounds (early depth, skips hidden primitives)
    FragmentBatch batch;
    FragmentResults results;
    RasterStats raster;
    DrawStats stats;
};

static_assert(kQuadPixelBits == 16, "a quad's coverage is its four uint16_t pixel masks, pixel 0 first");
static_assert(offsetof(Quad, y) == 4, "a quad's x and y side by side (ChunkPixels::row_of_four)");

// A chunk's destination pixels on the single-sampled RGBA8 drawing buffer, moved between the
// buffer and the chunk's lanes (lane 4 * i + j: pixel j of quad i, masks[lane] its coverage of 0 or 1).
// A quad inside the buffer moves as two 8-byte rows (lanes 0, 1 and 2, 3 are pixels x, x + 1 of
// rows y and y + 1); four side by side (a row of an 8x8 block, as the rasterizer emits them) as
// two 32-byte rows. A partial quad keeps its uncovered pixels' old values (a select, not a branch
// per pixel: the pixels are in this worker's tile). A quad reaching past the buffer's edge moves
// pixel by pixel, covered ones only. Functions of their own: inside the tile pass's lambda the
// loop's values lived on the stack.
struct ChunkPixels {
    uint8_t* color;               // pixel (0, 0)
    size_t pitch;                 // pixels from one row to the next
    int32_t last_x, last_y;       // a quad at x < last_x, y < last_y is inside
    uint8_t* at(const Quad& q) const { return color + 4 * (size_t(q.y) * pitch + size_t(q.x)); }
    bool inside(const Quad& q) const { return q.x < last_x && q.y < last_y; }
    // Whether q[0..3] lie side by side, all inside. x and y as one word: x + 2k does not carry into
    // y, as quads lie in the buffer (x >= 0).
    bool row_of_four(const Quad* q) const {
        uint64_t xy[4];
        for (int k = 0; k < 4; ++k) std::memcpy(&xy[k], &q[k].x, 8);
        return xy[1] == xy[0] + 2 && xy[2] == xy[0] + 4 && xy[3] == xy[0] + 6 && q[0].x + 6 < last_x && q[0].y < last_y;
    }
};
constexpr uint64_t kWholeQuad = 0x0001000100010001u;   // four masks of 1 (S == 1)

// The chunk's runs of four whole quads side by side (bit i: quads i .. i + 3), found as
// store_chunk_pixels walks the chunk: the fused copy kernel writes those straight into the buffer
// (PixelRows), and the two functions below skip them when given them as `skip`.
static_assert(kChunkQuads <= 64, "a chunk's rows of four in one uint64_t");
uint64_t whole_rows_of_four(const ChunkPixels buffer, const Quad* q, const uint16_t* masks, size_t n) {
    uint64_t rows = 0;
    for (size_t i = 0; i + 4 <= n;) {
        uint64_t m[4];
        std::memcpy(m, masks + 4 * i, 32);
        if ((m[0] & m[1] & m[2] & m[3]) == kWholeQuad && buffer.row_of_four(q + i)) {
            rows |= uint64_t(1) << i;
            i += 4;
        } else {
            ++i;
        }
    }
    return rows;
}

__attribute__((noinline)) void load_chunk_pixels(const ChunkPixels buffer, const Quad* q, const uint16_t* masks,
                                                 size_t n, uint32_t* lanes, uint64_t skip = 0) {
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

// Returns the number of pixels written.
__attribute__((noinline)) uint64_t store_chunk_pixels(const ChunkPixels buffer, const Quad* q, const uint16_t* masks,
                                                      size_t n, const uint32_t* lanes, uint64_t skip = 0) {
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

// Hidden-surface removal (DESIGN §4). Without blending, a pixel ends with the colour of the last
// fragment that passed the tests (no discard, no shader depth: the tests come before shading), so
// in a tile where primitives pile up, a first pass runs every primitive's raster and early tests
// and keeps, per pixel, the list entry of the last survivor; the second pass shades only those.
// The owner map holds per quad of the tile four uint16_t owners, laid out like a quad's coverage
// (pixel j in bits 16j..16j+15), so a quad is marked and filtered with a few word operations.
struct OwnerMap {
    static constexpr uint16_t kNone = 0xFFFF;
    static constexpr size_t kQuadsPerRow = size_t(kTileSize / 2);
    static constexpr size_t kQuads = kQuadsPerRow * kQuadsPerRow;
    static constexpr uint64_t kLanes = 0x0001000100010001u;   // one per pixel lane
    uint64_t* quads;
    TileRect rect;
    uint64_t& at(const Quad& q) const {
        return quads[size_t((q.y - rect.y0) >> 1) * kQuadsPerRow + size_t((q.x - rect.x0) >> 1)];
    }
    // survived: the quad's four single-sample masks (lanes of 0 or 1).
    // Returns the number of pixels marked (the lanes' sum lands in the top lane of survived * kLanes).
    uint64_t mark(const Quad& q, uint64_t survived, size_t entry) const {
        const uint64_t keep = survived * 0xFFFFu;   // lanes of 0 or 0xFFFF
        uint64_t& o = at(q);
        o = (o & ~keep) | (uint64_t(entry) * kLanes & keep);
        return (survived * kLanes) >> 48;
    }
    // Marks quads[0, n) with survived = mask_of(i) each; returns the pixels marked. A row of four
    // whole quads side by side (an 8x8 block's row, as the rasterizer emits them) is four
    // consecutive words.
    template <class MaskOf>
    uint64_t mark_all(const Quad* quads, size_t n, size_t entry, const MaskOf& mask_of) const {
        uint64_t marked = 0;
        size_t i = 0;
        for (; i + 4 <= n; i += 4) {
            const uint64_t m[4] = {mask_of(i), mask_of(i + 1), mask_of(i + 2), mask_of(i + 3)};
            if ((m[0] | m[1] | m[2] | m[3]) == 0) continue;   // all failed the depth test
            uint64_t xy[4];
            for (int k = 0; k < 4; ++k) std::memcpy(&xy[k], &quads[i + size_t(k)].x, 8);
            if ((m[0] & m[1] & m[2] & m[3]) == kLanes && xy[1] == xy[0] + 2 && xy[2] == xy[0] + 4 && xy[3] == xy[0] + 6) {
                uint64_t* const o = &at(quads[i]);
                for (int k = 0; k < 4; ++k) o[k] = uint64_t(entry) * kLanes;
                marked += 16;
                continue;
            }
            for (int k = 0; k < 4; ++k)
                if (m[k]) marked += mark(quads[i + size_t(k)], m[k], entry);
        }
        for (; i < n; ++i) marked += mark(quads[i], mask_of(i), entry);
        return marked;
    }
    // The lanes of `covered` whose pixel `entry` owns.
    uint64_t owned(const Quad& q, uint64_t covered, size_t entry) const {
        // 1 in each 16-bit lane of x that is zero ((v & 0x7FFF) + 0x7FFF carries into bit 15 of
        // its own lane only, when v != 0).
        constexpr uint64_t low = 0x7FFF7FFF7FFF7FFFu;
        const uint64_t x = at(q) ^ (uint64_t(entry) * kLanes);
        return covered & (~(((x & low) + low) | x | low) >> 15);
    }
};

// Work is split into chunks of consecutive vertices or primitives that the pool shades and sets up
// in parallel. Each chunk's results land in fixed places (vertices) or are gathered in chunk order
// (primitives, bins), so nothing depends on the thread count.
constexpr size_t kVertexChunk = 1024;   // vertices per vertex-stage job
constexpr size_t kSetupChunk = 2048;    // primitives per setup-and-binning job

struct VertexWorker {
    std::array<AttributeStream, kMaxVertexAttribs> attribs;
    VertexShaderOutputs shaded;
};

// The set-up primitives of one chunk, its counters and its bins (indices local to the chunk).
struct SetupChunk {
    std::vector<PrimitiveSetup> prims;
    SetupStats stats;
};

// The draw's set-up primitives: number k is record k & mask of chunk k >> shift (no per-primitive
// table: the chunk's base address is in a few hot cache lines).
struct PrimitiveTable {
    std::vector<const PrimitiveSetup*> chunk;
    unsigned shift = 0;
    uint32_t mask = 0;
    const PrimitiveSetup& operator[](uint32_t k) const { return chunk[k >> shift][k & mask]; }
};

// Whether a tile's primitives pile up enough for hidden-surface removal's first pass to pay: their
// bounding boxes cover the tile `times` over.
bool piles_up(const std::vector<uint32_t>& list, const PrimitiveTable& prims, const TileRect& rect, int64_t times) {
    const int64_t goal = times * int64_t(rect.x1 - rect.x0) * int64_t(rect.y1 - rect.y0);
    int64_t area = 0;
    for (uint32_t k : list) {
        const PrimitiveSetup& p = prims[k];
        const int64_t x0 = std::max(p.x0, rect.x0), x1 = std::min(p.x1, rect.x1);
        const int64_t y0 = std::max(p.y0, rect.y0), y1 = std::min(p.y1, rect.y1);
        if (x0 < x1 && y0 < y1 && (area += (x1 - x0) * (y1 - y0)) >= goal) return true;
    }
    return false;
}

// Primitives per batch. A batch's working memory is about 340 bytes per primitive (its set-up
// record, a clipped one more) plus its vertices (20 + 4 * varying words bytes each, up to three
// per primitive): ~30 MB for 2^16 triangles with 8 varying words. Large enough that a batch's
// fixed costs (waking the pool three times, the tail of its tile pass) stay below 1% of its work.
constexpr uint32_t kDrawBatchPrimitives = 1u << 16;
std::atomic<uint32_t> batch_primitives{kDrawBatchPrimitives};

// Everything a draw allocates, kept between draws on the calling thread (DESIGN §4: no per-draw
// allocations; buffers only grow, so a repeated draw touches no fresh pages).
struct DrawScratch {
    std::vector<uint32_t> ids, slot_of_position, tiles, index_base;
    std::unordered_map<uint32_t, uint32_t> slot;
    std::vector<VertexWorker> vertex_workers;
    VertexShaderOutputs all;
    std::vector<WindowPosition> window;   // triangles: the batch's vertices projected by setup
    std::vector<SetupChunk> chunks;
    std::vector<Bins> chunk_bins;
    PrimitiveTable prims;
    Bins bins;
    std::vector<Scratch> workers;
    std::vector<uint8_t> touched;   // per tile: had work in an earlier batch of the draw
    FragmentResults constant;         // a uniform-only shader's results (FragmentShader::run_constant)
    std::vector<float> constant_color;   // its output 0 as a chunk's lanes: [c * kChunkLanes + lane]
};

DrawScratch& draw_scratch() {
    thread_local DrawScratch scratch;
    return scratch;
}

// Grows v to at least n elements; never shrinks, so a smaller draw does not zero-fill again.
template <class T>
T* at_least(std::vector<T>& v, size_t n) {
    if (v.size() < n) v.resize(n);
    return v.data();
}

// Runs job(chunk, worker) for chunks [0, count) on the pool. After the first exception (a shader's
// loop limit) the remaining chunks are skipped; parallel_for rethrows it.
template <class Job>
void for_chunks(ThreadPool& pool, size_t count, const Job& job) {
    std::atomic<bool> failed{false};
    pool.parallel_for(count, [&](size_t chunk, unsigned worker) {
        if (failed.load(std::memory_order_relaxed)) return;
        try {
            job(chunk, worker);
        } catch (...) {
            failed = true;
            throw;
        }
    });
}

}  // namespace

namespace {
std::atomic<HiddenSurfaceRemoval> hidden_surface_removal{HiddenSurfaceRemoval::WherePilesUp};
}  // namespace

HiddenSurfaceRemoval set_hidden_surface_removal(HiddenSurfaceRemoval mode) {
    return hidden_surface_removal.exchange(mode);
}

uint32_t draw_batch_primitives() { return batch_primitives.load(std::memory_order_relaxed); }

uint32_t set_draw_batch_primitives(uint32_t primitives) {
    return batch_primitives.exchange(primitives ? std::min(primitives, kDrawBatchPrimitivesMax) : kDrawBatchPrimitives);
}

void draw(const DrawInputs& in, const DrawCall& call, DrawStats& total) {
    DrawStats st;
    st.draws = 1;
    DrawScratch& ds_ = draw_scratch();
    const State& state = in.state;
    RenderTarget& fb = in.target;
    // The RGBA8 drawing buffer (fast colour kernels, blend-lab hooks); null for framebuffer
    // objects and for float drawing buffers (color_format), which write through write_color.
    DefaultFramebuffer* const drawing_buffer =
        fb.default_framebuffer() && !fb.default_framebuffer()->is_float() ? fb.default_framebuffer() : nullptr;
    // Blend lab hooks (`if (sink)` lines): on the drawing buffer only; null = off.
    FragmentSink* const sink = drawing_buffer ? in.sink : nullptr;
    if (sink) sink->begin_draw(in.state, *drawing_buffer);
    const VertexShader& vs = in.vertex_shader;
    const FragmentShader& fs = in.fragment_shader;
    const VaryingLayout& layout = vs.varying_layout();
    const int words = layout.words;

    // ---- what the per-fragment work needs (DESIGN §4) ----
    const auto& config = fb.config();
    const BlendOp blend = BlendOp::from_state(state, config.alpha);
    const DepthStencilOp ds = DepthStencilOp::from_state(state, config.depth, config.stencil);
    const bool writes_color = blend.write[0] || blend.write[1] || blend.write[2] || blend.write[3];
    const bool writes_depth_stencil = (ds.depth_test && ds.depth_write) || ds.stencil_test;
    const bool no_output = !writes_color && !writes_depth_stencil;
    const RasterState rs = raster_state(state, fb);
    const TileGrid grid(fb.width(), fb.height());
    const int per = vertices_per_primitive(call.mode);
    const bool plain_write = blend.is_plain_write();
    // Multisample coverage operations come before the depth and stencil tests (ES 3.0 §4.1.3).
    const bool coverage_ops = config.samples > 1 && (state.sample_alpha_to_coverage || state.sample_coverage);
    const uint32_t coverage_mask = !state.sample_coverage ? 0xFFFFu
        : (coverage_from_value(state.sample_coverage_value, config.samples) ^
           (state.sample_coverage_invert ? 0xFFFFu : 0u));
    const FogOp fog = FogOp::from_state(state);
    const bool early = !fs.may_discard() && !fs.writes_depth() && !coverage_ops;
    const bool tests = ds.depth_test || ds.stencil_test;
    // ES 3.0 §2.15: with RASTERIZER_DISCARD, primitives are dropped right after the vertex stage.
    // With no output possible, primitives are set up (and counted) but nothing is rasterised.
    const bool rasterizes = !state.rasterizer_discard && !no_output;
    if (!state.rasterizer_discard) {
        if (no_output) st.draws_skipped_no_output = 1;
        if (!no_output && plain_write) st.draws_plain_write = 1;
        if (!no_output && early && tests) st.draws_early_depth = 1;
    }

    // ---- the per-tile pass's constants ----
    const SamplePattern& pattern = sample_pattern(config.samples);
    const int S = config.samples;
    std::vector<Scratch>& scratch = ds_.workers;   // grown before the first tile pass
    for (Scratch& w : scratch) w.raster = RasterStats{}, w.stats = DrawStats{};

    // What the fragment shader reads: only these inputs are computed per lane.
    const uint32_t builtins = fs.builtins_read();
    std::vector<int> smooth_words, flat_words;   // filled before the first tile pass
    const ColorKernel kernel = color_kernel(blend);
    const bool all_channels = blend.write[0] && blend.write[1] && blend.write[2] && blend.write[3];
    const float* unorm8_table = unorm8_to_float_table();
    const bool shader_depth = fs.writes_depth();
    const size_t pitch = size_t(fb.width());   // pixels from one row to the next
    // The drawing buffer's pixels as the colour kernels' chunks gather and scatter them (S == 1).
    const ChunkPixels buffer_pixels{drawing_buffer ? drawing_buffer->color_sample(0, 0, 0) : nullptr, pitch,
                                    fb.width() - 1, fb.height() - 1};
    // The common early depth test, the drawing buffer's 24-bit depth and no stencil, runs a quad
    // at a time (pipeline/early_depth); anything else sample by sample below.
    DefaultFramebuffer* const default_fb = fb.default_framebuffer();
    const bool quad_depth = early && ds.depth_test && !ds.stencil_test && !sink && default_fb;
    EarlyDepth quad_depth_test;
    if (quad_depth) {
        quad_depth_test.pattern = &pattern;
        quad_depth_test.func = ds.depth_func;
        quad_depth_test.write = ds.depth_write;
        quad_depth_test.depth = default_fb->depth_samples(0, 0);
        quad_depth_test.pitch = pitch;
    }
    // Primitives hidden in a whole tile skip raster and test (DepthBounds); not with area coverage,
    // which reaches pixels whose centre (the tested sample) is outside the bounding box.
    const bool depth_bounds = quad_depth && !state.smooth.polygon && !state.smooth.line && !state.smooth.point;

    // Single-sampled drawing buffer pixels (as 32-bit words) for prefetching; null when not touched.
    const uint32_t* const color_pixels = drawing_buffer && S == 1 && writes_color
        ? reinterpret_cast<const uint32_t*>(drawing_buffer->color_sample(0, 0, 0)) : nullptr;
    const uint32_t* const depth_pixels = quad_depth && S == 1 ? quad_depth_test.depth : nullptr;
    constexpr int32_t kPrefetchRows = 16;

    // The current batch (see below): its shaded vertices (instance i's vertex v at i * n + v), its
    // set-up primitives, their bins and the tiles with work.
    VertexShaderOutputs& all = ds_.all;
    PrimitiveTable& prims = ds_.prims;
    const Bins* bins = nullptr;
    std::vector<uint32_t>& tiles = ds_.tiles;
    // A uniform-only shader runs once per draw (DESIGN §4) and its colour goes straight to the
    // colour kernels, for every chunk that needs no per-lane colour (set before the first tile pass).
    bool constant = false;
    // A shader that only copies one varying vec4 to its one colour output (FragmentShader::copies)
    // is not run: the colour kernels read that varying's words from the batch (set with `constant`).
    int copied_word = -1;
    // copied_word's place in smooth_words when its four words are interpolated there, or -1: such
    // chunks on the single-sampled drawing buffer skip the batch (write_interpolated_color_lanes).
    int copied_index = -1;
    // With `constant`, single-sampled and blending per channel: the blend as a table (fragment_ops.h).
    BlendTable table;
    const BlendTable* blend_table = nullptr;
    const bool constant_kernels = !(!early && tests) && writes_color && !coverage_ops && !fog.enabled && !sink && drawing_buffer;
    // Hidden-surface removal (OwnerMap): single-sampled, no blending that reads the destination (a
    // float buffer's ONE/ZERO blending reads it: inf * 0 is NaN), tests before shading on the
    // drawing buffer's depth (or none), no stencil, no smoothing, no blend lab.
    const HiddenSurfaceRemoval hsr_mode = hidden_surface_removal.load(std::memory_order_relaxed);
    const bool hides = hsr_mode != HiddenSurfaceRemoval::Off && S == 1 && early && writes_color && plain_write && (!blend.enabled || drawing_buffer) &&
                       !ds.stencil_test && (!ds.depth_test || quad_depth) && !sink &&
                       !state.smooth.polygon && !state.smooth.line && !state.smooth.point;
    auto run_tile = [&](size_t index, unsigned worker) {
        const size_t tile = tiles[index];
        const std::vector<uint32_t>& list = bins->tile(tile);
        Scratch& w = scratch[worker];
        const TileRect rect = grid.rect(tile);
        if (depth_bounds) w.depth_bounds.begin_tile(quad_depth_test, rect);
        w.masks.resize(kChunkLanes);
        w.pixels.resize(kChunkLanes);
        // The fragment batch's arrays only grow (to a whole chunk): no zero fill per chunk.
        FragmentBatch& b = w.batch;
        at_least(b.varyings, size_t(words) * kChunkLanes);
        at_least(b.frag_coord, 4 * kChunkLanes);
        at_least(b.front_facing, kChunkLanes);
        at_least(b.point_coord, 2 * kChunkLanes);
        // Hidden-surface removal's first pass: every primitive's raster and early tests. Its extra
        // raster pays off where bounding boxes cover the tile twice, or three times for a shader that
        // only copies or is constant; such a shader costs less than the pass where early depth
        // already rejects most hidden fragments (100 large depth-tested triangles: 20% slower).
        const bool cheap_shader = constant || copied_word >= 0;
        const bool hide = hides && list.size() > 1 && list.size() < OwnerMap::kNone &&
                          (hsr_mode == HiddenSurfaceRemoval::InEveryTile ||
                           (!(cheap_shader && tests) && piles_up(list, prims, rect, cheap_shader ? 3 : 2)));
        const OwnerMap owners{hide ? at_least(w.owners, OwnerMap::kQuads) : nullptr, rect};
        if (hide) {
            std::fill_n(owners.quads, OwnerMap::kQuads, ~uint64_t(0));
            uint8_t* const owns = at_least(w.owns, list.size());
            std::fill_n(owns, list.size(), uint8_t(0));
            uint16_t* const masks = w.masks.data();
            RasterStats counted_in_second_pass;
            uint64_t survived = 0;
            for (size_t li = 0; li < list.size(); ++li) {
                const PrimitiveSetup& p = prims[list[li]];
                if (depth_bounds && w.depth_bounds.hides(p)) { ++w.stats.primitives_depth_hidden; continue; }
                w.quads.clear();
                rasterize(p, rect, pattern, w.quads, counted_in_second_pass);
                const Quad* const q = w.quads.data();
                if (!quad_depth) {
                    survived += owners.mark_all(q, w.quads.size(), li, [q](size_t i) { return q[i].coverage; });
                    continue;
                }
                for (size_t c0 = 0; c0 < w.quads.size(); c0 += kChunkQuads) {
                    const size_t chunk = std::min(kChunkQuads, w.quads.size() - c0);
                    EarlyDepth t = quad_depth_test;
                    t.prim = &p;
                    w.stats.fragments_killed_early += early_depth_test(t, q + c0, chunk, masks);
                    survived += owners.mark_all(q + c0, chunk, li, [masks](size_t i) {
                        uint64_t m4;
                        std::memcpy(&m4, &masks[4 * i], 8);
                        return m4;
                    });
                }
            }
            uint64_t owned = 0;
            for (size_t i = 0; i < OwnerMap::kQuads; ++i)
                for (int j = 0; j < 4; ++j) {
                    const uint16_t entry = uint16_t(owners.quads[i] >> (16 * j));
                    if (entry != OwnerMap::kNone) owns[entry] = 1, ++owned;
                }
            w.stats.fragments_hidden += survived - owned;
        }
        for (size_t li = 0; li < list.size(); ++li) {
            // A tile's primitives lie far apart in memory when there are many small ones: fetch the
            // setup four primitives ahead and, from it, the vertex values and pixels two ahead, so
            // they arrive in time (tiny_depth_triangles: ~10% faster than two and one ahead).
            if (li + 4 < list.size()) {
                const char* next = reinterpret_cast<const char*>(&prims[list[li + 4]]);
                for (size_t off = 0; off < sizeof(PrimitiveSetup); off += 64) __builtin_prefetch(next + off);
            }
            if (li + 2 < list.size()) {
                const PrimitiveSetup& next = prims[list[li + 2]];
                if (words > 0)
                    for (int v = 0; v < 3; ++v) __builtin_prefetch(&all.varyings[size_t(next.vertex[v]) * size_t(words)]);
                // A small primitive's pixels are cold in the colour and depth buffers: fetch its
                // rows (first and last pixel of each) while the ones before it are drawn.
                const int32_t x0 = std::max(next.x0, rect.x0), x1 = std::min(next.x1, rect.x1);
                const int32_t y0 = std::max(next.y0, rect.y0), y1 = std::min(next.y1, rect.y1);
                if (x0 < x1 && y0 < y1 && y1 - y0 <= kPrefetchRows)
                    for (int32_t y = y0; y < y1; ++y) {
                        const size_t first = size_t(y) * pitch + size_t(x0), last = size_t(y) * pitch + size_t(x1 - 1);
                        if (color_pixels) __builtin_prefetch(color_pixels + first, 1), __builtin_prefetch(color_pixels + last, 1);
                        if (depth_pixels) __builtin_prefetch(depth_pixels + first, 1), __builtin_prefetch(depth_pixels + last, 1);
                    }
            }
            if (hide && !w.owns[li]) continue;   // hidden everywhere in this tile
            const PrimitiveSetup& p = prims[list[li]];
            if (!hide && depth_bounds && w.depth_bounds.hides(p)) { ++w.stats.primitives_depth_hidden; continue; }
            w.quads.clear();
            w.areas.clear();
            const bool area = S == 1 && ((p.kind == PrimitiveKind::Triangle && state.smooth.polygon) ||
                                         (p.kind == PrimitiveKind::Line && state.smooth.line) ||
                                         (p.kind == PrimitiveKind::Point && state.smooth.point));
            if (area) {
                const GLenum hint = p.kind == PrimitiveKind::Triangle ? state.smooth.polygon_hint
                                  : p.kind == PrimitiveKind::Line ? state.smooth.line_hint : state.smooth.point_hint;
                AreaOptions options;
                options.sampled = hint == gl::FASTEST;   // NICEST and DONT_CARE: exact areas
                rasterize_area(p, rect, pattern, options, w.quads, w.areas, w.raster);
            } else if (blend_table && !tests && !hide) {   // covered blocks in place, the rest as quads
                blend_covered_part(p, rect, pattern, *blend_table, buffer_pixels.color, pitch, w.quads, w.raster, w.stats);
            } else {
                rasterize(p, rect, pattern, w.quads, w.raster);
            }
            if (w.quads.empty()) continue;
            const bool constant_chunks = constant && constant_kernels && !area;

            // What the primitive gives every chunk: vertex values of the interpolated words.
            const uint32_t provoking = p.kind == PrimitiveKind::Triangle ? p.vertex[2]
                                     : p.kind == PrimitiveKind::Line ? p.vertex[1] : p.vertex[0];
            const int interpolated = p.kind == PrimitiveKind::Triangle ? 3 : p.kind == PrimitiveKind::Line ? 2 : 0;
            VaryingInterpolation vi;
            const bool interpolate = interpolated && !smooth_words.empty();
            if (interpolate) {
                const size_t count = smooth_words.size();
                w.values.resize(size_t(interpolated) * count);
                for (int v = 0; v < interpolated; ++v)
                    for (size_t i = 0; i < count; ++i)
                        w.values[size_t(v) * count + i] =
                            as_float(all.varyings[size_t(p.vertex[v]) * size_t(words) + size_t(smooth_words[i])]);
                prepare_interpolation(p, interpolated, rect.x0, rect.y0, smooth_words.data(), count, w.values.data(), vi);
            }

            // Chunks of kChunkQuads quads keep every per-lane array in L1.
            for (size_t c0 = 0; c0 < w.quads.size(); c0 += kChunkQuads) {
                // The chunk's quads, compacted in place by early depth/stencil to the `kept` that
                // still cover a sample (lane 4*i + j is pixel j of cq[i]).
                Quad* const cq = w.quads.data() + c0;
                QuadArea* const ca = area ? w.areas.data() + c0 : nullptr;
                const size_t chunk = std::min(kChunkQuads, w.quads.size() - c0);
                uint16_t* const masks = w.masks.data();   // surviving sample mask per lane
                size_t kept = 0;
                if (hide) {
                    // The tests ran in the first pass: keep the pixels this primitive owns.
                    for (size_t qi = 0; qi < chunk; ++qi) {
                        const uint64_t m4 = owners.owned(cq[qi], cq[qi].coverage, li);
                        if (!m4) continue;
                        cq[kept] = cq[qi];
                        std::memcpy(&masks[kept * 4], &m4, 8);
                        ++kept;
                    }
                } else if (early && tests) {
                    // Early depth/stencil (legal when the shader cannot discard or write depth),
                    // then the quads with a surviving sample move to the front (kept <= qi).
                    uint64_t killed_early = 0;
                    if (quad_depth) {
                        EarlyDepth t = quad_depth_test;
                        t.prim = &p;
                        killed_early = early_depth_test(t, cq, chunk, masks);
                    } else {
                        for (size_t qi = 0; qi < chunk; ++qi) {
                            const Quad& quad = cq[qi];
                            for (int j = 0; j < 4; ++j) {
                                uint16_t mask = uint16_t(quad_pixel_mask(quad, j));
                                if (mask) {
                                    const int32_t x = quad.x + (j & 1), y = quad.y + (j >> 1);
                                    uint32_t* depth = fb.depth_samples(x, y);
                                    uint8_t* stencil = ds.stencil_test ? fb.stencil_samples(x, y) : nullptr;
                                    for (int s = 0; s < S; ++s) {
                                        if (!(mask & (1u << s))) continue;
                                        const uint32_t z = fb.depth_word(p.depth_at(int64_t(x) * kSubPixel + pattern.x[s],
                                                                              int64_t(y) * kSubPixel + pattern.y[s]));
                                        if (sink) sink->before_depth_stencil(ds, p, x, y, s, z, depth ? depth + s : nullptr, stencil ? stencil + s : nullptr, true);
                                        if (!depth_stencil_test(ds, p.front_facing, z, depth ? depth + s : nullptr,
                                                                stencil ? stencil + s : nullptr)) {
                                            mask = uint16_t(mask & ~(1u << s));
                                            ++killed_early;
                                        }
                                    }
                                }
                                masks[qi * 4 + size_t(j)] = mask;
                            }
                        }
                    }
                    for (size_t qi = 0; qi < chunk; ++qi) {
                        uint64_t m4;
                        std::memcpy(&m4, &masks[qi * 4], 8);
                        if (!m4) continue;
                        cq[kept] = cq[qi];
                        if (area) ca[kept] = ca[qi];
                        std::memcpy(&masks[kept * 4], &m4, 8);
                        ++kept;
                    }
                    w.stats.fragments_killed_early += killed_early;
                } else {
                    // A quad's coverage is its four pixel masks side by side (quad_pixel_mask).
                    for (size_t qi = 0; qi < chunk; ++qi) std::memcpy(&masks[qi * 4], &cq[qi].coverage, 8);
                    kept = chunk;
                }
                if (kept == 0) continue;
                w.stats.quads += kept;

                const size_t L = kept * 4;
                w.stats.fragments_shaded += L;
                // The colour of lane l, channel c of output o: col[(4 * o + c) * cs + l].
                const FragmentResults& r = w.results;
                // May point at the batch's varying words (uint32_t): read through a may_alias type,
                // so these reads stay after the words' writes (strict aliasing).
                using LaneFloat = float __attribute__((may_alias));
                const LaneFloat* col = ds_.constant_color.data();
                size_t cs = kChunkLanes;
                int outputs = 1;
                bool any_killed = false;
                const bool per_lane_color = area || coverage_ops || fog.enabled || sink || !drawing_buffer;
                if (copied_index >= 0 && interpolate && !constant_chunks && S == 1 && kernel != ColorKernel::Generic &&
                    !(!early && tests) && writes_color && !per_lane_color) {
                    // The copied varying's values go straight into pixels: no fragment batch, and
                    // runs of four whole quads straight into the buffer's rows.
                    uint32_t* const d = w.pixels.data();
                    const uint64_t rows = whole_rows_of_four(buffer_pixels, cq, masks, kept);
                    if (kernel != ColorKernel::Plain || !all_channels) load_chunk_pixels(buffer_pixels, cq, masks, kept, d, rows);
                    write_interpolated_color_lanes(kernel, blend, vi, size_t(copied_index), cq, kept, d,
                                                   PixelRows{buffer_pixels.color, buffer_pixels.pitch, rows});
                    const uint64_t written = store_chunk_pixels(buffer_pixels, cq, masks, kept, d, rows);
                    w.stats.samples_written += written;
                    if (!plain_write) w.stats.samples_blended += written;
                    continue;
                }
                if (!constant_chunks) {
                    // Build the fragment batch: the inputs the shader reads, per lane, structure of
                    // arrays.
                    b.lanes = L;
                    if (builtins & kFrontFacing) std::fill_n(b.front_facing.data(), L, uint8_t(p.front_facing ? 1 : 0));
                    if (interpolate) {
                        interpolate_varyings(vi, cq, kept, b.varyings.data(), L);
                    } else {
                        for (int word : smooth_words)   // points: no interpolation, the vertex's value
                            std::fill_n(&b.varyings[size_t(word) * L], L,
                                        all.varyings[size_t(provoking) * size_t(words) + size_t(word)]);
                    }
                    for (int word : flat_words)
                        std::fill_n(&b.varyings[size_t(word) * L], L, all.varyings[size_t(provoking) * size_t(words) + size_t(word)]);
                    if (builtins & (kFragCoordX | kFragCoordY | kPointCoordS | kPointCoordT | kFragCoordZ | kFragCoordW)) {
                        float* fc = b.frag_coord.data();
                        for (size_t qi = 0; qi < kept; ++qi) {
                            const Quad& quad = cq[qi];
                            for (int j = 0; j < 4; ++j) {
                                const size_t lane = qi * 4 + size_t(j);
                                const int32_t x = quad.x + (j & 1), y = quad.y + (j >> 1);
                                fc[lane] = float(x) + 0.5f;
                                fc[L + lane] = float(y) + 0.5f;
                                float pc[2] = {0, 0};
                                if (p.kind == PrimitiveKind::Point) p.point_coord(x, y, pc);
                                b.point_coord[lane] = pc[0];
                                b.point_coord[L + lane] = pc[1];
                                // The planes at the pixel centre, as PrimitiveSetup::eval computes them.
                                const double fx = pixel_centre_offset(x, p.origin_x), fy = pixel_centre_offset(y, p.origin_y);
                                if (builtins & kFragCoordZ) {   // p.depth_at: plane + offset, clamped to [0, 1]
                                    const double z = (p.depth.c + p.depth.a * fx + p.depth.b * fy) + p.depth_offset;
                                    fc[2 * L + lane] = float(z < 0 ? 0 : (z > 1 ? 1 : z));
                                }
                                if (builtins & kFragCoordW) fc[3 * L + lane] = float(p.inv_w.c + p.inv_w.a * fx + p.inv_w.b * fy);
                            }
                        }
                    }
                    cs = L;
                    if (copied_word >= 0) {   // the colour is the varying's lanes (FragmentShader::copies)
                        col = reinterpret_cast<const LaneFloat*>(b.varyings.data()) + size_t(copied_word) * L;
                    } else {
                        fs.run(b, w.results, worker);
                        for (uint8_t kill : r.killed) any_killed |= kill != 0;
                        col = r.color.data();
                        outputs = r.outputs;
                    }
                }

                // Late tests, blending and the write, per covered sample.
                // Per-lane color changes (area alpha, coverage ops, fog) take the general path.
                // Framebuffer objects (any format) also write through RenderTarget::write_color.
                if (!any_killed && !(!early && tests) && writes_color && !per_lane_color) {
                    // The common case: tests (if any) already done, nothing discarded.
                    auto write_all = [&](auto kernel_tag) {
                        constexpr ColorKernel K = decltype(kernel_tag)::value;
                        for (size_t lane = 0; lane < L; ++lane) {
                            const uint16_t mask = masks[lane];
                            if (!mask) continue;
                            const Quad& quad = cq[lane / 4];
                            const int j = int(lane % 4);
                            const int32_t x = quad.x + (j & 1), y = quad.y + (j >> 1);
                            const float color[4] = {col[lane], col[cs + lane], col[2 * cs + lane], col[3 * cs + lane]};
                            uint8_t* px = drawing_buffer->color_sample(x, y, 0);
                            if (S == 1) {
                                write_color<K>(blend, all_channels, unorm8_table, color, px);
                                w.stats.samples_written++;
                            } else {
                                for (int s = 0; s < S; ++s) {
                                    if (!(mask & (1u << s))) continue;
                                    write_color<K>(blend, all_channels, unorm8_table, color, px + 4 * s);
                                    w.stats.samples_written++;
                                }
                            }
                        }
                    };
                    const uint64_t before = w.stats.samples_written;
                    if (constant_chunks && blend_table) {   // by lookup; rows of four in place
                        uint32_t* const d = w.pixels.data();
                        const uint64_t rows = whole_rows_of_four(buffer_pixels, cq, masks, kept);
                        load_chunk_pixels(buffer_pixels, cq, masks, kept, d, rows);
                        apply_blend_table(*blend_table, cq, kept, d, PixelRows{buffer_pixels.color, pitch, rows});
                        w.stats.samples_written += store_chunk_pixels(buffer_pixels, cq, masks, kept, d, rows);
                    } else if (S == 1 && kernel != ColorKernel::Generic) {
                        // Gather the destination pixels (only when the kernel reads them), blend all
                        // lanes at once, scatter back (ChunkPixels).
                        uint32_t* const d = w.pixels.data();
                        if (kernel != ColorKernel::Plain || !all_channels) load_chunk_pixels(buffer_pixels, cq, masks, kept, d);
                        write_color_lanes(kernel, blend, col, cs, d, L);
                        w.stats.samples_written += store_chunk_pixels(buffer_pixels, cq, masks, kept, d);
                    } else switch (kernel) {
                        case ColorKernel::Plain: write_all(std::integral_constant<ColorKernel, ColorKernel::Plain>{}); break;
                        case ColorKernel::AlphaOver: write_all(std::integral_constant<ColorKernel, ColorKernel::AlphaOver>{}); break;
                        case ColorKernel::Additive: write_all(std::integral_constant<ColorKernel, ColorKernel::Additive>{}); break;
                        case ColorKernel::Generic: write_all(std::integral_constant<ColorKernel, ColorKernel::Generic>{}); break;
                    }
                    if (!plain_write) w.stats.samples_blended += w.stats.samples_written - before;
                    continue;
                }
                // Only shaded chunks come here (constant_chunks implies the case above): cs == L.
                for (size_t lane = 0; lane < L; ++lane) {
                    uint16_t mask = masks[lane];
                    if (!mask) continue;
                    if (any_killed && r.killed[lane]) {
                        w.stats.fragments_discarded++;
                        if (sink) sink->discarded(p, cq[lane / 4], int(lane % 4), mask);
                        continue;
                    }
                    const Quad& quad = cq[lane / 4];
                    const int j = int(lane % 4);
                    const int32_t x = quad.x + (j & 1), y = quad.y + (j >> 1);
                    if (sink) {
                        const float shaded[4] = {col[lane], col[L + lane], col[2 * L + lane], col[3 * L + lane]};
                        sink->shaded(p, x, y, mask, shaded);
                    }
                    if (coverage_ops) {   // before the depth and stencil tests (ES 3.0 §4.1.3)
                        const uint16_t before = mask;
                        if (state.sample_alpha_to_coverage) mask = uint16_t(mask & coverage_from_value(col[3 * L + lane], S));
                        mask = uint16_t(mask & coverage_mask);
                        if (sink) sink->coverage_ops(p, x, y, before, mask);
                        if (!mask) continue;
                    }
                    if (!early && tests) {
                        uint32_t* depth = fb.depth_samples(x, y);
                        uint8_t* stencil = fb.stencil_samples(x, y);
                        for (int s = 0; s < S; ++s) {
                            if (!(mask & (1u << s))) continue;
                            const double zf = shader_depth ? double(clamp01(r.depth[lane]))
                                                           : p.depth_at(int64_t(x) * kSubPixel + pattern.x[s],
                                                                        int64_t(y) * kSubPixel + pattern.y[s]);
                            if (sink) sink->before_depth_stencil(ds, p, x, y, s, fb.depth_word(zf), depth ? depth + s : nullptr, stencil ? stencil + s : nullptr, false);
                            if (!depth_stencil_test(ds, p.front_facing, fb.depth_word(zf),
                                                    depth ? depth + s : nullptr, stencil ? stencil + s : nullptr)) {
                                mask = uint16_t(mask & ~(1u << s));
                                w.stats.fragments_killed_late++;
                            }
                        }
                    }
                    if (!writes_color || !mask) continue;
                    float color[4] = {col[lane], col[L + lane], col[2 * L + lane], col[3 * L + lane]};
                    if (area) color[3] = float(double(color[3]) * ca[lane / 4].fraction[j]);
                    if (fog.enabled) {
                        const int64_t X = int64_t(x) * kSubPixel + kSubPixel / 2, Y = int64_t(y) * kSubPixel + kSubPixel / 2;
                        apply_fog(fog, fog_coordinate(fog, float(p.depth_at(X, Y)), float(p.eval(p.inv_w, X, Y))), color);
                    }
                    // ---- MRT (begin): fragment outputs 1.. (framebuffer objects with drawBuffers),
                    // with the same per-lane changes as output 0 ----
                    float more[kMaxFragmentOutputs][4];
                    for (int o = 1; o < outputs; ++o) {
                        const float* oc = col + size_t(4 * o) * L;
                        for (int c = 0; c < 4; ++c) more[o][c] = oc[size_t(c) * L + lane];
                        if (area) more[o][3] = float(double(more[o][3]) * ca[lane / 4].fraction[j]);
                        if (fog.enabled) {
                            const int64_t X = int64_t(x) * kSubPixel + kSubPixel / 2, Y = int64_t(y) * kSubPixel + kSubPixel / 2;
                            apply_fog(fog, fog_coordinate(fog, float(p.depth_at(X, Y)), float(p.eval(p.inv_w, X, Y))), more[o]);
                        }
                    }
                    // ---- MRT (end) ----
                    for (int s = 0; s < S; ++s) {
                        if (!(mask & (1u << s))) continue;
                        if (sink && sink->before_blend(p, x, y, s, color, drawing_buffer->color_sample(x, y, s),
                                                       shader_depth ? clamp01(r.depth[lane]) : -1.0f))
                            continue;   // the A-buffer keeps the sample instead of blending it
                        fb.write_color(blend, color, x, y, s);
                        for (int o = 1; o < outputs; ++o) fb.write_color(blend, more[o], x, y, s, o);   // MRT
                        if (sink) sink->after_blend(x, y, s, drawing_buffer->color_sample(x, y, s));
                        w.stats.samples_written++;
                        if (!plain_write) w.stats.samples_blended++;
                    }
                }
            }
        }
    };
    // A tile pass over a few pixels (a point, a short line) runs on the caller: waking the pool
    // costs more than the work. Tiles do not depend on which thread draws them, so the bytes are
    // the same either way.
    auto small_tile_pass = [&](size_t tile_count) {
        if (in.pool.size() == 1 || tile_count <= 1) return true;
        constexpr size_t kInlineEntries = 16, kInlinePixels = 2048;
        size_t entries = 0;
        int64_t pixels = 0;
        for (size_t index = 0; index < tile_count; ++index) {
            const std::vector<uint32_t>& list = bins->tile(tiles[index]);
            if ((entries += list.size()) > kInlineEntries) return false;
            const TileRect rect = grid.rect(tiles[index]);
            for (uint32_t k : list) {
                const PrimitiveSetup& p = prims[k];
                const int64_t x0 = std::max(p.x0, rect.x0), x1 = std::min(p.x1, rect.x1);
                const int64_t y0 = std::max(p.y0, rect.y0), y1 = std::min(p.y1, rect.y1);
                if (x0 < x1 && y0 < y1) pixels += (x1 - x0) * (y1 - y0);
            }
        }
        return pixels <= int64_t(kInlinePixels);
    };
    // ---- the draw in batches ----
    // At most draw_batch_primitives() primitives at a time go through the vertex stage (only the
    // vertices they use), setup and binning, and the per-tile pass, before the next batch: working
    // memory is bounded whatever the draw's size, and every pixel still sees the primitives in
    // draw order (ES 3.0 §4), batch after batch. A batch holds whole instances when one instance's
    // primitives fit (the draw's vertex list then serves every batch), else part of one instance.
    const uint32_t limit = draw_batch_primitives();
    const uint32_t per_instance = primitive_count(call.mode, call.count);
    const bool whole_instances = per_instance <= limit;
    const uint32_t instances_per_batch = whole_instances
        ? uint32_t(std::min<uint64_t>(call.instance_count, limit / std::max<uint32_t>(per_instance, 1))) : 1;
    const uint32_t step = whole_instances ? std::max<uint32_t>(per_instance, 1) : limit;

    // The batch's vertices: `ids` (distinct, in first-use order) and, for the vertex numbers in
    // `range` (draw order), the slot of each: begin..end - 1 are positions 0.., vertex 0 outside
    // the range (a fan's centre, a loop's end) is the last position.
    std::vector<uint32_t>& ids = ds_.ids;
    std::vector<uint32_t>& slot_of_position = ds_.slot_of_position;
    VertexRange range;
    auto list_vertices = [&](uint32_t p0, uint32_t p1) {
        range = whole_instances ? VertexRange{0, call.count, false} : primitive_vertex_range(call.mode, call.count, p0, p1);
        const uint32_t inside = range.end - range.begin, count = inside + (range.and_zero ? 1 : 0);
        ids.clear();
        if (call.indices) {
            slot_of_position.resize(count);
            std::unordered_map<uint32_t, uint32_t>& slot = ds_.slot;
            slot.clear();
            slot.reserve(size_t(count) * 2);
            for (uint32_t k = 0; k < count; ++k) {
                const uint32_t index = call.indices[k < inside ? range.begin + k : 0];
                auto [it, added] = slot.emplace(index, uint32_t(ids.size()));
                if (added) ids.push_back(index);
                slot_of_position[k] = it->second;
            }
        } else {
            ids.resize(count);
            for (uint32_t k = 0; k < count; ++k) ids[k] = call.first + (k < inside ? range.begin + k : 0);
        }
    };
    if (whole_instances) list_vertices(0, per_instance);
    const uint32_t used = vs.used_attributes();
    vs.prepare(in.tuning);
    std::vector<uint8_t>& touched = ds_.touched;   // tiles_touched counts each tile once per draw
    SetupStats setup_stats;
    bool tile_pass_prepared = false;

    // Instances [instance, instance + instances), primitives [p0, p1) of each. Inlined: with one
    // thread the tile pass runs on the caller, and a frame more in between measured ~2% slower on
    // shading-bound scenes (stack addresses aliasing the per-lane arrays).
    auto run_batch = [&](uint32_t instance, uint32_t instances, uint32_t p0, uint32_t p1) __attribute__((always_inline)) {
        // ---- vertex stage: each of the batch's vertices once per instance ----
        auto t0 = Clock::now();
        if (!whole_instances) list_vertices(p0, p1);
        const size_t n = ids.size();
        all.count = n * instances;
        float* const all_position = at_least(all.position, all.count * 4);
        float* const all_point_size = at_least(all.point_size, all.count);
        uint32_t* const all_varyings = at_least(all.varyings, all.count * size_t(words));
        // Triangles project and snap each vertex once, vectorised, while its position is hot.
        const bool project = per == 3 && !state.rasterizer_discard;
        WindowPosition* const all_window = project ? at_least(ds_.window, all.count) : nullptr;
        if (ds_.vertex_workers.size() < in.pool.size()) ds_.vertex_workers.resize(in.pool.size());
        const size_t vertex_chunks = (n + kVertexChunk - 1) / kVertexChunk;
        for_chunks(in.pool, vertex_chunks * instances, [&](size_t job, unsigned worker) {
            const uint32_t j = uint32_t(job / vertex_chunks);
            const size_t begin = (job % vertex_chunks) * kVertexChunk, count = std::min(kVertexChunk, n - begin);
            VertexWorker& w = ds_.vertex_workers[worker];
            for (int loc = 0; loc < kMaxVertexAttribs; ++loc)
                if (used & (1u << loc))
                    fetch_attribute(in.vertex_array, in.current_attribs[size_t(loc)], loc, ids.data() + begin, 0,
                                    count, instance + j, w.attribs[size_t(loc)]);
            vs.run(w.attribs, count, ids.data() + begin, instance + j, w.shaded);
            const size_t at = size_t(j) * n + begin;
            std::copy_n(w.shaded.position.data(), count * 4, all_position + at * 4);
            std::copy_n(w.shaded.point_size.data(), count, all_point_size + at);
            std::copy_n(w.shaded.varyings.data(), count * size_t(words), all_varyings + at * size_t(words));
            if (project) Setup(rs).project_vertices(w.shaded.position.data(), count, all_window + at);
        });
        st.vertices_shaded += all.count;
        st.seconds_vertex += lap(t0);
        if (state.rasterizer_discard) return;

        // ---- primitive assembly, clip, setup and binning, in chunks of primitives on the pool ----
        const uint32_t span = p1 - p0;
        const size_t batch_total = size_t(span) * instances;
        const size_t setup_chunks = (batch_total + kSetupChunk - 1) / kSetupChunk;
        if (ds_.chunks.size() < setup_chunks) ds_.chunks.resize(setup_chunks);
        std::vector<Bins>& chunk_bins = ds_.chunk_bins;
        if (chunk_bins.size() < setup_chunks) chunk_bins.resize(setup_chunks);
        const uint32_t inside = range.end - range.begin;
        for_chunks(in.pool, setup_chunks, [&](size_t c, unsigned) {
            SetupChunk& chunk = ds_.chunks[c];
            chunk.prims.clear();
            Setup setup(rs);
            const size_t begin = c * kSetupChunk, end = std::min(batch_total, begin + kSetupChunk);
            uint32_t j = uint32_t(begin / span), p = p0 + uint32_t(begin % span);
            for (size_t k = begin; k < end; ++k, ++p) {
                if (p == p1) p = p0, ++j;
                uint32_t v[3];
                primitive_vertices(call.mode, call.count, p, v);
                const uint32_t base = uint32_t(j * n);
                for (int i = 0; i < per; ++i) {
                    const uint32_t position = v[i] >= range.begin ? v[i] - range.begin : inside;
                    v[i] = base + (call.indices ? slot_of_position[position] : position);
                }
                // The primitive's number in the draw (modulo 2^32).
                const uint32_t number = uint32_t(uint64_t(instance + j) * per_instance + p);
                if (per == 3) setup.triangle(all_position, all_window, v, number, chunk.prims);
                else if (per == 2) setup.line(all_position + 4 * v[0], all_position + 4 * v[1], v[0], v[1], number, chunk.prims);
                else setup.point(all_position + 4 * v[0], all_point_size[v[0]], v[0], number, chunk.prims);
            }
            chunk.stats = setup.stats;
            if (!rasterizes) return;
            chunk_bins[c].reset(grid);
            chunk_bins[c].add(chunk.prims.data(), chunk.prims.size(), 0);
        });
        uint64_t emitted = 0;
        for (size_t c = 0; c < setup_chunks; ++c) setup_stats.add(ds_.chunks[c].stats), emitted += ds_.chunks[c].stats.emitted;
        if (!rasterizes || emitted == 0) {
            st.seconds_setup += since(t0);
            return;
        }

        // Number the primitives (chunk << shift | position in the chunk) and gather each tile's
        // list in chunk order. A batch's chunks emit at most 8 * kSetupChunk records each, so the
        // numbers of kDrawBatchPrimitivesMax primitives fit in 32 bits.
        size_t largest = 1;
        for (size_t c = 0; c < setup_chunks; ++c) largest = std::max(largest, ds_.chunks[c].prims.size());
        prims.shift = 0;
        while ((size_t(1) << prims.shift) < largest) ++prims.shift;
        prims.mask = uint32_t((uint64_t(1) << prims.shift) - 1);
        prims.chunk.clear();
        std::vector<uint32_t>& index_base = ds_.index_base;
        index_base.clear();
        for (size_t c = 0; c < setup_chunks; ++c) {
            prims.chunk.push_back(ds_.chunks[c].prims.data());
            index_base.push_back(uint32_t(c << prims.shift));
        }
        bins = &chunk_bins[0];   // one chunk: its bins are the batch's
        if (setup_chunks > 1) {
            ds_.bins.begin_gather(grid, chunk_bins.data(), setup_chunks);
            const std::vector<uint32_t>& occupied = ds_.bins.occupied();
            in.pool.parallel_for(occupied.size(), [&](size_t i, unsigned) { ds_.bins.gather_tile(occupied[i], chunk_bins.data(), setup_chunks, index_base.data()); });
            bins = &ds_.bins;
        }
        // Only tiles with work go to the pool (a draw of one small primitive wakes no thread).
        bins->checkerboard_order(tiles);
        st.seconds_setup += lap(t0);

        // ---- per tile on the pool: raster, tests, shading, blending ----
        if (!tile_pass_prepared) {   // once per draw, before the first tile pass
            if (scratch.size() < in.pool.size()) scratch.resize(in.pool.size());
            fs.prepare(in.pool.size(), in.tuning);
            constant = fs.run_constant(ds_.constant, 0);
            if (constant) {
                float* const lanes = at_least(ds_.constant_color, 4 * kChunkLanes);
                for (size_t c = 0; c < 4; ++c) std::fill_n(lanes + c * kChunkLanes, kChunkLanes, ds_.constant.color[c]);
                if (constant_kernels && S == 1 && !plain_write && blend_is_per_channel(blend)) {
                    build_blend_table(kernel, blend, ds_.constant.color.data(), table);
                    blend_table = &table;
                    st.draws_blend_table = 1;
                }
            }
            // What the fragment shader reads: only these varying words are computed per lane.
            for (int word = 0; word < words; ++word) {
                if (size_t(word) < layout.read_by_fragment.size() && !layout.read_by_fragment[size_t(word)]) continue;
                (layout.flat[size_t(word)] ? flat_words : smooth_words).push_back(word);
            }
            if (const FragmentCopies* copies = fs.copies(); copies && copies->outputs == 1) {
                const int first = copies->word[0];
                bool computed = first >= 0 && first + 4 <= words;
                for (int c = 0; c < 4 && computed; ++c)
                    computed = copies->word[size_t(c)] == first + c &&
                               (size_t(first + c) >= layout.read_by_fragment.size() || layout.read_by_fragment[size_t(first + c)]);
                if (computed) copied_word = first;
                for (size_t i = 0; computed && i + 4 <= smooth_words.size(); ++i)
                    if (smooth_words[i] == first && smooth_words[i + 3] == first + 3) copied_index = int(i);
            }
            touched.assign(grid.count(), 0);
            tile_pass_prepared = true;
        }
        for (uint32_t t : tiles)
            if (!touched[t]) touched[t] = 1, ++st.tiles_touched;
        if (small_tile_pass(tiles.size())) {
            for (size_t index = 0; index < tiles.size(); ++index) run_tile(index, 0);
        } else {
            in.pool.parallel_for(tiles.size(), run_tile);
        }
        st.seconds_fragment += since(t0);
    };
    for (uint32_t instance = 0; instance < call.instance_count; instance += instances_per_batch) {
        const uint32_t instances = std::min(instances_per_batch, call.instance_count - instance);
        uint32_t p0 = 0;
        do {
            const uint32_t p1 = uint32_t(std::min<uint64_t>(per_instance, uint64_t(p0) + step));
            run_batch(instance, instances, p0, p1);
            p0 = p1;
        } while (p0 < per_instance);
    }

    st.primitives = setup_stats.primitives;
    st.primitives_culled = setup_stats.culled;
    st.primitives_clipped = setup_stats.clipped;
    st.primitives_outside = setup_stats.outside;
    st.primitives_invalid = setup_stats.invalid;
    st.primitives_zero_area = setup_stats.zero_area;
    st.primitives_rasterized = setup_stats.emitted;
    for (size_t k = 0; k < scratch.size(); ++k) {
        st.add(scratch[k].stats);
        st.blocks_accepted_whole += scratch[k].raster.blocks_accepted;
    }
    total.add(st);
}

}  // namespace softgl
