#include "softgl/pipeline/draw.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include "softgl/pipeline/assemble.h"
#include "softgl/pipeline/bin.h"
#include "softgl/pipeline/blend.h"
#include "softgl/pipeline/depth_stencil.h"
#include "softgl/pipeline/raster.h"
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
    samples_written += o.samples_written; samples_blended += o.samples_blended;
    draws_skipped_no_output += o.draws_skipped_no_output; draws_early_depth += o.draws_early_depth;
    draws_plain_write += o.draws_plain_write; seconds_vertex += o.seconds_vertex;
    seconds_setup += o.seconds_setup; seconds_fragment += o.seconds_fragment;
}

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

float as_float(uint32_t bits) {
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}
uint32_t as_bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
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
    return r;
}

// Per-worker scratch, reused across primitives and draws.
struct Scratch {
    std::vector<Quad> quads;
    std::vector<uint16_t> masks;      // surviving sample mask per lane
    FragmentBatch batch;
    FragmentResults results;
    RasterStats raster;
    DrawStats stats;
};

}  // namespace

void draw(const DrawInputs& in, const DrawCall& call, DrawStats& total) {
    DrawStats st;
    st.draws = 1;
    const State& state = in.state;
    RenderTarget& fb = in.target;
    const VertexShader& vs = in.vertex_shader;
    const FragmentShader& fs = in.fragment_shader;
    const VaryingLayout& layout = vs.varying_layout();
    const int words = layout.words;

    // ---- vertex stage: shade each distinct vertex once per instance ----
    auto t0 = Clock::now();
    std::vector<uint32_t> ids;                  // distinct vertex ids, in first-use order
    std::vector<uint32_t> slot_of_position(call.count);
    if (call.indices) {
        std::unordered_map<uint32_t, uint32_t> slot;
        slot.reserve(call.count * 2);
        for (uint32_t k = 0; k < call.count; ++k) {
            auto [it, added] = slot.emplace(call.indices[k], uint32_t(ids.size()));
            if (added) ids.push_back(call.indices[k]);
            slot_of_position[k] = it->second;
        }
    } else {
        ids.resize(call.count);
        for (uint32_t k = 0; k < call.count; ++k) ids[k] = call.first + k, slot_of_position[k] = k;
    }
    const size_t n = ids.size();
    std::array<AttributeStream, kMaxVertexAttribs> attribs;
    VertexShaderOutputs shaded, all;
    all.count = n * call.instance_count;
    all.position.reserve(all.count * 4);
    all.point_size.reserve(all.count);
    all.varyings.reserve(all.count * size_t(words));
    const uint32_t used = vs.used_attributes();
    for (uint32_t instance = 0; instance < call.instance_count; ++instance) {
        for (int loc = 0; loc < kMaxVertexAttribs; ++loc)
            if (used & (1u << loc))
                fetch_attribute(in.vertex_array, in.current_attribs[size_t(loc)], loc, ids.data(), 0, n,
                                instance, attribs[size_t(loc)]);
        vs.run(attribs, n, ids.data(), instance, shaded);
        all.position.insert(all.position.end(), shaded.position.begin(), shaded.position.end());
        all.point_size.insert(all.point_size.end(), shaded.point_size.begin(), shaded.point_size.end());
        all.varyings.insert(all.varyings.end(), shaded.varyings.begin(), shaded.varyings.end());
    }
    st.vertices_shaded = all.count;
    st.seconds_vertex = since(t0);

    // ES 3.0 §2.15: with RASTERIZER_DISCARD, primitives are dropped right after the vertex stage.
    if (state.rasterizer_discard) {
        total.add(st);
        return;
    }

    // ---- primitive assembly, clip and setup (serial, in primitive order) ----
    t0 = Clock::now();
    const RasterState rs = raster_state(state, fb);
    Setup setup(rs);
    std::vector<PrimitiveSetup> prims;
    std::vector<uint32_t> assembled;
    assemble(call.mode, call.count, assembled);
    const int per = vertices_per_primitive(call.mode);
    const size_t prims_per_instance = assembled.size() / size_t(per);
    uint32_t number = 0;
    for (uint32_t instance = 0; instance < call.instance_count; ++instance) {
        const uint32_t base = uint32_t(instance * n);
        for (size_t p = 0; p < prims_per_instance; ++p, ++number) {
            uint32_t v[3];
            for (int k = 0; k < per; ++k) v[k] = base + slot_of_position[assembled[p * size_t(per) + size_t(k)]];
            const float* pos = all.position.data();
            if (per == 3) setup.triangle(pos + 4 * v[0], pos + 4 * v[1], pos + 4 * v[2], v[0], v[1], v[2], number, prims);
            else if (per == 2) setup.line(pos + 4 * v[0], pos + 4 * v[1], v[0], v[1], number, prims);
            else setup.point(pos + 4 * v[0], all.point_size[v[0]], v[0], number, prims);
        }
    }
    st.primitives = setup.stats.primitives;
    st.primitives_culled = setup.stats.culled;
    st.primitives_clipped = setup.stats.clipped;
    st.primitives_outside = setup.stats.outside;
    st.primitives_invalid = setup.stats.invalid;
    st.primitives_zero_area = setup.stats.zero_area;
    st.primitives_rasterized = setup.stats.emitted;

    // ---- what the per-fragment work needs (DESIGN §4) ----
    const auto& config = fb.config();
    const BlendOp blend = BlendOp::from_state(state, config.alpha);
    const DepthStencilOp ds = DepthStencilOp::from_state(state, config.depth, config.stencil);
    const bool writes_color = blend.write[0] || blend.write[1] || blend.write[2] || blend.write[3];
    const bool writes_depth_stencil = (ds.depth_test && ds.depth_write) || ds.stencil_test;
    if (!writes_color && !writes_depth_stencil) {
        st.draws_skipped_no_output = 1;   // nothing can change: skip rasterisation and shading
        st.seconds_setup = since(t0);
        total.add(st);
        return;
    }
    const bool plain_write = blend.is_plain_write();
    if (plain_write) st.draws_plain_write = 1;
    const bool early = !fs.may_discard() && !fs.writes_depth() && !state.sample_alpha_to_coverage;
    if (early && (ds.depth_test || ds.stencil_test)) st.draws_early_depth = 1;

    const TileGrid grid(fb.width(), fb.height());
    Bins bins;
    bins.reset(grid);
    bins.add(prims);
    st.seconds_setup = since(t0);

    // ---- per tile on the pool: raster, tests, shading, blending ----
    t0 = Clock::now();
    const SamplePattern& pattern = sample_pattern(config.samples);
    const int S = config.samples;
    std::vector<Scratch> scratch(in.pool.size());
    fs.prepare(in.pool.size());
    in.pool.parallel_for(grid.count(), [&](size_t tile, unsigned worker) {
        const std::vector<uint32_t>& list = bins.tile(tile);
        if (list.empty()) return;
        Scratch& w = scratch[worker];
        w.stats.tiles_touched++;
        const TileRect rect = grid.rect(tile);
        for (uint32_t k : list) {
            const PrimitiveSetup& p = prims[k];
            w.quads.clear();
            rasterize(p, rect, pattern, w.quads, w.raster);
            if (w.quads.empty()) continue;

            // Early depth/stencil (legal when the shader cannot discard or write depth).
            const size_t lanes = w.quads.size() * 4;
            w.masks.assign(lanes, 0);
            size_t kept = 0;
            for (size_t q = 0; q < w.quads.size(); ++q) {
                const Quad& quad = w.quads[q];
                uint16_t any = 0;
                for (int j = 0; j < 4; ++j) {
                    uint16_t mask = uint16_t(quad_pixel_mask(quad, j));
                    if (mask && early && (ds.depth_test || ds.stencil_test)) {
                        const int32_t x = quad.x + (j & 1), y = quad.y + (j >> 1);
                        uint32_t* depth = fb.depth_samples(x, y);
                        uint8_t* stencil = fb.stencil_samples(x, y);
                        for (int s = 0; s < S; ++s) {
                            if (!(mask & (1u << s))) continue;
                            const uint32_t z = fb.depth_word(
                                p.depth_at(int64_t(x) * kSubPixel + pattern.x[s], int64_t(y) * kSubPixel + pattern.y[s]));
                            if (!depth_stencil_test(ds, p.front_facing, z, depth ? depth + s : nullptr,
                                                    stencil ? stencil + s : nullptr)) {
                                mask = uint16_t(mask & ~(1u << s));
                                w.stats.fragments_killed_early++;
                            }
                        }
                    }
                    w.masks[q * 4 + size_t(j)] = mask;
                    any |= mask;
                }
                if (any) w.quads[kept++] = quad, std::copy_n(&w.masks[q * 4], 4, &w.masks[(kept - 1) * 4]);
            }
            w.quads.resize(kept);
            if (kept == 0) continue;
            w.stats.quads += kept;

            // Build the fragment batch: interpolated varyings and built-ins per lane.
            FragmentBatch& b = w.batch;
            const size_t L = kept * 4;
            b.lanes = L;
            b.varyings.resize(size_t(words) * L);
            b.frag_coord.resize(4 * L);
            b.front_facing.assign(L, p.front_facing ? 1 : 0);
            b.point_coord.resize(2 * L);
            b.covered.resize(L);
            const uint32_t provoking = p.kind == PrimitiveKind::Triangle ? p.vertex[2]
                                     : p.kind == PrimitiveKind::Line ? p.vertex[1] : p.vertex[0];
            const int interpolated = p.kind == PrimitiveKind::Triangle ? 3 : p.kind == PrimitiveKind::Line ? 2 : 0;
            for (size_t lane = 0; lane < L; ++lane) {
                const Quad& quad = w.quads[lane / 4];
                const int j = int(lane % 4);
                const int32_t x = quad.x + (j & 1), y = quad.y + (j >> 1);
                const int64_t X = int64_t(x) * kSubPixel + kSubPixel / 2, Y = int64_t(y) * kSubPixel + kSubPixel / 2;
                double weights[3] = {0, 0, 0};
                if (interpolated) p.weights_at(X, Y, weights);
                for (int word = 0; word < words; ++word) {
                    uint32_t value;
                    if (interpolated && !layout.flat[size_t(word)]) {
                        double v = 0;
                        for (int c = 0; c < interpolated; ++c)
                            v += weights[c] * double(as_float(all.varyings[size_t(p.vertex[c]) * size_t(words) + size_t(word)]));
                        value = as_bits(float(v));
                    } else {
                        value = all.varyings[size_t(provoking) * size_t(words) + size_t(word)];
                    }
                    b.varyings[size_t(word) * L + lane] = value;
                }
                b.frag_coord[lane] = float(x) + 0.5f;
                b.frag_coord[L + lane] = float(y) + 0.5f;
                b.frag_coord[2 * L + lane] = float(p.depth_at(X, Y));
                b.frag_coord[3 * L + lane] = float(p.eval(p.inv_w, X, Y));
                float pc[2] = {0, 0};
                if (p.kind == PrimitiveKind::Point) p.point_coord(x, y, pc);
                b.point_coord[lane] = pc[0];
                b.point_coord[L + lane] = pc[1];
                b.covered[lane] = w.masks[lane] ? 1 : 0;
            }
            fs.run(b, w.results, worker);
            w.stats.fragments_shaded += L;

            // Late tests, blending and the write, per covered sample.
            const FragmentResults& r = w.results;
            for (size_t lane = 0; lane < L; ++lane) {
                uint16_t mask = w.masks[lane];
                if (!mask) continue;
                if (!r.killed.empty() && r.killed[lane]) {
                    w.stats.fragments_discarded++;
                    continue;
                }
                const Quad& quad = w.quads[lane / 4];
                const int j = int(lane % 4);
                const int32_t x = quad.x + (j & 1), y = quad.y + (j >> 1);
                if (!early && (ds.depth_test || ds.stencil_test)) {
                    uint32_t* depth = fb.depth_samples(x, y);
                    uint8_t* stencil = fb.stencil_samples(x, y);
                    const bool shader_depth = fs.writes_depth();
                    for (int s = 0; s < S; ++s) {
                        if (!(mask & (1u << s))) continue;
                        const double zf = shader_depth ? double(clamp01(r.depth[lane]))
                                                       : p.depth_at(int64_t(x) * kSubPixel + pattern.x[s],
                                                                    int64_t(y) * kSubPixel + pattern.y[s]);
                        if (!depth_stencil_test(ds, p.front_facing, fb.depth_word(zf),
                                                depth ? depth + s : nullptr, stencil ? stencil + s : nullptr)) {
                            mask = uint16_t(mask & ~(1u << s));
                            w.stats.fragments_killed_late++;
                        }
                    }
                }
                if (!writes_color || !mask) continue;
                const float color[4] = {r.color[lane], r.color[L + lane], r.color[2 * L + lane], r.color[3 * L + lane]};
                for (int s = 0; s < S; ++s) {
                    if (!(mask & (1u << s))) continue;
                    fb.write_color(blend, color, x, y, s);
                    w.stats.samples_written++;
                    if (!plain_write) w.stats.samples_blended++;
                }
            }
        }
    });
    for (const Scratch& w : scratch) {
        st.add(w.stats);
        st.blocks_accepted_whole += w.raster.blocks_accepted;
    }
    st.seconds_fragment = since(t0);
    total.add(st);
}

}  // namespace softgl
