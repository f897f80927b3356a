#include "softgl/pipeline/tile_pass.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "softgl/pipeline/coverage.h"
#include "softgl/pipeline/draw_rollback.h"
#include "softgl/pipeline/fragment_sink.h"
#include "softgl/pipeline/interpolate.h"
#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/sample_mask.h"
#include "softgl/pipeline/whole_rect.h"
#include "softgl/surface/formats.h"

namespace softgl {

namespace {

// The steps a chunk goes through on the common path are inlined into the primitive's loop, as
// one function: each chunk pays no calls between them.
#define SOFTGL_STEP __attribute__((always_inline)) inline

constexpr size_t kChunkQuads = 32;   // 128 lanes: the executor's batch
constexpr size_t kChunkLanes = 4 * kChunkQuads;
// A chunk of at least this many kept quads (a large primitive's) is shaded as it is, unless it is
// not full and more than an eighth of its lanes are helpers that single pixels would leave out:
// gathering would only move its lanes (exec_spot, full-screen quads: 27% more instructions when
// gathered; counting the helpers of full chunks 0.5%).
constexpr size_t kOwnBatchQuads = kChunkQuads / 2;
constexpr uint32_t kPositionBuiltins = kFragCoordX | kFragCoordY | kFragCoordZ | kFragCoordW | kPointCoordS | kPointCoordT;
static_assert(kChunkQuads <= 64, "a chunk's rows of four in one uint64_t (whole_rows_of_four)");

// A lane's colour may be read from the batch's varying words (uint32_t): through a may_alias type,
// so these reads stay after the words' writes (strict aliasing).
using LaneFloat = float __attribute__((may_alias));

float as_float(uint32_t bits) {
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

// Grows v to at least n elements; never shrinks, so a smaller draw does not zero-fill again.
template <class T>
T* at_least(std::vector<T>& v, size_t n) {
    if (v.size() < n) v.resize(n);
    return v.data();
}

// Hidden-surface removal (docs/architecture.md, "Fast paths"). Without blending, a pixel ends with
// the colour of the last fragment that passed the tests (no discard, no shader depth: the tests
// come before shading), so in a tile where primitives pile up, a first pass runs every primitive's
// raster and early tests and keeps, per pixel, the list entry of the last survivor; the second
// pass shades only those.
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

// Whether a tile's primitives pile up enough for hidden-surface removal's first pass to pay: the
// pixels they may cover add up to `times` the tile. A triangle covers at most its area (half the
// cross product of two edges' coefficients, in 1/256-pixel units squared) and its bounding box's
// part of the tile; its box alone is at least twice its area, so a mesh that covers a tile once (terrain:
// 0.5% of the fragments hidden, the pass 6% of the draw's instructions) looked piled up. Other
// primitives count their box (`by_boxes`: every primitive, the rule before).
bool piles_up(const std::vector<uint32_t>& list, const PrimitiveTable& prims, const TileRect& rect, int64_t times,
              bool by_boxes) {
    const int64_t goal = times * int64_t(rect.x1 - rect.x0) * int64_t(rect.y1 - rect.y0);
    int64_t area = 0;
    for (uint32_t k : list) {
        const PrimitiveSetup& p = prims[k];
        const int64_t x0 = std::max(p.x0, rect.x0), x1 = std::min(p.x1, rect.x1);
        const int64_t y0 = std::max(p.y0, rect.y0), y1 = std::min(p.y1, rect.y1);
        if (x0 >= x1 || y0 >= y1) continue;
        int64_t pixels = (x1 - x0) * (y1 - y0);
        if (!by_boxes && p.kind == PrimitiveKind::Triangle && p.edge_count == 3) {
            // |a0 b1 - a1 b0| < 2^59 (coordinates within the guard band): pixels, rounded up.
            const int64_t twice = p.a[0] * p.b[1] - p.a[1] * p.b[0];
            constexpr int64_t kTwicePixel = 2 * int64_t(kSubPixel) * int64_t(kSubPixel);
            pixels = std::min(pixels, ((twice < 0 ? -twice : twice) + kTwicePixel - 1) / kTwicePixel);
        }
        if ((area += pixels) >= goal) return true;
    }
    return false;
}

// The shade step for a shader that only copies varyings or constants (FragmentShader::copies):
// its colour outputs, bit for bit what run() gives, without the executor.
void copy_outputs(const FragmentCopies& copies, const FragmentBatch& b, FragmentResults& out) {
    const size_t L = b.lanes, S = b.stride(), O = size_t(copies.outputs);
    out.outputs = copies.outputs;
    if (out.color.size() < 4 * O * L) out.color.resize(4 * O * L);   // grows only: no zero fill per batch
    out.killed.clear();
    for (size_t k = 0; k < 4 * O; ++k) {
        if (copies.word[k] >= 0) {
            std::memcpy(&out.color[k * L], &b.varyings[size_t(copies.word[k]) * S], 4 * L);
        } else {
            float value;
            std::memcpy(&value, &copies.bits[k], 4);
            std::fill_n(&out.color[k * L], L, value);
        }
    }
}

// The coverage step (SOFTGL_smooth, GL 1.5 §3.4-3.5): the pixel's covered fraction scales alpha.
inline void coverage(float rgba[4], double fraction) { rgba[3] = float(double(rgba[3]) * fraction); }

// The fog step, at the pixel centre (pipeline/fog).
inline void fog(const FogOp& op, const PrimitiveSetup& p, int32_t x, int32_t y, float rgba[4]) {
    const int64_t X = int64_t(x) * kSubPixel + kSubPixel / 2, Y = int64_t(y) * kSubPixel + kSubPixel / 2;
    apply_fog(op, fog_coordinate(op, float(p.depth_at(X, Y)), float(p.eval(p.inv_w, X, Y))), rgba);
}

// The lanes of n quads' masks that no sample covers (helper lanes), a quad's four at a time (a
// 16-bit lane v sets its bit 15 in (v & 0x7FFF) + 0x7FFF | v only when v != 0, as OwnerMap::owned).
size_t helper_lanes(const uint16_t* masks, size_t n) {
    constexpr uint64_t low = 0x7FFF7FFF7FFF7FFFu;
    size_t helpers = 0;
    for (size_t i = 0; i < n; ++i) {
        uint64_t m4;
        std::memcpy(&m4, masks + 4 * i, 8);
        const uint64_t zero = ~(((m4 & low) + low) | m4 | low) >> 15;   // 1 in each lane that is zero
        helpers += size_t((zero * 0x0001000100010001u) >> 48);          // their sum, in the top lane
    }
    return helpers;
}

// Per draw, kept between draws on the calling thread (no per-draw allocations; buffers only grow,
// so a repeated draw touches no fresh pages).
struct TilePassScratch {
    std::vector<TilePass::Scratch> workers;
    std::vector<uint8_t> touched;           // per tile: had work in an earlier batch of the draw
    FragmentResults constant;               // a uniform-only shader's results (FragmentShader::run_constant)
    std::vector<float> constant_color;      // its output 0 as a chunk's lanes: [c * kChunkLanes + lane]
    std::vector<int> smooth_words, flat_words;
    BlendTable table;
};

// Shade full batches (docs/architecture.md, "Fast paths"): the fragments of a tile's primitives,
// after their early tests, gathered for one shader run of up to kChunkLanes lanes. Lanes are
// whole quads (lane 4*i + j pixel j of quad[i]), or with no helper lanes single pixels (lane l
// pixel (xy[2l], xy[2l + 1])); masks[lane] its surviving samples. Runs say which primitive each
// lane belongs to, in draw order, for the steps lane by lane. A pixel is in a batch at most once
// when the write step gathers and scatters pixels (`occupied`), so every pixel still sees its
// fragments blended in draw order.
struct Gathered {
    struct Run {
        const PrimitiveSetup* p;
        size_t end;                        // lanes [previous run's end, end)
    };
    size_t quads = 0, lanes = 0;
    std::vector<Quad> quad;                // [kChunkQuads]
    std::vector<uint16_t> masks;           // [kChunkLanes]
    std::vector<int32_t> xy;               // [2 * kChunkLanes] (single pixels)
    std::vector<Run> runs;
    uint64_t occupied[kTileSize];          // row y - y0 of the tile, bit x - x0
    bool any_occupied = false;
};
static_assert(kTileSize <= 64, "a tile's row of pixels in one uint64_t (Gathered::occupied)");

}  // namespace

// Per-worker scratch, reused across primitives and draws. Each starts on its own cache line: one
// worker's counters must not share a line with the next worker's vectors (written per quad).
struct alignas(64) TilePass::Scratch {
    std::vector<Quad> quads;          // the primitive's quads in this tile
    std::vector<QuadArea> areas;      // SOFTGL_smooth: covered fractions of the quads
    std::vector<float> values;        // the primitive's vertex values of the interpolated words
    FragmentResults flat_results;     // a flat primitive's colour (FragmentShader::run_flat) ...
    std::vector<float> flat_color;    // ... as a chunk's lanes: [c * kChunkLanes + lane]
    std::vector<uint32_t> pixels;     // per lane of a chunk: the destination pixel (S == 1 colour path)
    std::vector<uint16_t> masks;      // per lane of a chunk: surviving sample mask
    std::vector<uint64_t> owners;     // hidden-surface removal: the tile's owner map (OwnerMap)
    std::vector<uint8_t> owns;        // ... and per entry of the tile's list, whether it owns a pixel
    // ... and the first pass's quads, kept for the second pass (no second raster of the entries
    // that own pixels): entry li's are kept_quads[kept[li].begin ..] when kept[li].kept.
    struct KeptRaster {
        uint32_t begin = 0, count = 0;
        bool kept = false;
        RasterStats stats;            // what raster() counts for them
    };
    std::vector<Quad> kept_quads;
    std::vector<KeptRaster> kept;
    DepthBounds depth_bounds;         // the tile's stored depth bounds (early depth, skips hidden primitives)
    FragmentBatch batch;
    FragmentResults results;
    Gathered gathered;                // fragment_batches: the tile's batch being filled
    RasterStats raster;
    DrawStats stats;
};

namespace {
TilePassScratch& tile_pass_scratch() {
    thread_local TilePassScratch scratch;
    return scratch;
}

uint64_t batch_bytes(const FragmentBatch& b) {
    return capacity_bytes(b.varyings) + capacity_bytes(b.frag_coord) + capacity_bytes(b.front_facing) +
           capacity_bytes(b.point_coord);
}

uint64_t results_bytes(const FragmentResults& r) {
    return capacity_bytes(r.color) + capacity_bytes(r.depth) + capacity_bytes(r.killed);
}
}  // namespace

uint64_t tile_pass_scratch_bytes() {
    const TilePassScratch& s = tile_pass_scratch();
    uint64_t n = capacity_bytes(s.workers) + capacity_bytes(s.touched) + results_bytes(s.constant) +
                 capacity_bytes(s.constant_color) + capacity_bytes(s.smooth_words) + capacity_bytes(s.flat_words);
    for (const TilePass::Scratch& w : s.workers)
        n += capacity_bytes(w.quads) + capacity_bytes(w.areas) + capacity_bytes(w.values) + capacity_bytes(w.pixels) +
             capacity_bytes(w.masks) + capacity_bytes(w.owners) + capacity_bytes(w.owns) + capacity_bytes(w.kept_quads) +
             capacity_bytes(w.kept) + batch_bytes(w.batch) + results_bytes(w.results) + capacity_bytes(w.gathered.quad) +
             capacity_bytes(w.gathered.masks) + capacity_bytes(w.gathered.xy) + capacity_bytes(w.gathered.runs);
    return n;
}

// One tile on one worker.
struct TilePass::Tile {
    Scratch& w;
    unsigned worker;
    TileRect rect;
    const std::vector<uint32_t>& list;   // the tile's primitives, in draw order
    bool hide = false;                   // hidden-surface removal's first pass ran
    OwnerMap owners{nullptr, {}};
};

// One primitive in the tile: what it gives every chunk of its quads.
struct TilePass::Primitive {
    const PrimitiveSetup& p;
    size_t entry;                  // its place in the tile's list (the owner map's entries)
    uint32_t provoking = 0;        // the vertex flat varyings come from
    bool interpolate = false;      // smooth words interpolated (triangles and lines)
    // Every word the shader reads has the same bits at each vertex (and is neither -0 nor NaN):
    // where the weights are finite each fragment reads those values (weights_finite), and a
    // shader that runs flat (FragmentShader::run_flat) gives them all one colour.
    bool flat = false;
    bool flat_weights = false;     // ... and the weights are finite at every pixel of the tile
    size_t flat_lanes = 0;         // lanes of Scratch::flat_color filled with its colour
    VaryingInterpolation vi{};
};

// Up to kChunkQuads of the primitive's quads: every per-lane array stays in L1. The early tests
// compact them in place to the `kept` that still cover a sample (lane 4*i + j is pixel j of
// quads[i], masks[lane] its surviving samples).
struct TilePass::Chunk {
    Quad* quads;
    QuadArea* areas;               // area coverage: the quads' fractions, else null
    size_t count;
    uint16_t* masks;
    size_t kept = 0;
    // A gathered batch of single pixels: lane l is pixel (xy[2l], xy[2l + 1]), `pixels` lanes.
    const int32_t* xy = nullptr;
    size_t pixels = 0;
    size_t lanes() const { return xy ? pixels : 4 * kept; }
    SOFTGL_STEP void pixel(size_t lane, int32_t& x, int32_t& y) const {
        if (xy) {
            x = xy[2 * lane], y = xy[2 * lane + 1];
        } else {
            const Quad& quad = quads[lane / 4];
            x = quad.x + int32_t(lane & 1), y = quad.y + int32_t((lane >> 1) & 1);
        }
    }
};

// The shade step's colours: lane l, channel c of output o at col[(4 * o + c) * stride + l].
struct TilePass::Colors {
    const LaneFloat* col;
    size_t stride;
    int outputs;
    bool any_killed;               // the shader discarded a lane (FragmentResults::killed)
    bool words = false;            // texel words: no colours, the pixels' words are in Scratch::pixels
};

TilePass::TilePass(const DrawInputs& in, const FragmentOps& ops, const TileGrid& grid, DrawPlan& plan)
    : in_(in), plan_(plan), state_(in.state), fb_(in.target), fs_(in.fragment_shader),
      drawing_buffer_(plan.target == DrawTarget::DrawingBuffer ? in.target.default_framebuffer() : nullptr),
      color_bytes_(in.target.color_rgba8()),
      sink_(plan.blend_lab ? in.sink : nullptr),
      blend_(ops.blend), ds_(ops.depth_stencil), fog_(ops.fog), pattern_(sample_pattern(in.target.config().samples)),
      grid_(grid), samples_(in.target.config().samples),
      words_(in.vertex_shader.varying_layout().words), builtins_(in.fragment_shader.builtins_read()),
      coverage_mask_(!in.state.sample_coverage ? 0xFFFFu
                     : coverage_from_value(in.state.sample_coverage_value, samples_) ^
                           (in.state.sample_coverage_invert ? 0xFFFFu : 0u)),
      shader_depth_(in.fragment_shader.writes_depth()), unorm8_table_(unorm8_to_float_table()), pitch_(size_t(in.target.width())),
      buffer_pixels_{color_bytes_, pitch_,
                     in.target.width() - 1, in.target.height() - 1},
      copies_(plan.fragment_copies == Path::Taken ? in.fragment_shader.copies() : nullptr) {
    if (plan.quad_depth == Path::Taken) {
        quad_depth_test_.pattern = &pattern_;
        quad_depth_test_.func = ds_.depth_func;
        quad_depth_test_.write = ds_.depth_write;
        quad_depth_test_.depth = fb_.depth_samples(0, 0);   // the drawing buffer's or an image's
        quad_depth_test_.pitch = pitch_;
        if (samples_ == 1) depth_pixels_ = quad_depth_test_.depth;
    }
    if (color_bytes_ && samples_ == 1 && plan.writes_color) color_pixels_ = reinterpret_cast<const uint32_t*>(color_bytes_);
    if (depth_pixels_) quad_depth_test_.prefetch_color = color_pixels_;   // same pitch (prefetch_ahead)
    for (Scratch& w : tile_pass_scratch().workers) w.raster = RasterStats{}, w.stats = DrawStats{};
}

// Once per draw, before the first batch's tiles: the workers, the shader's constant colour (the
// plan's second step) and the varying words the shader reads.
void TilePass::prepare(DrawStats& stats) {
    TilePassScratch& s = tile_pass_scratch();
    if (s.workers.size() < in_.pool.size()) s.workers.resize(in_.pool.size());
    scratch_ = s.workers.data();
    fs_.prepare(in_.pool.size(), in_.tuning);
    const bool uniform_only = fs_.run_constant(s.constant, 0);
    plan_shading(plan_, uniform_only, blend_);
    if (plan_.constant_color == Path::Taken) {
        float* const lanes = at_least(s.constant_color, 4 * kChunkLanes);
        for (size_t c = 0; c < 4; ++c) std::fill_n(lanes + c * kChunkLanes, kChunkLanes, s.constant.color[c]);
        constant_color_ = lanes;
        stats.draws_constant_color = 1;
    }
    if (plan_.blend_table == Path::Taken) {
        build_blend_table(plan_.kernel, blend_, s.constant.color.data(), s.table);
        blend_table_ = &s.table;
        stats.draws_blend_table = 1;
    }
    if (plan_.fragment_copies == Path::Taken) stats.draws_copied_varying = 1;
    if (plan_.texture_copy == Path::Taken) stats.draws_texture_copy = 1;
    plan_texel_words(plan_, in_.tuning, fs_);
    texel_words_ = plan_.texel_words == Path::Taken;
    if (texel_words_) stats.draws_texel_words = 1;
    gather_ = plan_.fragment_batches == Path::Taken;
    single_pixels_ = gather_ && plan_.no_helper_lanes == Path::Taken;
    // Two fragments of a pixel in one batch would both read its old colour where the colour
    // kernels gather pixels (or, multisampled, samples) and read them; a plain write of all
    // channels stores in lane order.
    exclusive_pixels_ = gather_ && plan_.color_kernels == Path::Taken &&
                        plan_.kernel != ColorKernel::Generic && (plan_.kernel != ColorKernel::Plain || !plan_.all_channels);
    // What the fragment shader reads: only these varying words are computed per lane.
    const VaryingLayout& layout = in_.vertex_shader.varying_layout();
    s.smooth_words.clear();
    s.flat_words.clear();
    for (int word = 0; word < words_; ++word) {
        if (size_t(word) < layout.read_by_fragment.size() && !layout.read_by_fragment[size_t(word)]) continue;
        (layout.flat[size_t(word)] ? s.flat_words : s.smooth_words).push_back(word);
    }
    smooth_words_ = &s.smooth_words;
    flat_words_ = &s.flat_words;
    // Flat primitives go straight to the colour kernels, as a constant colour does.
    flat_primitives_ = in_.tuning.flat_primitives && fs_.runs_flat() && plan_.color_kernels == Path::Taken && plan_.constant_color != Path::Taken &&
                       plan_.fused_copy != Path::Taken && !plan_.area_coverage;
    if (flat_primitives_) stats.draws_flat_primitives = 1;
    s.touched.assign(grid_.count(), 0);
    prepared_ = true;
}

// A tile pass over a few pixels (a point, a short line) runs on the caller: waking the pool costs
// more than the work. Tiles do not depend on which thread draws them, so the bytes are the same
// either way.
bool TilePass::small(size_t tile_count) const {
    if (in_.pool.size() == 1 || tile_count <= 1) return true;
    constexpr size_t kInlineEntries = 16, kInlinePixels = 2048;
    size_t entries = 0;
    int64_t pixels = 0;
    for (size_t index = 0; index < tile_count; ++index) {
        const std::vector<uint32_t>& list = bins_->tile((*tiles_)[index]);
        if ((entries += list.size()) > kInlineEntries) return false;
        const TileRect rect = grid_.rect((*tiles_)[index]);
        for (uint32_t k : list) {
            const PrimitiveSetup& p = (*prims_)[k];
            const int64_t x0 = std::max(p.x0, rect.x0), x1 = std::min(p.x1, rect.x1);
            const int64_t y0 = std::max(p.y0, rect.y0), y1 = std::min(p.y1, rect.y1);
            if (x0 < x1 && y0 < y1) pixels += (x1 - x0) * (y1 - y0);
        }
    }
    return pixels <= int64_t(kInlinePixels);
}

void TilePass::run(const TileBatch& batch, DrawStats& stats) {
    if (!prepared_) prepare(stats);
    bins_ = &batch.bins;
    prims_ = &batch.prims;
    vertices_ = &batch.vertices;
    tiles_ = &batch.tiles;
    std::vector<uint8_t>& touched = tile_pass_scratch().touched;   // tiles_touched: once per draw
    for (uint32_t t : batch.tiles)
        if (!touched[t]) touched[t] = 1, ++stats.tiles_touched;
    const auto all_tiles = [&](auto with_sink) {
        constexpr bool WithSink = decltype(with_sink)::value;
        if (small(batch.tiles.size())) {
            for (size_t index = 0; index < batch.tiles.size(); ++index) tile<WithSink>(index, 0);
        } else {
            in_.pool.parallel_for(batch.tiles.size(), [this](size_t index, unsigned worker) { tile<WithSink>(index, worker); });
        }
    };
    if (sink_) all_tiles(std::true_type{});
    else all_tiles(std::false_type{});
}

void TilePass::add_counters(DrawStats& stats) const {
    for (const Scratch& w : tile_pass_scratch().workers) {
        stats.add(w.stats);
        stats.blocks_accepted_whole += w.raster.blocks_accepted;
    }
}

// Hidden-surface removal's first pass pays where bounding boxes cover the tile twice, or three
// times for a shader that only copies or is constant; such a shader costs less than the pass where
// early depth already rejects most hidden fragments (100 large depth-tested triangles: 20% slower;
// 10k instanced cubes with a copying shader: the pass was 43% of the draw's instructions). Any
// copying shader counts, not only the one-vec4 copy the fused kernels read (copied_word), and so
// does a texture copy whose texels go to the pixels as words (tex_nearest, two triangles per
// full-screen quad: the pass was 6% of the draw's instructions and hid nothing).
bool TilePass::hides(const Tile& t) const {
    if (plan_.hidden_surface_removal != Path::Taken || t.list.size() <= 1 || t.list.size() >= OwnerMap::kNone)
        return false;
    if (plan_.hidden_surface_in_every_tile) return true;
    const bool cheap_shader = plan_.uniform_only || plan_.fragment_copies == Path::Taken || texel_words_;
    const bool tests = plan_.depth_test || plan_.stencil_test;
    return !(cheap_shader && tests) && piles_up(t.list, *prims_, t.rect, cheap_shader ? 3 : 2, plan_.hidden_surface_by_boxes);
}

template <bool WithSink>
void TilePass::tile(size_t index, unsigned worker) {
    const size_t tile = (*tiles_)[index];
    Scratch& w = scratch_[worker];
    Tile t{w, worker, grid_.rect(tile), bins_->tile(tile)};
    // Work budget and rollback (core/work_budget.h, pipeline/draw_rollback.h): when the draw can
    // be stopped after writing pixels, the tile's pixels are kept before its first write of the
    // draw; its primitives are charged up front.
    if (rollback_) rollback_->save(tile, t.rect);
    if (in_.budget) in_.budget->charge(uint64_t(t.list.size()) * kTilePrimitiveWorkUnits);
    const uint64_t shaded_before = w.stats.fragments_shaded;
    const bool depth_bounds = plan_.depth_bounds == Path::Taken;
    if (depth_bounds)
        w.depth_bounds.begin_tile(quad_depth_test_, t.rect,
                                  plan_.depth_bounds_sabotaged ? DepthBoundsMode::SabotagedForTests : DepthBoundsMode::On,
                                  plan_.simd);
    w.masks.resize(kChunkLanes);
    w.pixels.resize(kChunkLanes);
    // The fragment batch's arrays only grow (to a whole chunk): no zero fill per chunk.
    FragmentBatch& b = w.batch;
    at_least(b.varyings, size_t(words_) * kChunkLanes);
    at_least(b.frag_coord, 4 * kChunkLanes);
    at_least(b.front_facing, kChunkLanes);
    at_least(b.point_coord, 2 * kChunkLanes);
    if (gather_) {
        Gathered& g = w.gathered;
        at_least(g.quad, kChunkQuads);
        at_least(g.masks, kChunkLanes);
        at_least(g.xy, 2 * kChunkLanes);
        g.quads = g.lanes = 0;
        g.runs.clear();
        std::fill_n(g.occupied, kTileSize, uint64_t(0));
        g.any_occupied = false;
    }
    t.hide = hides(t);
    if (t.hide) hidden_surface_first_pass(t), ++w.stats.tiles_hidden_surface;
    const std::vector<uint32_t>& list = t.list;
    for (size_t li = 0; li < list.size(); ++li) {
        prefetch_ahead(t, li);
        // A stop (Ctrl-C, budget) between primitives, when the draw can put its pixels back.
        if (rollback_ && in_.budget->stop_requested()) in_.budget->check();
        if (t.hide && !w.owns[li]) continue;   // hidden everywhere in this tile
        const PrimitiveSetup& p = (*prims_)[list[li]];
        if (!t.hide && depth_bounds && w.depth_bounds.hides(p)) {
            ++w.stats.primitives_depth_hidden;
            continue;
        }
        if (t.hide && w.kept[li].kept) {   // the first pass's quads (raster() would give the same)
            const Scratch::KeptRaster& k = w.kept[li];
            w.quads.assign(w.kept_quads.begin() + k.begin, w.kept_quads.begin() + k.begin + k.count);
            w.areas.clear();
            w.raster.add(k.stats);
        } else {
            raster(t, p);
        }
        if (w.quads.empty()) continue;
        draw_primitive<WithSink>(t, p, li);
    }
    if constexpr (!WithSink)
        if (gather_) flush(t);   // the rest of the tile's fragments
    // The tile's fragments (helpers included), charged when done: a draw of many large primitives
    // without loops (finding 5's instances) runs out of budget too.
    if (in_.budget) in_.budget->charge((w.stats.fragments_shaded - shaded_before) * kFragmentWorkUnits);
}

// Every primitive's raster and early tests; per pixel, the list entry of the last survivor.
void TilePass::hidden_surface_first_pass(Tile& t) {
    Scratch& w = t.w;
    const std::vector<uint32_t>& list = t.list;
    const OwnerMap owners{at_least(w.owners, OwnerMap::kQuads), t.rect};
    t.owners = owners;
    std::fill_n(owners.quads, OwnerMap::kQuads, ~uint64_t(0));
    uint8_t* const owns = at_least(w.owns, list.size());
    std::fill_n(owns, list.size(), uint8_t(0));
    uint16_t* const masks = w.masks.data();
    const bool quad_depth = plan_.quad_depth == Path::Taken, depth_bounds = plan_.depth_bounds == Path::Taken;
    // Quads kept for the second pass, at most this many per tile (bounded working memory; the
    // entries after that are rasterized again).
    constexpr size_t kKeptQuadsMax = size_t(1) << 16;
    w.kept_quads.clear();
    Scratch::KeptRaster* const kept = at_least(w.kept, list.size());
    uint64_t survived = 0;
    for (size_t li = 0; li < list.size(); ++li) {
        const PrimitiveSetup& p = (*prims_)[list[li]];
        kept[li].kept = false;
        if (depth_bounds && w.depth_bounds.hides(p)) {
            ++w.stats.primitives_depth_hidden;
            continue;
        }
        const bool keep = !plan_.area_coverage && w.kept_quads.size() < kKeptQuadsMax;
        std::vector<Quad>& out = keep ? w.kept_quads : w.quads;
        const size_t at = keep ? out.size() : 0;
        if (!keep) out.clear();
        RasterStats counted;
        rasterize_at(plan_.simd, p, t.rect, pattern_, out, counted);
        const Quad* const q = out.data() + at;
        const size_t n = out.size() - at;
        if (keep) kept[li] = Scratch::KeptRaster{uint32_t(at), uint32_t(n), true, counted};
        if (!quad_depth) {
            survived += owners.mark_all(q, n, li, [q](size_t i) { return q[i].coverage; });
            continue;
        }
        for (size_t c0 = 0; c0 < n; c0 += kChunkQuads) {
            const size_t chunk = std::min(kChunkQuads, n - c0);
            EarlyDepth test = quad_depth_test_;
            test.prim = &p;
            w.stats.fragments_killed_early += early_depth_test_at(plan_.simd, test, q + c0, chunk, masks);
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

// A tile's primitives lie far apart in memory when there are many small ones: fetch the setup
// four primitives ahead and, from it, the vertex values and pixels two ahead, so they arrive in
// time (tiny_depth_triangles: ~10% faster than two and one ahead).
SOFTGL_STEP void TilePass::prefetch_ahead(const Tile& t, size_t li) const {
    constexpr int32_t kPrefetchRows = 16;
    const std::vector<uint32_t>& list = t.list;
    if (li + 4 < list.size()) {
        const char* next = reinterpret_cast<const char*>(&(*prims_)[list[li + 4]]);
        for (size_t off = 0; off < sizeof(PrimitiveSetup); off += 64) __builtin_prefetch(next + off);
    }
    if (li + 2 < list.size()) {
        const PrimitiveSetup& next = (*prims_)[list[li + 2]];
        if (words_ > 0)
            for (int v = 0; v < 3; ++v) __builtin_prefetch(&vertices_->varyings[size_t(next.vertex[v]) * size_t(words_)]);
        // A small primitive's pixels are cold in the colour and depth buffers: fetch its rows
        // (first and last pixel of each) while the ones before it are drawn.
        const int32_t x0 = std::max(next.x0, t.rect.x0), x1 = std::min(next.x1, t.rect.x1);
        const int32_t y0 = std::max(next.y0, t.rect.y0), y1 = std::min(next.y1, t.rect.y1);
        if (x0 < x1 && y0 < y1 && y1 - y0 <= kPrefetchRows) {
            for (int32_t y = y0; y < y1; ++y) {
                const size_t first = size_t(y) * pitch_ + size_t(x0), last = size_t(y) * pitch_ + size_t(x1 - 1);
                if (color_pixels_) __builtin_prefetch(color_pixels_ + first, 1), __builtin_prefetch(color_pixels_ + last, 1);
                if (depth_pixels_) __builtin_prefetch(depth_pixels_ + first, 1), __builtin_prefetch(depth_pixels_ + last, 1);
            }
        } else if (x0 < x1 && y0 < y1 && depth_pixels_) {
            // A larger one: the depth lines of its first block row, which the early depth test
            // reads first (it fetches each next block row's itself, and the colour of what it
            // tests: EarlyDepth::prefetch_color).
            const int32_t rows_end = std::min(y1, (y0 & ~int32_t(kBlockSize - 1)) + int32_t(kBlockSize));
            for (int32_t y = y0; y < rows_end; ++y) {
                const uintptr_t first = reinterpret_cast<uintptr_t>(depth_pixels_ + size_t(y) * pitch_ + size_t(x0));
                const uintptr_t last = reinterpret_cast<uintptr_t>(depth_pixels_ + size_t(y) * pitch_ + size_t(x1 - 1));
                for (uintptr_t a = first & ~uintptr_t(63); a <= last; a += 64) __builtin_prefetch(reinterpret_cast<const void*>(a), 1);
            }
        }
    }
}

// The primitive's quads in the tile: with area coverage (SOFTGL_smooth) every pixel it touches and
// its covered fraction; with a blend table and no tests, whole blocks are blended in place and
// only the rest becomes quads (whole_rect.h); likewise a depth-only draw's whole blocks are
// depth-tested in place.
void TilePass::raster(Tile& t, const PrimitiveSetup& p) {
    Scratch& w = t.w;
    w.quads.clear();
    w.areas.clear();
    if (plan_.area_coverage) {
        const GLenum hint = p.kind == PrimitiveKind::Triangle ? state_.smooth.polygon_hint
                          : p.kind == PrimitiveKind::Line ? state_.smooth.line_hint : state_.smooth.point_hint;
        AreaOptions options;
        options.sampled = hint == gl::FASTEST;   // NICEST and DONT_CARE: exact areas
        rasterize_area(p, t.rect, pattern_, options, w.quads, w.areas, w.raster);
    } else if (plan_.whole_rect_blend == Path::Taken && !t.hide) {   // covered blocks in place, the rest as quads
        blend_covered_part(plan_.simd, p, t.rect, pattern_, *blend_table_, buffer_pixels_.color, pitch_, w.quads,
                           w.raster, w.stats);
    } else if (plan_.depth_blocks == Path::Taken && !t.hide) {   // covered blocks tested in place
        depth_covered_part(plan_.simd, p, t.rect, pattern_, quad_depth_test_, w.quads, w.raster, w.stats);
    } else {
        rasterize_at(plan_.simd, p, t.rect, pattern_, w.quads, w.raster);
    }
}

template <bool WithSink>
SOFTGL_STEP void TilePass::draw_primitive(Tile& t, const PrimitiveSetup& p, size_t entry) {
    Scratch& w = t.w;
    Primitive prim{p, entry};
    bool prepared = false;   // the varyings' planes: only once a fragment survives the early tests
    for (size_t c0 = 0; c0 < w.quads.size(); c0 += kChunkQuads) {
        Chunk c{w.quads.data() + c0, plan_.area_coverage ? w.areas.data() + c0 : nullptr,
                std::min(kChunkQuads, w.quads.size() - c0), w.masks.data()};
        c.kept = early_tests<WithSink>(t, prim, c);
        if (c.kept == 0) continue;
        if (plan_.depth_only == Path::Taken) {   // tested (depth/stencil written); nothing to shade
            w.stats.quads += c.kept;
            continue;
        }
        if (!prepared) prepare_varyings(t, prim), prepared = true;
        w.stats.quads += c.kept;
        // A chunk small enough to be gathered is: a shader run per small primitive costs more
        // than its lanes in a full batch (small_draws: 4% more instructions).
        if (prim.flat && (!gather_ || c.kept >= kOwnBatchQuads) &&
            (!prim.interpolate || prim.flat_weights || weights_finite(prim.vi, c.quads, c.masks, c.kept))) {
            if (gather_) flush(t);   // the fragments gathered before come first
            w.stats.fragments_shaded += 4 * c.kept;
            w.stats.fragments_flat += 4 * c.kept;
            write(t, c, flat_colors(t, prim, c));
            continue;
        }
        if constexpr (!WithSink) {   // the blend lab's draws are never gathered (plan_fragment_batches)
            if (gather_) {
                if (c.kept < kOwnBatchQuads ||
                    (single_pixels_ && c.kept < kChunkQuads && helper_lanes(c.masks, c.kept) * 8 > 4 * c.kept)) {
                    if (single_pixels_) gather_pixels(t, prim, c);
                    else gather_quads(t, prim, c);
                    continue;
                }
                flush(t);   // a big chunk is a batch of its own, after the fragments gathered before it
            }
        }
        w.stats.fragments_shaded += 4 * c.kept;
        if (plan_.fused_copy == Path::Taken) {
            write_copied_varying(t, prim, c);
            continue;
        }
        const Colors col = shade(t, prim, c);
        // The common case: tests (if any) already done, nothing discarded, nothing per lane.
        if (!col.any_killed && plan_.color_kernels == Path::Taken) write(t, c, col);
        else per_lane<WithSink>(t, prim, c, col, 0, c.lanes());
    }
}

namespace {

// Whether the covered pixels of a gathered batch's quad are free (no fragment of the batch yet);
// if so, marks them. Only where the write step gathers pixels (exclusive_pixels_).
SOFTGL_STEP bool take_pixels(Gathered& g, const TileRect& rect, const Quad& q, const uint16_t* masks) {
    const int32_t x = q.x - rect.x0, y = q.y - rect.y0;   // even, inside the tile
    const uint64_t row0 = uint64_t((masks[0] != 0) | (masks[1] != 0) << 1) << x;
    const uint64_t row1 = uint64_t((masks[2] != 0) | (masks[3] != 0) << 1) << x;
    if ((g.occupied[y] & row0) | (g.occupied[y + 1] & row1)) return false;
    g.occupied[y] |= row0, g.occupied[y + 1] |= row1;
    g.any_occupied = true;
    return true;
}

// Lanes [first, end) of the gathered batch are primitive p's.
SOFTGL_STEP void add_run(Gathered& g, const PrimitiveSetup& p, size_t end) {
    if (!g.runs.empty() && g.runs.back().p == &p) g.runs.back().end = end;
    else g.runs.push_back({&p, end});
}

}  // namespace

// The chunk's kept quads into the tile's batch, flushing it when it is full or already holds one
// of their pixels; their varyings interpolated with this primitive's planes, in place.
void TilePass::gather_quads(Tile& t, const Primitive& prim, const Chunk& c) {
    Scratch& w = t.w;
    Gathered& g = w.gathered;
    FragmentBatch& b = w.batch;
    const PrimitiveSetup& p = prim.p;
    const uint32_t* const provoking = &vertices_->varyings[size_t(prim.provoking) * size_t(words_)];
    size_t i = 0;
    while (i < c.kept) {
        size_t n = 0;
        while (i + n < c.kept && g.quads + n < kChunkQuads &&
               (!exclusive_pixels_ || take_pixels(g, t.rect, c.quads[i + n], c.masks + 4 * (i + n))))
            ++n;
        if (n) {
            const size_t L0 = g.lanes, lanes = 4 * n;
            std::copy_n(c.quads + i, n, g.quad.data() + g.quads);
            std::copy_n(c.masks + 4 * i, lanes, g.masks.data() + L0);
            uint32_t* const v = b.varyings.data() + L0;
            if (prim.interpolate && !prim.flat_weights) {
                interpolate_varyings_at(plan_.simd, prim.vi, c.quads + i, n, v, kChunkLanes);
            } else {   // flat with finite weights: interpolation gives every vertex's bits
                for (int word : *smooth_words_) std::fill_n(v + size_t(word) * kChunkLanes, lanes, provoking[word]);
            }
            for (int word : *flat_words_) std::fill_n(v + size_t(word) * kChunkLanes, lanes, provoking[word]);
            if (builtins_ & kFrontFacing) std::fill_n(b.front_facing.data() + L0, lanes, uint8_t(p.front_facing ? 1 : 0));
            if (builtins_ & kPositionBuiltins)
                for (size_t lane = 0; lane < lanes; ++lane) {
                    const Quad& quad = c.quads[i + lane / 4];
                    fill_builtins(p, b, L0 + lane, kChunkLanes, quad.x + int32_t(lane & 1), quad.y + int32_t((lane >> 1) & 1));
                }
            g.quads += n, g.lanes += lanes, i += n;
            add_run(g, p, g.lanes);
        }
        if (i < c.kept) flush(t);
    }
}

// No helper lanes: the chunk's covered pixels into the tile's batch, one lane each (flushing as
// gather_quads does), their varyings interpolated pixel by pixel in the lanes they take (thin
// primitives cover one or two pixels of most quads).
void TilePass::gather_pixels(Tile& t, const Primitive& prim, const Chunk& c) {
    Scratch& w = t.w;
    Gathered& g = w.gathered;
    FragmentBatch& b = w.batch;
    const PrimitiveSetup& p = prim.p;
    const uint32_t* const provoking = &vertices_->varyings[size_t(prim.provoking) * size_t(words_)];
    const size_t total = 4 * c.kept;
    size_t from = 0;
    while (from < total) {
        const size_t L0 = g.lanes;
        size_t n = 0;
        for (; from < total && L0 + n < kChunkLanes; ++from) {
            const uint16_t mask = c.masks[from];
            if (!mask) continue;
            const Quad& quad = c.quads[from / 4];
            const int32_t x = quad.x + int32_t(from & 1), y = quad.y + int32_t((from >> 1) & 1);
            if (exclusive_pixels_) {
                uint64_t& row = g.occupied[y - t.rect.y0];
                const uint64_t bit = uint64_t(1) << (x - t.rect.x0);
                if (row & bit) break;   // in the batch already: flush, then this pixel again
                row |= bit;
                g.any_occupied = true;
            }
            const size_t lane = L0 + n;
            g.masks[lane] = mask;
            g.xy[2 * lane] = x, g.xy[2 * lane + 1] = y;
            ++n;
        }
        if (n) {
            uint32_t* const v = b.varyings.data() + L0;
            if (prim.interpolate && !prim.flat_weights) {
                interpolate_pixels_at(plan_.simd, prim.vi, g.xy.data() + 2 * L0, n, v, kChunkLanes);
            } else {   // flat with finite weights: interpolation gives every vertex's bits
                for (int word : *smooth_words_) std::fill_n(v + size_t(word) * kChunkLanes, n, provoking[word]);
            }
            for (int word : *flat_words_) std::fill_n(v + size_t(word) * kChunkLanes, n, provoking[word]);
            if (builtins_ & kFrontFacing) std::fill_n(b.front_facing.data() + L0, n, uint8_t(p.front_facing ? 1 : 0));
            if (builtins_ & kPositionBuiltins)
                for (size_t k = 0; k < n; ++k) fill_builtins(p, b, L0 + k, kChunkLanes, g.xy[2 * (L0 + k)], g.xy[2 * (L0 + k) + 1]);
            g.lanes += n;
            add_run(g, p, g.lanes);
        }
        while (from < total && !c.masks[from]) ++from;
        if (from < total) flush(t);
    }
}

// The gathered batch through the shade and write steps: the colour kernels on all its lanes, or
// lane by lane, primitive by primitive, in draw order.
void TilePass::flush(Tile& t) {
    Scratch& w = t.w;
    Gathered& g = w.gathered;
    if (g.lanes == 0) return;
    FragmentBatch& b = w.batch;
    b.lanes = g.lanes;
    b.lane_stride = kChunkLanes;
    w.stats.fragments_shaded += g.lanes;
    Chunk c{g.quad.data(), nullptr, g.quads, g.masks.data(), g.quads};
    if (single_pixels_) c.xy = g.xy.data(), c.pixels = g.lanes;
    const Colors col = run_shader(t);
    if (!col.any_killed && plan_.color_kernels == Path::Taken) {
        write(t, c, col);
    } else {
        size_t first = 0;
        for (const Gathered::Run& run : g.runs) {
            per_lane<false>(t, Primitive{*run.p, 0}, c, col, first, run.end);
            first = run.end;
        }
    }
    g.quads = g.lanes = 0;
    g.runs.clear();
    if (g.any_occupied) std::fill_n(g.occupied, kTileSize, uint64_t(0)), g.any_occupied = false;
}

// The primitive's vertex values of the interpolated words, and its interpolation planes.
void TilePass::prepare_varyings(Tile& t, Primitive& prim) {
    const PrimitiveSetup& p = prim.p;
    prim.provoking = p.kind == PrimitiveKind::Triangle ? p.vertex[2]
                   : p.kind == PrimitiveKind::Line ? p.vertex[1] : p.vertex[0];
    const int interpolated = p.kind == PrimitiveKind::Triangle ? 3 : p.kind == PrimitiveKind::Line ? 2 : 0;
    const std::vector<int>& smooth = *smooth_words_;
    prim.interpolate = interpolated && !smooth.empty();
    prim.flat = flat_primitives_;
    prim.flat_lanes = 0;
    if (!prim.interpolate) return;
    std::vector<float>& values = t.w.values;
    const size_t count = smooth.size();
    if (values.size() < 3 * count) values.resize(3 * count);
    // Each vertex's words straight into prepare_interpolation's form: v_0, then d_1 (and d_2).
    const uint32_t* const varyings = vertices_->varyings.data();
    const uint32_t* const v0 = varyings + size_t(p.vertex[0]) * size_t(words_);
    const uint32_t* const v1 = varyings + size_t(p.vertex[1]) * size_t(words_);
    const uint32_t* const v2 = varyings + size_t(p.vertex[2]) * size_t(words_);
    const int* const words = smooth.data();
    float* const out = values.data();
    if (interpolated == 3) {
        for (size_t i = 0; i < count; ++i) {
            const float a = as_float(v0[words[i]]);
            out[i] = a;
            out[count + i] = vertex_difference(as_float(v1[words[i]]), a);
            out[2 * count + i] = vertex_difference(as_float(v2[words[i]]), a);
        }
    } else {
        for (size_t i = 0; i < count; ++i) {
            const float a = as_float(v0[words[i]]);
            out[i] = a;
            out[count + i] = vertex_difference(as_float(v1[words[i]]), a);
        }
    }
    if (prim.flat) {
        // Flat when every read word has the same bits at each vertex (not -0, not NaN: v_0 + 0
        // must give v_0 back; tests/pipeline/test_flat_primitives.py).
        const uint32_t* const vs[3] = {v0, v1, v2};
        for (size_t i = 0; i < count && prim.flat; ++i) {
            const uint32_t bits = v0[words[i]];
            prim.flat = bits != 0x80000000u && !std::isnan(as_float(bits));
            for (int v = 1; v < interpolated && prim.flat; ++v) prim.flat = vs[v][words[i]] == bits;
        }
    }
    set_interpolation_planes(p, interpolated, t.rect.x0, t.rect.y0, words, count, out, prim.vi);
    // Quads may reach one pixel past the tile's last row or column (a buffer of odd size).
    prim.flat_weights = prim.flat && weights_finite_in(prim.vi, t.rect.x1 - t.rect.x0, t.rect.y1 - t.rect.y0);
}

// The chunk's surviving samples, its quads with one compacted to the front: the pixels the
// primitive owns after hidden-surface removal's first pass; or the early depth/stencil tests
// (legal when the shader cannot discard or write depth); or, tested later or not at all, the
// coverage as it is.
template <bool WithSink>
SOFTGL_STEP size_t TilePass::early_tests(Tile& t, const Primitive& prim, Chunk& c) {
    // In locals: the mask stores below may alias anything, so fields would be read again each time.
    Quad* const cq = c.quads;
    QuadArea* const ca = c.areas;
    uint16_t* const masks = c.masks;
    const size_t count = c.count;
    size_t kept = 0;
    if (t.hide) {   // the tests ran in the first pass
        const OwnerMap owners = t.owners;
        const size_t entry = prim.entry;
        for (size_t qi = 0; qi < count; ++qi) {
            const uint64_t m4 = owners.owned(cq[qi], cq[qi].coverage, entry);
            if (!m4) continue;
            cq[kept] = cq[qi];
            std::memcpy(&masks[kept * 4], &m4, 8);
            ++kept;
        }
        return kept;
    }
    if (!plan_.early_tests()) {
        // A quad's coverage is its four pixel masks side by side (quad_pixel_mask).
        for (size_t qi = 0; qi < count; ++qi) std::memcpy(&masks[qi * 4], &cq[qi].coverage, 8);
        return count;
    }
    uint64_t killed_early;
    if (plan_.quad_depth == Path::Taken) {
        EarlyDepth test = quad_depth_test_;
        test.prim = &prim.p;
        killed_early = early_depth_test_at(plan_.simd, test, cq, count, masks);
    } else {
        killed_early = early_tests_per_sample<WithSink>(prim, c);
    }
    t.w.stats.fragments_killed_early += killed_early;
    if (plan_.depth_only == Path::Taken) {   // nothing reads the quads after their tests: only counted
        for (size_t qi = 0; qi < count; ++qi) {
            uint64_t m4;
            std::memcpy(&m4, &masks[qi * 4], 8);
            kept += m4 != 0;
        }
        return kept;
    }
    // The quads with a surviving sample move to the front (kept <= qi).
    for (size_t qi = 0; qi < count; ++qi) {
        uint64_t m4;
        std::memcpy(&m4, &masks[qi * 4], 8);
        if (!m4) continue;
        cq[kept] = cq[qi];
        if (ca) ca[kept] = ca[qi];
        std::memcpy(&masks[kept * 4], &m4, 8);
        ++kept;
    }
    return kept;
}

// Early depth/stencil sample by sample (stencil, framebuffer objects, the blend lab); returns the
// number of samples that failed.
template <bool WithSink>
size_t TilePass::early_tests_per_sample(const Primitive& prim, Chunk& c) {
    const PrimitiveSetup& p = prim.p;
    size_t killed = 0;
    for (size_t qi = 0; qi < c.count; ++qi) {
        const Quad& quad = c.quads[qi];
        for (int j = 0; j < 4; ++j) {
            uint16_t mask = uint16_t(quad_pixel_mask(quad, j));
            if (mask) {
                const int32_t x = quad.x + (j & 1), y = quad.y + (j >> 1);
                uint32_t* depth = fb_.depth_samples(x, y);
                uint8_t* stencil = ds_.stencil_test ? fb_.stencil_samples(x, y) : nullptr;
                for (int s = 0; s < samples_; ++s) {
                    if (!(mask & (1u << s))) continue;
                    const uint32_t z = fb_.depth_word(p.depth_at(int64_t(x) * kSubPixel + pattern_.x[s],
                                                                 int64_t(y) * kSubPixel + pattern_.y[s]));
                    if constexpr (WithSink)
                        sink_->before_depth_stencil(ds_, p, x, y, s, z, depth ? depth + s : nullptr,
                                                    stencil ? stencil + s : nullptr, true);
                    if (!depth_stencil_test(ds_, p.front_facing, z, depth ? depth + s : nullptr,
                                            stencil ? stencil + s : nullptr)) {
                        mask = uint16_t(mask & ~(1u << s));
                        ++killed;
                    }
                }
            }
            c.masks[qi * 4 + size_t(j)] = mask;
        }
    }
    return killed;
}

// The shader only copies one smooth vec4 varying: its values go straight into pixels, no fragment
// batch, and runs of four whole quads straight into the buffer's rows.
SOFTGL_STEP void TilePass::write_copied_varying(Tile& t, const Primitive& prim, const Chunk& c) {
    uint32_t* const d = t.w.pixels.data();
    const uint64_t rows = whole_rows_of_four(buffer_pixels_, c.quads, c.masks, c.kept);
    if (plan_.kernel != ColorKernel::Plain || !plan_.all_channels)
        load_chunk_pixels(buffer_pixels_, c.quads, c.masks, c.kept, d, rows);
    write_interpolated_color_lanes_at(plan_.simd, plan_.kernel, blend_, prim.vi, size_t(plan_.copied_index), c.quads,
                                      c.kept, d, PixelRows{buffer_pixels_.color, buffer_pixels_.pitch, rows});
    const uint64_t written = store_chunk_pixels(buffer_pixels_, c.quads, c.masks, c.kept, d, rows);
    t.w.stats.samples_written += written;
    if (!plan_.plain_write) t.w.stats.samples_blended += written;
}

// The chunk's colours: the constant colour; or, from the fragment batch, the copied varying's
// lanes, the shader's copies, or the shader's results.
SOFTGL_STEP TilePass::Colors TilePass::shade(Tile& t, const Primitive& prim, const Chunk& c) {
    if (plan_.constant_color == Path::Taken) return Colors{constant_color_, kChunkLanes, 1, false};
    build_fragment_batch(t, prim, c);
    return run_shader(t);
}

// A flat primitive's colour for the chunk's lanes: the shader runs once per primitive and tile,
// on the provoking vertex's words (flat words come from it; the smooth ones are the same at every
// vertex).
SOFTGL_STEP TilePass::Colors TilePass::flat_colors(Tile& t, Primitive& prim, const Chunk& c) {
    Scratch& w = t.w;
    const size_t L = c.lanes();
    if (prim.flat_lanes == 0) fs_.run_flat(&vertices_->varyings[size_t(prim.provoking) * size_t(words_)], w.flat_results, t.worker);
    if (prim.flat_lanes < L) {
        float* const lanes = at_least(w.flat_color, 4 * kChunkLanes);
        for (size_t k = 0; k < 4; ++k) std::fill(lanes + k * kChunkLanes + prim.flat_lanes, lanes + k * kChunkLanes + L, w.flat_results.color[k]);
        prim.flat_lanes = L;
    }
    return Colors{w.flat_color.data(), kChunkLanes, 1, false};
}

// The shader (or its copies) on the fragment batch.
SOFTGL_STEP TilePass::Colors TilePass::run_shader(Tile& t) {
    FragmentBatch& b = t.w.batch;
    const size_t L = b.lanes, S = b.stride();
    if (plan_.copied_word >= 0)   // the colour is the varying's lanes (FragmentShader::copies)
        return Colors{reinterpret_cast<const LaneFloat*>(b.varyings.data()) + size_t(plan_.copied_word) * S, S, 1, false};
    if (texel_words_) {
        fs_.run_words(b, t.w.pixels.data(), t.worker);
        return Colors{nullptr, 0, 1, false, true};
    }
    FragmentResults& r = t.w.results;
    if (copies_) copy_outputs(*copies_, b, r);
    else fs_.run(b, r, t.worker);
    bool any_killed = false;
    for (uint8_t kill : r.killed) any_killed |= kill != 0;
    return Colors{r.color.data(), L, r.outputs, any_killed};
}

// The inputs the shader reads, per lane, structure of arrays.
void TilePass::build_fragment_batch(Tile& t, const Primitive& prim, const Chunk& c) {
    const PrimitiveSetup& p = prim.p;
    FragmentBatch& b = t.w.batch;
    const size_t L = 4 * c.kept;
    const uint32_t* const provoking = &vertices_->varyings[size_t(prim.provoking) * size_t(words_)];
    b.lanes = L;
    b.lane_stride = 0;
    if (builtins_ & kFrontFacing) std::fill_n(b.front_facing.data(), L, uint8_t(p.front_facing ? 1 : 0));
    if (prim.interpolate) {
        interpolate_varyings_at(plan_.simd, prim.vi, c.quads, c.kept, b.varyings.data(), L);
    } else {
        for (int word : *smooth_words_)   // points: no interpolation, the vertex's value
            std::fill_n(&b.varyings[size_t(word) * L], L, provoking[word]);
    }
    for (int word : *flat_words_) std::fill_n(&b.varyings[size_t(word) * L], L, provoking[word]);
    if (!(builtins_ & kPositionBuiltins)) return;
    for (size_t qi = 0; qi < c.kept; ++qi) {
        const Quad& quad = c.quads[qi];
        for (int j = 0; j < 4; ++j) fill_builtins(p, b, qi * 4 + size_t(j), L, quad.x + (j & 1), quad.y + (j >> 1));
    }
}

// Lane `lane` (arrays `stride` lanes per component) is pixel (x, y) of p: gl_FragCoord,
// gl_PointCoord.
SOFTGL_STEP void TilePass::fill_builtins(const PrimitiveSetup& p, FragmentBatch& b, size_t lane, size_t stride,
                                         int32_t x, int32_t y) const {
    float* const fc = b.frag_coord.data();
    fc[lane] = float(x) + 0.5f;
    fc[stride + lane] = float(y) + 0.5f;
    float pc[2] = {0, 0};
    if (p.kind == PrimitiveKind::Point) p.point_coord(x, y, pc);
    b.point_coord[lane] = pc[0];
    b.point_coord[stride + lane] = pc[1];
    // The planes at the pixel centre, as PrimitiveSetup::eval computes them.
    const double fx = pixel_centre_offset(x, p.origin_x), fy = pixel_centre_offset(y, p.origin_y);
    if (builtins_ & kFragCoordZ) {   // p.depth_at: plane + offset, clamped to [0, 1]
        const double z = (p.depth.c + p.depth.a * fx + p.depth.b * fy) + p.depth_offset;
        fc[2 * stride + lane] = float(z < 0 ? 0 : (z > 1 ? 1 : z));
    }
    if (builtins_ & kFragCoordW) fc[3 * stride + lane] = float(p.inv_w.c + p.inv_w.a * fx + p.inv_w.b * fy);
}

// The colour kernels on the chunk (the RGBA8 drawing buffer; tests done, nothing discarded):
// by table lookup with rows of four in place; single-sampled, all lanes at once between gathered
// and scattered pixels (ChunkPixels); multisampled, all lanes at once, then into each covered
// sample; the Generic kernel sample by sample.
SOFTGL_STEP void TilePass::write(Tile& t, const Chunk& c, const Colors& col) {
    Scratch& w = t.w;
    const size_t L = c.lanes();
    const uint64_t before = w.stats.samples_written;
    const LaneFloat* const src = col.col;
    const size_t cs = col.stride;
    // In locals: the byte stores into pixels may alias anything, so fields would be read again.
    const Chunk chunk = c;
    const uint16_t* const masks = c.masks;
    const bool all_channels = plan_.all_channels;
    const float* const table = unorm8_table_;
    const int samples = samples_;
    auto write_all = [&](auto kernel_tag) {
        constexpr ColorKernel K = decltype(kernel_tag)::value;
        for (size_t lane = 0; lane < L; ++lane) {
            const uint16_t mask = masks[lane];
            if (!mask) continue;
            int32_t x, y;
            chunk.pixel(lane, x, y);
            const float color[4] = {src[lane], src[cs + lane], src[2 * cs + lane], src[3 * cs + lane]};
            uint8_t* px = color_bytes_ + (size_t(y) * pitch_ + size_t(x)) * size_t(samples) * 4;
            if (samples == 1) {
                write_color<K>(blend_, all_channels, table, color, px);
                w.stats.samples_written++;
            } else {
                for (int s = 0; s < samples; ++s) {
                    if (!(mask & (1u << s))) continue;
                    write_color<K>(blend_, all_channels, table, color, px + 4 * s);
                    w.stats.samples_written++;
                }
            }
        }
    };
    if (blend_table_) {
        uint32_t* const d = w.pixels.data();
        const uint64_t rows = whole_rows_of_four(buffer_pixels_, c.quads, c.masks, c.kept);
        load_chunk_pixels(buffer_pixels_, c.quads, c.masks, c.kept, d, rows);
        apply_blend_table_at(plan_.simd, *blend_table_, c.quads, c.kept, d, PixelRows{buffer_pixels_.color, pitch_, rows});
        w.stats.samples_written += store_chunk_pixels(buffer_pixels_, c.quads, c.masks, c.kept, d, rows);
    } else if (samples_ == 1 && plan_.kernel != ColorKernel::Generic) {
        // Gather the destination pixels (only when the kernel reads them), blend all lanes at
        // once, scatter back.
        uint32_t* const d = w.pixels.data();
        const bool reads = plan_.kernel != ColorKernel::Plain || !plan_.all_channels;
        if (c.xy) {   // single pixels, each covered
            if (reads) load_lane_pixels(buffer_pixels_, c.xy, L, d);
            if (!col.words) write_color_lanes_at(plan_.simd, plan_.kernel, blend_, src, cs, d, L);
            store_lane_pixels(buffer_pixels_, c.xy, L, d);
            w.stats.samples_written += L;
        } else {
            if (reads && !col.words) {   // both steps at once (write_color_quads_at)
                w.stats.samples_written += write_color_quads_at(plan_.simd, in_.tuning.blend_in_place, plan_.kernel, blend_,
                                                                src, cs, buffer_pixels_, c.quads, c.masks, c.kept, d,
                                                                w.stats.quads_blended_in_place);
            } else {
                if (reads) load_chunk_pixels(buffer_pixels_, c.quads, c.masks, c.kept, d);
                if (!col.words) write_color_lanes_at(plan_.simd, plan_.kernel, blend_, src, cs, d, L);
                w.stats.samples_written += store_chunk_pixels(buffer_pixels_, c.quads, c.masks, c.kept, d);
            }
        }
    } else if (plan_.kernel != ColorKernel::Generic) {
        // Multisampled: the kernel on all lanes at once, then each lane's result into its covered
        // samples. A kernel that does not read the destination gives one result per lane, the
        // same for every sample; one that does runs once per sample index over that sample of
        // every lane's pixel (lanes not covering it compute a value nobody stores). Lane by lane
        // it is write_color<K> on each covered sample, as write_all below.
        uint32_t* const d = w.pixels.data();
        const size_t S = size_t(samples);
        const uint16_t whole = uint16_t((1u << S) - 1u);
        const bool reads = plan_.kernel != ColorKernel::Plain || !all_channels;
        auto pixel_of = [&](size_t lane) {
            int32_t x, y;
            chunk.pixel(lane, x, y);
            return color_bytes_ + (size_t(y) * pitch_ + size_t(x)) * S * 4;
        };
        uint64_t written = 0;
        if (!reads) {
            write_color_lanes_at(plan_.simd, plan_.kernel, blend_, src, cs, d, L);
            for (size_t lane = 0; lane < L; ++lane) {
                const uint16_t mask = masks[lane];
                if (!mask) continue;
                uint8_t* const px = pixel_of(lane);
                if (mask == whole) {
                    for (size_t s = 0; s < S; ++s) std::memcpy(px + 4 * s, &d[lane], 4);
                    written += S;
                    continue;
                }
                for (size_t s = 0; s < S; ++s)
                    if (mask & (1u << s)) std::memcpy(px + 4 * s, &d[lane], 4), ++written;
            }
        } else {
            for (size_t s = 0; s < S; ++s) {
                bool any = false;
                for (size_t lane = 0; lane < L; ++lane)
                    if (masks[lane] & (1u << s)) std::memcpy(&d[lane], pixel_of(lane) + 4 * s, 4), any = true;
                if (!any) continue;
                write_color_lanes_at(plan_.simd, plan_.kernel, blend_, src, cs, d, L);
                for (size_t lane = 0; lane < L; ++lane)
                    if (masks[lane] & (1u << s)) std::memcpy(pixel_of(lane) + 4 * s, &d[lane], 4), ++written;
            }
        }
        w.stats.samples_written += written;
    } else {
        switch (plan_.kernel) {
            case ColorKernel::Plain: write_all(std::integral_constant<ColorKernel, ColorKernel::Plain>{}); break;
            case ColorKernel::AlphaOver: write_all(std::integral_constant<ColorKernel, ColorKernel::AlphaOver>{}); break;
            case ColorKernel::Additive: write_all(std::integral_constant<ColorKernel, ColorKernel::Additive>{}); break;
            case ColorKernel::Generic: write_all(std::integral_constant<ColorKernel, ColorKernel::Generic>{}); break;
        }
    }
    if (!plan_.plain_write) w.stats.samples_blended += w.stats.samples_written - before;
}

// Lane by lane, per covered sample: discard, coverage operations, late tests, coverage, fog and
// blending through RenderTarget::write_color (any format, every colour output).
template <bool WithSink>
void TilePass::per_lane(Tile& t, const Primitive& prim, const Chunk& c, const Colors& col, size_t first, size_t end) {
    Scratch& w = t.w;
    const PrimitiveSetup& p = prim.p;
    const size_t cs = col.stride;
    const FragmentResults& r = w.results;
    for (size_t lane = first; lane < end; ++lane) {
        uint16_t mask = c.masks[lane];
        if (!mask) continue;
        if (col.any_killed && r.killed[lane]) {
            w.stats.fragments_discarded++;
            if constexpr (WithSink) sink_->discarded(p, c.quads[lane / 4], int(lane % 4), mask);
            continue;
        }
        int32_t x, y;
        c.pixel(lane, x, y);
        if constexpr (WithSink) {
            const float shaded[4] = {col.col[lane], col.col[cs + lane], col.col[2 * cs + lane], col.col[3 * cs + lane]};
            sink_->shaded(p, x, y, mask, shaded);
        }
        if (plan_.coverage_ops && !(mask = coverage_ops<WithSink>(p, col, lane, x, y, mask))) continue;
        if (plan_.late_tests()) mask = late_tests<WithSink>(t, prim, lane, x, y, mask);
        if (!plan_.writes_color || !mask) continue;
        // Every colour output (MRT: framebuffer objects with drawBuffers) with the same changes.
        float colors[kMaxFragmentOutputs][4];
        for (int o = 0; o < col.outputs; ++o) {
            const LaneFloat* oc = col.col + size_t(4 * o) * cs;
            for (int k = 0; k < 4; ++k) colors[o][k] = oc[size_t(k) * cs + lane];
            if (c.areas) coverage(colors[o], c.areas[lane / 4].fraction[lane % 4]);
            if (fog_.enabled) fog(fog_, p, x, y, colors[o]);
        }
        blend<WithSink>(t, prim, col, lane, x, y, mask, colors);
    }
}

// Alpha-to-coverage and SAMPLE_COVERAGE (multisampled), before the depth and stencil tests
// (ES 3.0 §4.1.3): the lane's samples that stay.
template <bool WithSink>
uint16_t TilePass::coverage_ops(const PrimitiveSetup& p, const Colors& col, size_t lane, int32_t x, int32_t y,
                                uint16_t mask) const {
    const uint16_t before = mask;
    if (state_.sample_alpha_to_coverage)
        mask = uint16_t(mask & coverage_from_value(col.col[3 * col.stride + lane], samples_));
    mask = uint16_t(mask & coverage_mask_);
    if constexpr (WithSink) sink_->coverage_ops(p, x, y, before, mask);
    return mask;
}

// Depth/stencil after shading (the shader may discard or write gl_FragDepth, or coverage
// operations came first): the lane's surviving samples.
template <bool WithSink>
uint16_t TilePass::late_tests(Tile& t, const Primitive& prim, size_t lane, int32_t x, int32_t y, uint16_t mask) {
    const PrimitiveSetup& p = prim.p;
    const FragmentResults& r = t.w.results;
    uint32_t* depth = fb_.depth_samples(x, y);
    uint8_t* stencil = fb_.stencil_samples(x, y);
    for (int s = 0; s < samples_; ++s) {
        if (!(mask & (1u << s))) continue;
        const double zf = shader_depth_ ? double(clamp01(r.depth[lane]))
                                       : p.depth_at(int64_t(x) * kSubPixel + pattern_.x[s],
                                                    int64_t(y) * kSubPixel + pattern_.y[s]);
        if constexpr (WithSink)
            sink_->before_depth_stencil(ds_, p, x, y, s, fb_.depth_word(zf), depth ? depth + s : nullptr,
                                        stencil ? stencil + s : nullptr, false);
        if (!depth_stencil_test(ds_, p.front_facing, fb_.depth_word(zf), depth ? depth + s : nullptr,
                                stencil ? stencil + s : nullptr)) {
            mask = uint16_t(mask & ~(1u << s));
            t.w.stats.fragments_killed_late++;
        }
    }
    return mask;
}

// The lane's colours into its surviving samples (RenderTarget::write_color blends by the state).
template <bool WithSink>
void TilePass::blend(Tile& t, const Primitive& prim, const Colors& col, size_t lane, int32_t x, int32_t y,
                     uint16_t mask, const float (*colors)[4]) {
    Scratch& w = t.w;
    for (int s = 0; s < samples_; ++s) {
        if (!(mask & (1u << s))) continue;
        if constexpr (WithSink) {
            const float shader_depth = shader_depth_ ? clamp01(w.results.depth[lane]) : -1.0f;
            if (sink_->before_blend(prim.p, x, y, s, colors[0], drawing_buffer_->color_sample(x, y, s), shader_depth))
                continue;   // the A-buffer keeps the sample instead of blending it
        }
        fb_.write_color(blend_, colors[0], x, y, s);
        for (int o = 1; o < col.outputs; ++o) fb_.write_color(blend_, colors[o], x, y, s, o);   // MRT
        if constexpr (WithSink) sink_->after_blend(x, y, s, drawing_buffer_->color_sample(x, y, s));
        w.stats.samples_written++;
        if (!plan_.plain_write) w.stats.samples_blended++;
    }
}

}  // namespace softgl
