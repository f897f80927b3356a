#include "softgl/pipeline/draw.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <optional>
#include <unordered_map>

#include "softgl/pipeline/assemble.h"
#include "softgl/pipeline/bin.h"
#include "softgl/pipeline/draw_rollback.h"
#include "softgl/pipeline/fragment_sink.h"
#include "softgl/pipeline/setup.h"
#include "softgl/pipeline/tile_pass.h"
#include "softgl/pipeline/vertex_fetch.h"

namespace softgl {

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
    // SOFTGL_smooth shapes (GL 1.5 §3.4-3.5); smoothing is ignored when multisampling (§3.2.1).
    r.line_smooth = s.smooth.line && r.samples == 1;
    const float* range = r.line_smooth ? kSmoothLineWidthRange : kAliasedLineWidthRange;
    r.line_width = std::clamp(double(s.line_width), double(range[0]), double(range[1]));
    r.point_smooth = s.smooth.point && r.samples == 1;
    r.sample_bounds = r.samples == 1 && !s.smooth.polygon;
    return r;
}

// Work is split into chunks of consecutive vertices or primitives that the pool shades and sets up
// in parallel. Each chunk's results land in fixed places (vertices) or are gathered in chunk order
// (primitives, bins), so nothing depends on the thread count.
constexpr size_t kVertexChunk = 1024;   // vertices per vertex-stage job
constexpr size_t kSetupChunk = 2048;    // primitives per setup-and-binning job

struct VertexWorker {
    std::array<AttributeStream, kMaxVertexAttribs> attribs;
    std::vector<uint32_t> vertex_ids, instance_ids;   // per lane of the job
    AttributeStream one_instance;                     // a per-vertex array's lanes of one instance
};

// The set-up primitives of one chunk, its counters and its bins (indices local to the chunk).
struct SetupChunk {
    std::vector<PrimitiveSetup> prims;
    SetupStats stats;
};

// Everything a draw's batches allocate, kept between draws on the calling thread
// (docs/architecture.md, "Fast paths": no per-draw allocations; buffers only grow, so a repeated
// draw touches no fresh pages). The tile pass keeps its own (pipeline/tile_pass.cpp).
struct DrawScratch {
    std::vector<uint32_t> ids, listed, slot_of_position, tiles, index_base;
    std::vector<uint32_t> slot_of_index;   // list_vertices: per index - lowest, its slot (~0u: none yet)
    std::unordered_map<uint32_t, uint32_t> slot;   // ... when the indices span too wide a range
    std::vector<VertexWorker> vertex_workers;
    VertexShaderOutputs all;
    std::vector<WindowPosition> window;   // triangles and lines: the batch's vertices projected by setup
    std::vector<SetupChunk> chunks;
    std::vector<Bins> chunk_bins;
    PrimitiveTable prims;
    Bins bins;
};

DrawScratch& draw_scratch() {
    thread_local DrawScratch scratch;
    return scratch;
}

uint64_t draw_scratch_bytes() {
    const DrawScratch& s = draw_scratch();
    uint64_t n = capacity_bytes(s.ids) + capacity_bytes(s.listed) + capacity_bytes(s.slot_of_position) + capacity_bytes(s.tiles) +
                 capacity_bytes(s.index_base) + capacity_bytes(s.slot_of_index) + capacity_bytes(s.slot) +
                 capacity_bytes(s.vertex_workers) + capacity_bytes(s.all.position) + capacity_bytes(s.all.point_size) +
                 capacity_bytes(s.all.varyings) + capacity_bytes(s.window) + capacity_bytes(s.chunks) +
                 capacity_bytes(s.chunk_bins) + capacity_bytes(s.prims.chunk) + s.bins.capacity_bytes();
    for (const VertexWorker& w : s.vertex_workers) {
        n += capacity_bytes(w.vertex_ids) + capacity_bytes(w.instance_ids);
        for (const AttributeStream& a : w.attribs)
            for (const std::vector<uint32_t>& c : a.comp) n += capacity_bytes(c);
    }
    for (const SetupChunk& c : s.chunks) n += capacity_bytes(c.prims);
    for (const Bins& b : s.chunk_bins) n += b.capacity_bytes();
    return n;
}

// The scratch this thread keeps between draws (the draw's, its tile pass's for every worker,
// the rollback copies: all on the calling thread), charged to the memory ledger after every draw
// (docs/reliability.md, "Memory"): to the account of the context that drew last on this thread,
// which is the one holding it for its next draw. The bytes are already allocated, so they are
// forced past the limits; what a draw can grow them by is bounded by its batch size.
void charge_thread_scratch(const std::shared_ptr<MemoryAccount>& account) {
    thread_local MemoryReservation held;
    if (held.account() != account.get()) held = MemoryReservation(account);
    held.force(draw_scratch_bytes() + tile_pass_scratch_bytes() + rollback_scratch_bytes());
}

// Grows v to at least n elements; never shrinks, so a smaller draw does not zero-fill again.
template <class T>
T* at_least(std::vector<T>& v, size_t n) {
    if (v.size() < n) v.resize(n);
    return v.data();
}

// Runs job(chunk, worker) for chunks [0, count) on the pool. After the first exception (the work
// budget ran out or Ctrl-C: core/work_budget.h) the remaining chunks are skipped; parallel_for
// rethrows it.
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

// A draw in batches. At most plan.batch_primitives primitives at a time go through the vertex
// stage (only the vertices they use), setup and binning, and the tile pass, before the next batch:
// working memory is bounded whatever the draw's size, and every pixel still sees the primitives in
// draw order (ES 3.0 §4), batch after batch. A batch holds whole instances when one instance's
// primitives fit (the draw's vertex list then serves every batch), else part of one instance.
class Batches {
public:
    Batches(const DrawInputs& in, const DrawCall& call, const FragmentOps& ops, DrawPlan& plan, DrawStats& st)
        : in_(in), call_(call), plan_(plan), st_(st), s_(draw_scratch()), rs_(raster_state(in.state, in.target)),
          grid_(in.target.width(), in.target.height()), words_(in.vertex_shader.varying_layout().words),
          per_instance_(primitive_count(call.mode, call.count)),
          whole_instances_(per_instance_ <= plan.batch_primitives), tile_pass_(in, ops, grid_, plan) {}

    void run_all() {
        const uint32_t limit = plan_.batch_primitives;
        const uint32_t instances_per_batch = whole_instances_
            ? uint32_t(std::min<uint64_t>(call_.instance_count, limit / std::max<uint32_t>(per_instance_, 1))) : 1;
        const uint32_t step = whole_instances_ ? std::max<uint32_t>(per_instance_, 1) : limit;
        if (whole_instances_) list_vertices(0, per_instance_);
        several_batches_ = call_.instance_count > instances_per_batch || per_instance_ > step;
        for (uint32_t instance = 0; instance < call_.instance_count; instance += instances_per_batch) {
            const uint32_t instances = std::min(instances_per_batch, call_.instance_count - instance);
            if (in_.budget) in_.budget->check();
            uint32_t p0 = 0;
            do {
                const uint32_t p1 = uint32_t(std::min<uint64_t>(per_instance_, uint64_t(p0) + step));
                run(instance, instances, p0, p1);
                p0 = p1;
            } while (p0 < per_instance_);
        }
    }

    // The draw's counters: setup's and the tile pass's.
    void add_counters() {
        st_.primitives = setup_stats_.primitives;
        st_.primitives_culled = setup_stats_.culled;
        st_.primitives_clipped = setup_stats_.clipped;
        st_.primitives_outside = setup_stats_.outside;
        st_.primitives_invalid = setup_stats_.invalid;
        st_.primitives_zero_area = setup_stats_.zero_area;
        st_.primitives_rasterized = setup_stats_.emitted;
        tile_pass_.add_counters(st_);
    }

    // After run_all, or when it threw: whether the draw kept copies, and putting them back.
    bool keeps_copies() const { return rollback_.has_value(); }
    // Whether a tile pass began (pixels may have been written).
    bool began_writing() const { return decided_; }
    void roll_back() {
        if (rollback_) rollback_->restore();
    }

private:
    // Instances [instance, instance + instances), primitives [p0, p1) of each.
    void run(uint32_t instance, uint32_t instances, uint32_t p0, uint32_t p1) {
        Clock::time_point t0 = Clock::now();
        shade_vertices(instance, instances, p0, p1);
        st_.seconds_vertex += lap(t0);
        if (plan_.skip == DrawSkip::RasterizerDiscard) return;
        const bool binned = set_up_and_bin(instance, instances, p0, p1);
        st_.seconds_setup += lap(t0);
        if (!binned) return;
        if (!decided_) decide_rollback();
        tile_pass_.run(TileBatch{*bins_, s_.prims, s_.all, s_.tiles}, st_);
        st_.seconds_fragment += since(t0);
    }

    // Before the draw's first tile pass (pipeline/draw_rollback.h): a draw that can be stopped after
    // writing pixels keeps copies to put them back; any other defers a stop to its end (the vertex
    // stage and setup before this point write no pixel and stop at once).
    void decide_rollback() {
        decided_ = true;
        if (!in_.budget) return;   // unbudgeted (test harnesses): nothing stops it
        uint64_t pairs = 0, pixels = 0;
        for (uint32_t tile : s_.tiles) pairs += bins_->tile(tile).size();
        for (size_t c = 0; c < setup_chunks_; ++c) pixels += s_.chunk_bins[c].quad_pixels_bound;
        const uint64_t estimate = fragment_work_estimate(pairs, pixels, in_.fragment_shader.instructions_bound());
        if (rollback_needed(several_batches_, estimate, in_.budget->remaining())) {
            // The copies are charged to the memory ledger at their bound (every pixel of every
            // attachment) for the draw's length; over the limit, the draw stops before writing.
            const uint64_t bound = DrawRollback::bytes_bound(in_.target);
            copies_memory_ = MemoryReservation(in_.memory);
            if (!copies_memory_.reserve(bound))
                throw DrawOutOfMemory("the copies of the pixels it may write (kept to undo a stopped draw) need " +
                                          std::to_string(bound) + " bytes, which " + copies_memory_.over_limit(bound),
                                      true);
            rollback_.emplace(in_.target, grid_);
            tile_pass_.set_rollback(&*rollback_);
        } else {
            in_.budget->defer_stops(true);
        }
    }

    // The batch's vertices: `ids` (distinct, in first-use order) and, for the vertex numbers in
    // `range` (draw order), the slot of each: begin..end - 1 are positions 0.., vertex 0 outside
    // the range (a fan's centre, a loop's end) is the last position.
    void list_vertices(uint32_t p0, uint32_t p1) {
        range_ = whole_instances_ ? VertexRange{0, call_.count, false}
                                  : primitive_vertex_range(call_.mode, call_.count, p0, p1);
        const uint32_t inside = range_.end - range_.begin, count = inside + (range_.and_zero ? 1 : 0);
        std::vector<uint32_t>& ids = s_.ids;
        ids.clear();
        if (call_.indices) {
            s_.slot_of_position.resize(count);
            auto index_at = [&](uint32_t k) { return call_.indices[k < inside ? range_.begin + k : 0]; };
            const uint32_t* const run = call_.indices + range_.begin;   // positions 0 .. inside - 1
            uint32_t lowest = range_.and_zero ? call_.indices[0] : ~0u, highest = range_.and_zero ? lowest : 0;
            if (whole_instances_ && call_.index_bounds) lowest = call_.lowest_index, highest = call_.highest_index;
            else
                for (uint32_t k = 0; k < inside; ++k) lowest = std::min(lowest, run[k]), highest = std::max(highest, run[k]);
            const uint64_t span = count ? uint64_t(highest) - lowest + 1 : 0;
            if (span <= std::max<uint64_t>(uint64_t(1) << 16, 8 * uint64_t(count))) {
                // A table over the indices' span (8- and 16-bit indices always fit): the same slots
                // as the hash map below without a node allocated and freed per vertex.
                uint32_t* const slot = at_least(s_.slot_of_index, size_t(span));
                std::fill_n(slot, size_t(span), ~0u);
                // Listed in a buffer that only grows (ids, cut to the distinct ones, would be
                // zero-filled again by the next draw's growth), then copied.
                uint32_t* const listed = at_least(s_.listed, count);
                uint32_t* const slot_of_position = s_.slot_of_position.data();
                uint32_t distinct = 0;
                auto visit = [&](uint32_t k, uint32_t index) {
                    uint32_t& s = slot[index - lowest];
                    if (s == ~0u) s = distinct, listed[distinct++] = index;
                    slot_of_position[k] = s;
                };
                for (uint32_t k = 0; k < inside; ++k) visit(k, run[k]);
                if (range_.and_zero) visit(inside, call_.indices[0]);
                ids.assign(listed, listed + distinct);
            } else {
                std::unordered_map<uint32_t, uint32_t>& slot = s_.slot;
                slot.clear();
                slot.reserve(size_t(count) * 2);
                for (uint32_t k = 0; k < count; ++k) {
                    const uint32_t index = index_at(k);
                    auto [it, added] = slot.emplace(index, uint32_t(ids.size()));
                    if (added) ids.push_back(index);
                    s_.slot_of_position[k] = it->second;
                }
            }
        } else {
            ids.resize(count);
            for (uint32_t k = 0; k < count; ++k) ids[k] = call_.first + (k < inside ? range_.begin + k : 0);
        }
    }

    // The vertex stage: each of the batch's vertices once per instance, instance i's vertex v at
    // i * n + v. Triangles and lines project and snap each vertex once, vectorised, while its
    // position is hot. A job shades up to kVertexChunk vertices: a chunk of one instance's, or,
    // when an instance has fewer, the vertices of as many whole instances as fit (10k instances
    // of 8 vertices are 79 executor runs of 1,024 lanes, not 10k runs of 8).
    void shade_vertices(uint32_t instance, uint32_t instances, uint32_t p0, uint32_t p1) {
        if (!whole_instances_) list_vertices(p0, p1);
        const std::vector<uint32_t>& ids = s_.ids;
        const size_t n = ids.size();
        VertexShaderOutputs& all = s_.all;
        all.count = n * instances;
        float* const all_position = at_least(all.position, all.count * 4);
        float* const all_point_size = at_least(all.point_size, all.count);
        uint32_t* const all_varyings = at_least(all.varyings, all.count * size_t(words_));
        const bool project = plan_.vertices_per_primitive >= 2 && plan_.skip != DrawSkip::RasterizerDiscard;
        WindowPosition* const all_window = project ? at_least(s_.window, all.count) : nullptr;
        if (s_.vertex_workers.size() < in_.pool.size()) s_.vertex_workers.resize(in_.pool.size());
        const uint32_t used = in_.vertex_shader.used_attributes();
        const size_t vertex_chunks = (n + kVertexChunk - 1) / kVertexChunk;
        const size_t per_job = n == 0 || n >= kVertexChunk ? 1 : kVertexChunk / n;   // instances
        const size_t instance_groups = (size_t(instances) + per_job - 1) / per_job;
        for_chunks(in_.pool, vertex_chunks * instance_groups, [&](size_t job, unsigned worker) {
            const size_t j = (job / vertex_chunks) * per_job, k = std::min(per_job, size_t(instances) - j);
            const size_t begin = (job % vertex_chunks) * kVertexChunk, per = std::min(kVertexChunk, n - begin);
            const size_t count = k * per;   // k > 1 only when per == n: the lanes are contiguous
            if (in_.budget) in_.budget->charge(count * kVertexWorkUnits);
            VertexWorker& w = s_.vertex_workers[worker];
            w.vertex_ids.resize(count);
            w.instance_ids.resize(count);
            for (size_t i = 0; i < k; ++i) {
                std::copy_n(ids.data() + begin, per, w.vertex_ids.data() + i * per);
                std::fill_n(w.instance_ids.data() + i * per, per, uint32_t(instance + j + i));
            }
            for (int loc = 0; loc < kMaxVertexAttribs; ++loc) {
                if (!(used & (1u << loc))) continue;
                AttributeStream& out = w.attribs[size_t(loc)];
                const VertexAttribPointer& a = in_.vertex_array.attribs[size_t(loc)];
                if (k > 1 && a.enabled && a.divisor == 0) {
                    // A per-vertex array reads the same elements for each of the job's instances:
                    // the first instance's lanes, copied to the others.
                    fetch_attribute(in_.vertex_array, in_.current_attribs[size_t(loc)], loc, w.vertex_ids.data(), 0, per,
                                    w.instance_ids.data(), w.one_instance);
                    out.kind = w.one_instance.kind;
                    for (size_t c = 0; c < 4; ++c) {
                        out.comp[c].resize(count);   // usually the size already: no fill
                        for (size_t i = 0; i < k; ++i) std::copy_n(w.one_instance.comp[c].data(), per, out.comp[c].data() + i * per);
                    }
                } else {
                    fetch_attribute(in_.vertex_array, in_.current_attribs[size_t(loc)], loc, w.vertex_ids.data(), 0,
                                    count, w.instance_ids.data(), out);
                }
            }
            const size_t at = j * n + begin;
            const VertexDestination to{all_position + at * 4, all_point_size + at, all_varyings + at * size_t(words_)};
            in_.vertex_shader.run(w.attribs, count, w.vertex_ids.data(), w.instance_ids.data(), to);
            if (project) Setup(rs_).project_vertices(to.position, count, all_window + at, plan_.simd);
        });
        st_.vertices_shaded += all.count;
    }

    // Primitive assembly, clip, setup and binning, in chunks of primitives on the pool; then the
    // primitives numbered and each tile's list gathered in chunk order. Returns whether a tile pass
    // follows (the draw rasterizes and the batch has primitives).
    bool set_up_and_bin(uint32_t instance, uint32_t instances, uint32_t p0, uint32_t p1) {
        const uint32_t span = p1 - p0;
        const size_t batch_total = size_t(span) * instances;
        const size_t setup_chunks = (batch_total + kSetupChunk - 1) / kSetupChunk;
        if (s_.chunks.size() < setup_chunks) s_.chunks.resize(setup_chunks);
        std::vector<Bins>& chunk_bins = s_.chunk_bins;
        if (chunk_bins.size() < setup_chunks) chunk_bins.resize(setup_chunks);
        const uint32_t inside = range_.end - range_.begin;
        const size_t n = s_.ids.size();
        const int per = plan_.vertices_per_primitive;
        const float* const all_position = s_.all.position.data();
        const WindowPosition* const all_window = s_.window.data();
        for_chunks(in_.pool, setup_chunks, [&](size_t c, unsigned) {
            SetupChunk& chunk = s_.chunks[c];
            chunk.prims.clear();
            Setup setup(rs_);
            const size_t begin = c * kSetupChunk, end = std::min(batch_total, begin + kSetupChunk);
            if (in_.budget) in_.budget->charge((end - begin) * kPrimitiveWorkUnits);
            uint32_t j = uint32_t(begin / span), p = p0 + uint32_t(begin % span);
            // The primitive's number in the draw (modulo 2^32). A chunk's numbers are consecutive:
            // a batch of whole instances holds all of each (p0 = 0, p1 = per_instance_), else one.
            const uint32_t first_number = uint32_t(uint64_t(instance + j) * per_instance_ + p);
            if (per == 3) {
                // Triangles: their vertex slots, a block at a time, then setup.triangles over them.
                constexpr size_t kBlock = 256;
                uint32_t slots[3 * kBlock];
                for (size_t k = begin; k < end;) {
                    const size_t block = std::min(kBlock, end - k);
                    for (size_t m = 0; m < block; ++m, ++p) {
                        if (p == p1) p = p0, ++j;
                        uint32_t* const v = slots + 3 * m;
                        const uint32_t base = uint32_t(j * n);
                        if (call_.mode == gl::TRIANGLES) {   // positions 3p .. 3p + 2, all inside the range
                            const uint32_t at = 3 * p - range_.begin;
                            for (int i = 0; i < 3; ++i)
                                v[i] = base + (call_.indices ? s_.slot_of_position[at + i] : at + i);
                            continue;
                        }
                        primitive_vertices(call_.mode, call_.count, p, v);
                        for (int i = 0; i < 3; ++i) {
                            const uint32_t position = v[i] >= range_.begin ? v[i] - range_.begin : inside;
                            v[i] = base + (call_.indices ? s_.slot_of_position[position] : position);
                        }
                    }
                    setup.triangles(all_position, all_window, slots, block,
                                    first_number + uint32_t(k - begin), chunk.prims, plan_.simd);
                    k += block;
                }
            } else {
                for (size_t k = begin; k < end; ++k, ++p) {
                    if (p == p1) p = p0, ++j;
                    uint32_t v[3];
                    primitive_vertices(call_.mode, call_.count, p, v);
                    const uint32_t base = uint32_t(j * n);
                    for (int i = 0; i < per; ++i) {
                        const uint32_t position = v[i] >= range_.begin ? v[i] - range_.begin : inside;
                        v[i] = base + (call_.indices ? s_.slot_of_position[position] : position);
                    }
                    const uint32_t number = first_number + uint32_t(k - begin);
                    if (per == 2) setup.line(all_position, all_window, v, number, chunk.prims);
                    else setup.point(all_position + 4 * v[0], s_.all.point_size[v[0]], v[0], number, chunk.prims);
                }
            }
            chunk.stats = setup.stats;
            if (!plan_.rasterizes()) return;
            chunk_bins[c].reset(grid_);
            chunk_bins[c].add(chunk.prims.data(), chunk.prims.size(), 0);
        });
        setup_chunks_ = setup_chunks;
        uint64_t emitted = 0;
        for (size_t c = 0; c < setup_chunks; ++c) setup_stats_.add(s_.chunks[c].stats), emitted += s_.chunks[c].stats.emitted;
        if (!plan_.rasterizes() || emitted == 0) return false;
        gather_bins(setup_chunks);
        return true;
    }

    // Numbers the primitives (chunk << shift | position in the chunk) and gathers each tile's list
    // in chunk order. A batch's chunks emit at most 8 * kSetupChunk records each, so the numbers of
    // kDrawBatchPrimitivesMax primitives fit in 32 bits.
    void gather_bins(size_t setup_chunks) {
        PrimitiveTable& prims = s_.prims;
        std::vector<Bins>& chunk_bins = s_.chunk_bins;
        size_t largest = 1;
        for (size_t c = 0; c < setup_chunks; ++c) largest = std::max(largest, s_.chunks[c].prims.size());
        prims.shift = 0;
        while ((size_t(1) << prims.shift) < largest) ++prims.shift;
        prims.mask = uint32_t((uint64_t(1) << prims.shift) - 1);
        prims.chunk.clear();
        std::vector<uint32_t>& index_base = s_.index_base;
        index_base.clear();
        for (size_t c = 0; c < setup_chunks; ++c) {
            prims.chunk.push_back(s_.chunks[c].prims.data());
            index_base.push_back(uint32_t(c << prims.shift));
        }
        bins_ = &chunk_bins[0];   // one chunk: its bins are the batch's
        if (setup_chunks > 1) {
            s_.bins.begin_gather(grid_, chunk_bins.data(), setup_chunks);
            const std::vector<uint32_t>& occupied = s_.bins.occupied();
            in_.pool.parallel_for(occupied.size(), [&](size_t i, unsigned) {
                s_.bins.gather_tile(occupied[i], chunk_bins.data(), setup_chunks, index_base.data());
            });
            bins_ = &s_.bins;
        }
        // Only tiles with work go to the pool (a draw of one small primitive wakes no thread).
        bins_->checkerboard_order(s_.tiles);
    }

    const DrawInputs& in_;
    const DrawCall& call_;
    DrawPlan& plan_;
    DrawStats& st_;
    DrawScratch& s_;
    const RasterState rs_;
    const TileGrid grid_;
    const int words_;
    const uint32_t per_instance_;
    const bool whole_instances_;
    VertexRange range_;
    SetupStats setup_stats_;
    const Bins* bins_ = nullptr;
    TilePass tile_pass_;
    bool several_batches_ = false;
    size_t setup_chunks_ = 0;   // the last batch's
    bool decided_ = false;
    std::optional<DrawRollback> rollback_;
    MemoryReservation copies_memory_;   // rollback_'s bound, charged for the draw's length
};

}  // namespace

DrawPlan draw(const DrawInputs& in, const DrawCall& call, DrawStats& total) {
    // However the draw ends, the scratch it grew is charged to its context.
    struct ChargeScratch {
        const std::shared_ptr<MemoryAccount>& account;
        ~ChargeScratch() { charge_thread_scratch(account); }
    } charge_scratch{in.memory};
    const FragmentOps ops = FragmentOps::from(in);
    DrawPlan plan = plan_draw(in, call, ops);
    DrawStats st;
    st.draws = 1;
    // The draw kinds known before shading (the others: TilePass::prepare).
    if (plan.skip == DrawSkip::NoOutput) st.draws_skipped_no_output = 1;
    if (plan.rasterizes()) {
        st.draws_plain_write = plan.plain_write;
        st.draws_early_depth = plan.early_tests();
        st.draws_late_tests = plan.late_tests();
        st.draws_per_lane_color = plan.writes_color && plan.color_kernels != Path::Taken;
    }
    if (plan.blend_lab) in.sink->begin_draw(in.state, *in.target.default_framebuffer());
    in.vertex_shader.prepare(in.tuning);   // the executors' SIMD level and sampler path
    Batches batches(in, call, ops, plan, st);
    // A draw that stops part-way (its work budget ran out, Ctrl-C, no memory) after writing pixels
    // leaves every pixel as it was: the tiles it wrote are put back (pipeline/draw_rollback.h).
    try {
        batches.run_all();
    } catch (const std::bad_alloc&) {
        batches.roll_back();
        if (in.budget) in.budget->defer_stops(false);
        throw DrawOutOfMemory("an allocation of its working memory failed (std::bad_alloc)",
                              batches.keeps_copies() || !batches.began_writing());
    } catch (...) {
        batches.roll_back();
        if (in.budget) in.budget->defer_stops(false);
        throw;
    }
    // A stop deferred to the end of the draw (Ctrl-C): the bindings raise it now; the draw is whole.
    if (in.budget) in.budget->defer_stops(false);
    st.draws_with_rollback = batches.keeps_copies();
    batches.add_counters();
    total.add(st);
    return plan;
}

}  // namespace softgl
