#include "softgl/pipeline/glsl_stages.h"

#include <algorithm>
#include <cstring>
#include <type_traits>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace softgl {

using glsl::Scalar;
using glsl::SlotKind;

void IncompleteTextureSampler::sample(const glsl::TextureQuery& q) {
    for (int lane = 0; lane < q.lane_count; ++lane) {
        for (int c = 0; c < 4; ++c) {
            if (!q.out[c]) continue;
            Scalar v;
            if (q.kind == glsl::TextureKind::Size) v.i = 0;
            else if (q.result == glsl::BaseType::Float) v.f = c == 3 ? 1.0f : 0.0f;
            else v.i = c == 3 ? 1 : 0;
            q.out[c][lane] = v;
        }
    }
}

namespace {

// out[v * N + k] = source[k][v] for the `count` vertices: components to vertices, N known at
// compile time so each vertex's words are stored together from registers.
template <size_t N, class Out>
void interleave(const Scalar* const* source, size_t count, Out* out) {
    const Scalar* s[N];
    for (size_t k = 0; k < N; ++k) s[k] = source[k];
    for (size_t v = 0; v < count; ++v)
        for (size_t k = 0; k < N; ++k) {
            if constexpr (std::is_same_v<Out, float>) out[v * N + k] = s[k][v].f;
            else out[v * N + k] = s[k][v].u;
        }
}

void interleave(const Scalar* const* source, size_t n, size_t count, uint32_t* out) {
    switch (n) {
        case 0: return;
        case 1: return interleave<1>(source, count, out);
        case 2: return interleave<2>(source, count, out);
        case 3: return interleave<3>(source, count, out);
        case 4: return interleave<4>(source, count, out);
        default:
            for (size_t v = 0; v < count; ++v)
                for (size_t k = 0; k < n; ++k) out[v * n + k] = source[k][v].u;
    }
}

}  // namespace

GlslVertexShader::GlslVertexShader(std::shared_ptr<const glsl::LinkedProgram> program,
                                   const std::vector<int>& input_location, const std::vector<int>& input_component)
    : program_(std::move(program)), input_location_(input_location), input_component_(input_component) {
    for (int loc : input_location_)
        if (loc >= 0 && loc < kMaxVertexAttribs) used_ |= 1u << loc;
    for (const glsl::Slot& s : program_->vertex.inputs)
        input_builtin_.push_back(s.name == "gl_VertexID" ? Builtin::VertexId
                                 : s.name == "gl_InstanceID" ? Builtin::InstanceId : Builtin::None);
    const auto& outputs = program_->vertex.outputs;
    output_word_.assign(outputs.size(), -1);
    // The executor writes every lane of an output whose register the program writes (glsl/
    // executor.h, StageRun::outputs); the others are zeroed per run.
    unwritten_.assign(outputs.size(), 1);
    for (const glsl::Instruction& i : program_->vertex.code)
        glsl::for_each_write(program_->vertex, i, [&](glsl::Reg r) {
            for (size_t k = 0; k < outputs.size(); ++k)
                if (outputs[k].reg == r) unwritten_[k] = 0;
        });
    for (size_t i = 0; i < outputs.size(); ++i) {
        if (outputs[i].name == "gl_Position") position_slot_[outputs[i].component] = int(i);
        if (outputs[i].name == "gl_PointSize") point_size_slot_ = int(i);
    }
    // One word per varying component, in the program's varying order.
    for (const auto& v : program_->reflection.varyings) {
        for (int c = 0; c < v.components; ++c) {
            const int word = layout_.words++;
            if (v.vertex_slot >= 0) output_word_[size_t(v.vertex_slot + c)] = word;
            const auto base = v.vertex_slot >= 0 ? outputs[size_t(v.vertex_slot + c)].base : glsl::BaseType::Float;
            layout_.flat.push_back(v.interpolation == glsl::Interpolation::Flat || base != glsl::BaseType::Float);
            layout_.read_by_fragment.push_back(v.fragment_slot >= 0);
        }
    }
}

void GlslVertexShader::prepare(const Tuning& tuning) const {
    simd_ = tuning.simd;
    sampler_path_ = tuning.sampler_path;
    hoist_ = tuning.hoist_uniform_values;
}

uint64_t GlslVertexShader::take_fast_texture_queries() const {
    std::lock_guard<std::mutex> lock(runs_mutex_);
    uint64_t n = 0;
    for (const auto& r : idle_runs_) n += std::exchange(r->fast_texture_queries, 0);
    return n;
}

void GlslVertexShader::run(const std::array<AttributeStream, kMaxVertexAttribs>& attribs, size_t count,
                           const uint32_t* vertex_ids, const uint32_t* instance_ids, const VertexDestination& out) const {
    const glsl::IrProgram& ir = program_->vertex;
    std::unique_ptr<Run> borrowed;
    {
        std::lock_guard<std::mutex> lock(runs_mutex_);
        if (!idle_runs_.empty()) borrowed = std::move(idle_runs_.back()), idle_runs_.pop_back();
    }
    if (!borrowed) borrowed = std::make_unique<Run>(Run{std::make_unique<glsl::Executor>(ir, 128, hoist_), {}, {}, {}, {}, {}, {}, {}});
    Run& r = *borrowed;
    if (r.executor->hoists() != hoist_) r.executor = std::make_unique<glsl::Executor>(ir, 128, hoist_);
    r.executor->set_simd_level(simd_);   // executors outlive draws; the level is the draw's
    // gl_VertexID and gl_InstanceID read the caller's arrays (32-bit words, as attribute streams).
    const Scalar* ids = reinterpret_cast<const Scalar*>(vertex_ids);
    const Scalar* instances = reinterpret_cast<const Scalar*>(instance_ids);
    if (!ids) {
        r.ids.resize(count);
        for (size_t v = 0; v < count; ++v) r.ids[v].u = uint32_t(v);
        ids = r.ids.data();
    }
    if (!instances) {
        r.instances.assign(count, Scalar{});
        instances = r.instances.data();
    }
    r.inputs.assign(ir.inputs.size(), nullptr);
    for (size_t i = 0; i < ir.inputs.size(); ++i) {
        if (input_builtin_[i] == Builtin::VertexId) r.inputs[i] = ids;
        else if (input_builtin_[i] == Builtin::InstanceId) r.inputs[i] = instances;
        else if (input_location_[i] >= 0 && input_location_[i] < kMaxVertexAttribs) {
            const auto& stream = attribs[size_t(input_location_[i])].comp[size_t(input_component_[i])];
            r.inputs[i] = reinterpret_cast<const Scalar*>(stream.data());
        }
    }
    // Output i at results[i * count ..], zero where the shader does not write it (the rest is
    // written by the run: no fill; the array only grows). gl_PointSize goes straight to `out`.
    if (r.results.size() < ir.outputs.size() * count) r.results.resize(ir.outputs.size() * count);
    r.outputs.resize(ir.outputs.size());
    for (size_t i = 0; i < r.outputs.size(); ++i) {
        r.outputs[i] = int(i) == point_size_slot_ ? reinterpret_cast<Scalar*>(out.point_size) : r.results.data() + i * count;
        if (unwritten_[i]) std::fill_n(r.outputs[i], count, Scalar{});
    }
    glsl::StageRun run;
    run.lane_count = int(count);
    run.inputs = r.inputs.data();
    run.outputs = r.outputs.data();
    run.uniforms = uniforms_;
    run.sampler = textures_ ? textures_ : &sampler_;
    run.sampler_path = sampler_path_;
    run.fast_texture_queries = &r.fast_texture_queries;
    run.budget = budget_;
    r.executor->run(run);
    const Scalar* const* const results = r.outputs.data();

    // The results from components to vertices: one pass over the vertices per array, every
    // component of a vertex written together (a component the shader leaves unwritten reads zeros).
    r.zeros.resize(count);
    const Scalar* position[4];
    for (int c = 0; c < 4; ++c) position[c] = position_slot_[c] >= 0 ? results[size_t(position_slot_[c])] : r.zeros.data();
    interleave<4>(position, count, out.position);
    if (point_size_slot_ < 0) std::fill_n(out.point_size, count, 1.0f);
    const size_t words = size_t(layout_.words);
    r.word_source.assign(words, r.zeros.data());
    for (size_t i = 0; i < output_word_.size(); ++i)
        if (output_word_[i] >= 0) r.word_source[size_t(output_word_[i])] = results[i];
    interleave(r.word_source.data(), words, count, out.varyings);
    std::lock_guard<std::mutex> lock(runs_mutex_);
    idle_runs_.push_back(std::move(borrowed));
}

GlslFragmentShader::GlslFragmentShader(std::shared_ptr<const glsl::LinkedProgram> program, const VaryingLayout&)
    : program_(std::move(program)) {
    const glsl::IrProgram& ir = program_->fragment;
    instructions_bound_ = glsl::instructions_bound(ir);
    input_word_.assign(ir.inputs.size(), -1);
    input_builtin_.assign(ir.inputs.size(), -1);
    int word = 0;
    for (const auto& v : program_->reflection.varyings) {
        for (int c = 0; c < v.components; ++c, ++word)
            if (v.fragment_slot >= 0) input_word_[size_t(v.fragment_slot + c)] = word;
    }
    for (size_t i = 0; i < ir.inputs.size(); ++i) {
        const glsl::Slot& s = ir.inputs[i];
        if (s.name == "gl_FragCoord") input_builtin_[i] = s.component;
        else if (s.name == "gl_FrontFacing") input_builtin_[i] = 4;
        else if (s.name == "gl_PointCoord") input_builtin_[i] = 5 + s.component;
        // FragmentBuiltin bits; the IR declares the built-ins whether or not the shader reads them.
        const glsl::ShaderUsage& usage = program_->reflection.fragment_usage;
        const bool read = input_builtin_[i] < 4 ? usage.reads_frag_coord
                        : input_builtin_[i] == 4 ? usage.reads_front_facing : usage.reads_point_coord;
        if (input_builtin_[i] >= 0 && read) builtins_read_ |= 1u << input_builtin_[i];
    }
    // docs/architecture.md, "Fast paths": a shader whose outputs depend only on uniforms gives every lane the same values
    // (lanes are independent; derivatives of uniform values are the same in every lane), so one
    // quad is shaded and its values are copied to the others.
    uniform_only_ = program_->reflection.fragment_depends_only_on_uniforms &&
                    !program_->reflection.fragment_usage.may_discard;
    // Derivatives and implicit-LOD lookups, as the optimised IR has them (the executor's test):
    // without them a lane's values are its own, and no helper pixel needs shading.
    quad_neighbours_ = glsl::reads_quad_neighbours(ir);
    derivatives_ = glsl::takes_derivatives(ir);
    implicit_lod_dims_ = glsl::implicit_lod_dims(ir);
    // A primitive whose varyings are the same at every fragment gives each the same results when
    // lanes are independent and nothing else per pixel is read (TilePass's flat primitives).
    flat_ = !quad_neighbours_ && builtins_read_ == 0 && !program_->reflection.fragment_usage.may_discard &&
            !program_->reflection.fragment_usage.writes_frag_depth;
    // Colour output o: whichever of gl_FragColor (o = 0), gl_FragData[o] or the `out` at location
    // o (arrays take consecutive locations, ES 3.00 §4.3.8.2) the shader really writes (the IR
    // declares both ES 1.00 outputs; reflection lists the active one).
    color_slot_.assign(4 * size_t(kMaxFragmentOutputs), -1);
    int highest = 0;
    for (size_t i = 0; i < ir.outputs.size(); ++i) {
        const glsl::Slot& s = ir.outputs[i];
        if (s.name == "gl_FragDepth" || s.name == "gl_FragDepthEXT") {
            if (writes_depth()) depth_slot_ = int(i);   // declared by the IR even when not written
            continue;
        }
        if (s.kind != SlotKind::FragmentOutput || s.component > 3) continue;
        for (const auto& o : program_->reflection.outputs) {
            if (o.name != s.name || !o.active) continue;
            const int location = (o.location < 0 ? 0 : o.location) + s.element;
            if (location < 0 || location >= kMaxFragmentOutputs) continue;
            color_slot_[size_t(4 * location + s.component)] = int(i);
            highest = std::max(highest, location);
        }
    }
    // EXT_draw_buffers: gl_FragColor is written to every draw buffer when the shader enables
    // the extension (WEBGL_draw_buffers); the results then carry it as every output.
    broadcast_ = program_->reflection.fragment_usage.frag_color_broadcast;
    outputs_ = broadcast_ ? kMaxFragmentOutputs : highest + 1;
    copies_only_ = find_copies();
    if (!copies_only_ && !find_texture_copy()) texture_copy_ = TextureCopy{};
}

// docs/architecture.md, "Fast paths" (texture copies): main is a LoadUniform of the sampler, one
// Texture (Sample, implicit LOD, 2D, float, no comparison, s and t two varying inputs) and Movs of
// its four results to the four components of the one colour output. The executor runs this as
// one query with every lane active (no control flow) whose results the Movs copy bit for bit (or
// the lookup writes the outputs itself: fuse_texture_moves); run_texture_copy makes that query.
bool GlslFragmentShader::find_texture_copy() {
    const glsl::IrProgram& ir = program_->fragment;
    if (may_discard() || writes_depth() || broadcast_ || outputs_ != 1) return false;
    const size_t R = ir.register_count;
    const glsl::Instruction* load = nullptr;
    const glsl::Instruction* lookup = nullptr;
    std::vector<glsl::Reg> moved(R, glsl::kNoReg);   // per output register: the register moved to it
    for (const glsl::Instruction& i : ir.code) {
        switch (i.op) {
            case glsl::Op::FunctionBegin: case glsl::Op::FunctionEnd: break;
            case glsl::Op::LoadUniform:
                if (load || lookup) return false;
                load = &i;
                break;
            case glsl::Op::Texture:
                if (lookup) return false;
                lookup = &i;
                break;
            case glsl::Op::Mov:
                if (!lookup || i.dst >= R || moved[i.dst] != glsl::kNoReg) return false;
                moved[i.dst] = i.a;
                break;
            default: return false;
        }
    }
    if (!load || !lookup || lookup->texture < 0 || size_t(lookup->texture) >= ir.textures.size()) return false;
    const glsl::TextureOperands& t = ir.textures[size_t(lookup->texture)];
    if (t.kind != glsl::TextureKind::Sample || t.dim != glsl::SamplerDim::Tex2D || t.shadow ||
        t.result != glsl::BaseType::Float || t.lod_mode != glsl::TextureLod::Implicit || t.unit != load->dst ||
        t.coord[2] != glsl::kNoReg || t.coord[3] != glsl::kNoReg || t.compare != glsl::kNoReg || t.lod != glsl::kNoReg)
        return false;
    // s and t: varying inputs no instruction writes (the Movs write only output registers).
    int word[2] = {-1, -1};
    for (int k = 0; k < 2; ++k) {
        for (size_t i = 0; i < ir.inputs.size(); ++i)
            if (ir.inputs[i].reg == t.coord[k]) word[k] = input_word_[i];
        if (word[k] < 0 || t.coord[k] >= R || moved[t.coord[k]] != glsl::kNoReg) return false;
    }
    // Output component c is result c; nothing else is moved anywhere.
    size_t moves = 0;
    for (glsl::Reg r = 0; r < R; ++r) moves += moved[r] != glsl::kNoReg;
    if (moves != 4) return false;
    for (int c = 0; c < 4; ++c) {
        if (color_slot_[size_t(c)] < 0 || t.dst[c] == glsl::kNoReg) return false;
        const glsl::Reg out = ir.outputs[size_t(color_slot_[size_t(c)])].reg;
        if (out >= R || moved[out] != t.dst[c]) return false;
    }
    texture_copy_.texture = lookup->texture;
    texture_copy_.unit_uniform = load->imm[0];
    texture_copy_.word[0] = word[0], texture_copy_.word[1] = word[1];
    return true;
}

glsl::TextureQuery GlslFragmentShader::texture_copy_query(const FragmentBatch& b, unsigned worker) const {
    Worker& w = workers_[worker];
    const glsl::TextureOperands& t = program_->fragment.textures[size_t(texture_copy_.texture)];
    const size_t L = b.lanes, S = b.stride();
    if (w.active.size() < L) w.active.resize(L, ~0u);   // only ever all ones
    const Scalar unit = uniforms_ ? uniforms_[texture_copy_.unit_uniform] : Scalar{};
    if (w.units.size() < L || w.units.empty() || w.units[0].u != unit.u) w.units.assign(std::max(L, w.units.size()), unit);
    glsl::TextureQuery q;
    q.kind = glsl::TextureKind::Sample;
    q.dim = t.dim;
    q.shadow = false;
    q.result = glsl::BaseType::Float;
    q.lod_mode = glsl::TextureLod::Implicit;
    q.lane_count = int(L);
    q.active = w.active.data();
    q.unit = w.units.data();
    q.uniform_unit = true;
    for (int k = 0; k < 2; ++k) q.coord[k] = reinterpret_cast<const Scalar*>(&b.varyings[size_t(texture_copy_.word[k]) * S]);
    for (int k = 0; k < 3; ++k) q.offset[k] = t.offset[k];
    q.path = sampler_path_;
    q.simd = simd_;
    q.fast_queries = &w.fast_texture_queries;
    return q;
}

// Texel words: the draw's textures are bound (set_sampler) and the uniforms set before prepare.
bool GlslFragmentShader::gives_texel_words() const {
    if (texture_copy_.texture < 0 || !texture_copies_ || !textures_ || workers_.empty()) return false;
    FragmentBatch one;
    one.lanes = 1;
    one.varyings.assign(size_t(std::max(texture_copy_.word[0], texture_copy_.word[1]) + 1), 0);
    return textures_->gives_words(texture_copy_query(one, 0), linear_words_);
}

void GlslFragmentShader::run_words(const FragmentBatch& b, uint32_t* words, unsigned worker) const {
    textures_->sample_words(texture_copy_query(b, worker), words);
}

// The query Executor::texture makes for the program find_texture_copy recognised, with the
// executor's operands: every lane active, the sampler uniform's unit in every lane, the implicit
// derivatives (differences inside each quad, when the sampler says the LOD matters), the draw's
// sampler path and SIMD level; the results go straight to the colour output.
void GlslFragmentShader::run_texture_copy(const FragmentBatch& b, FragmentResults& out, unsigned worker) const {
    Worker& w = workers_[worker];
    const size_t L = b.lanes;
    glsl::TextureQuery q = texture_copy_query(b, worker);
    for (int c = 0; c < 4; ++c) q.out[c] = reinterpret_cast<Scalar*>(&out.color[size_t(c) * L]);
    glsl::TextureSampler* const sampler = textures_ ? textures_ : &w.sampler;
    if (sampler->lod_matters(q)) {
        // As Executor::texture: per quad, dx = (p1 - p0, p1 - p0, p3 - p2, p3 - p2) and
        // dy = (p2 - p0, p3 - p1, p2 - p0, p3 - p1); lanes past the last whole quad 0.
        if (w.derivatives.size() < 4 * L) w.derivatives.resize(4 * L);
        const size_t quads = L / 4;
        for (int k = 0; k < 2; ++k) {
            Scalar* const dx = w.derivatives.data() + size_t(2 * k) * L;
            Scalar* const dy = dx + L;
            const Scalar* const v = q.coord[k];
            size_t qd = 0;
#if defined(__SSE2__)
            for (; qd < quads; ++qd) {   // the same subtractions of the same lanes, a quad at a time
                const __m128 p = _mm_loadu_ps(&v[4 * qd].f);
                _mm_storeu_ps(&dx[4 * qd].f, _mm_sub_ps(_mm_shuffle_ps(p, p, _MM_SHUFFLE(3, 3, 1, 1)),
                                                      _mm_shuffle_ps(p, p, _MM_SHUFFLE(2, 2, 0, 0))));
                _mm_storeu_ps(&dy[4 * qd].f, _mm_sub_ps(_mm_shuffle_ps(p, p, _MM_SHUFFLE(3, 2, 3, 2)),
                                                      _mm_shuffle_ps(p, p, _MM_SHUFFLE(1, 0, 1, 0))));
            }
#endif
            for (; qd < quads; ++qd) {
                const Scalar* p = v + 4 * qd;
                const float top = p[1].f - p[0].f, bottom = p[3].f - p[2].f, left = p[2].f - p[0].f, right = p[3].f - p[1].f;
                dx[4 * qd].f = top, dx[4 * qd + 1].f = top, dx[4 * qd + 2].f = bottom, dx[4 * qd + 3].f = bottom;
                dy[4 * qd].f = left, dy[4 * qd + 1].f = right, dy[4 * qd + 2].f = left, dy[4 * qd + 3].f = right;
            }
            for (size_t l = quads * 4; l < L; ++l) dx[l].f = 0.0f, dy[l].f = 0.0f;
            q.ddx[k] = dx;
            q.ddy[k] = dy;
        }
    }
    sampler->sample(q);
}

// docs/architecture.md, "Fast paths": a program that is nothing but Movs (and main's function markers) from varyings or
// constants to colour outputs gives every lane its sources' bits (a Mov copies bits, -0.0 and
// NaN payloads included; with no control flow every lane is active), so the pipeline may copy
// them from the batch instead of calling run() (pipeline/tile_pass, the shade step).
bool GlslFragmentShader::find_copies() {
    const glsl::IrProgram& ir = program_->fragment;
    if (may_discard() || writes_depth()) return false;
    const size_t R = ir.register_count;
    std::vector<glsl::Reg> source(R, glsl::kNoReg);   // per register: the Mov that writes it (once)
    for (const glsl::Instruction& i : ir.code) {
        if (i.op == glsl::Op::FunctionBegin || i.op == glsl::Op::FunctionEnd) continue;
        if (i.op != glsl::Op::Mov || i.dst >= R || i.a >= R || source[i.dst] != glsl::kNoReg) return false;
        source[i.dst] = i.a;
    }
    // A source must be a varying's register or a constant's, written by no Mov.
    std::vector<int> word(R, -1), uses(R, 0);
    std::vector<uint8_t> constant(R, 0);
    std::vector<uint32_t> bits(R, 0);
    for (size_t k = 0; k < ir.inputs.size(); ++k)
        if (ir.inputs[k].reg < R) ++uses[ir.inputs[k].reg], word[ir.inputs[k].reg] = input_word_[k];
    for (const glsl::ConstantRegister& c : ir.constants)
        if (c.reg < R) constant[c.reg] = 1, bits[c.reg] = c.value.u;
    const size_t written = broadcast_ ? 1 : size_t(outputs_);   // broadcast: output 0 everywhere
    copies_.outputs = outputs_;
    for (size_t k = 0; k < 4 * written; ++k) {
        copies_.word[k] = -1, copies_.bits[k] = 0;   // never written: run() gives 0
        if (color_slot_[k] < 0) continue;
        const glsl::Reg out = ir.outputs[size_t(color_slot_[k])].reg;
        if (out >= R || source[out] == glsl::kNoReg) return false;
        const glsl::Reg from = source[out];
        if (source[from] != glsl::kNoReg) return false;
        if (constant[from] && uses[from] == 0) copies_.bits[k] = bits[from];
        else if (!constant[from] && uses[from] == 1 && word[from] >= 0) copies_.word[k] = word[from];
        else return false;
    }
    for (size_t k = 4 * written; k < 4 * size_t(outputs_); ++k)
        copies_.word[k] = copies_.word[k % 4], copies_.bits[k] = copies_.bits[k % 4];
    return true;
}

const FragmentCopies* GlslFragmentShader::copies() const { return copies_only_ ? &copies_ : nullptr; }

bool GlslFragmentShader::reads_quad_neighbours_in_draw() const {
    if (!quad_neighbours_) return false;
    if (derivatives_ || !textures_) return true;
    // The executor takes a lookup's derivatives only where the sampler says the LOD matters
    // (TextureSampler::lod_matters), and no lookup of these dimensions says so in this draw.
    for (uint32_t m = implicit_lod_dims_; m; m &= m - 1)
        if (textures_->lod_matters_in(glsl::SamplerDim(__builtin_ctz(m)))) return true;
    return false;
}

void GlslFragmentShader::prepare(unsigned workers, const Tuning& tuning) const {
    if (workers_.size() < workers) workers_.resize(workers);
    sampler_path_ = tuning.sampler_path;
    texture_copies_ = tuning.texture_copies;
    linear_words_ = tuning.linear_words;
    simd_ = std::min(tuning.simd, best_simd_level());   // Executor::set_simd_level's
    for (Worker& w : workers_) {
        if (!w.executor || w.executor->hoists() != tuning.hoist_uniform_values)
            w.executor = std::make_unique<glsl::Executor>(program_->fragment, 128, tuning.hoist_uniform_values);
        w.executor->set_simd_level(tuning.simd);   // executors outlive draws; the level is the draw's
    }
}

uint64_t GlslFragmentShader::take_fast_texture_queries() const {
    uint64_t n = 0;
    for (Worker& w : workers_) n += std::exchange(w.fast_texture_queries, 0);
    return n;
}

void GlslFragmentShader::run(const FragmentBatch& b, FragmentResults& out, unsigned worker) const {
    Worker& w = workers_[worker];
    const glsl::IrProgram& ir = program_->fragment;
    const size_t L = b.lanes, S = b.stride();
    const size_t O = size_t(outputs_);
    out.outputs = outputs_;
    if (out.color.size() < 4 * O * L) out.color.resize(4 * O * L);   // grows only: no zero fill per batch
    if (texture_copy_.texture >= 0 && texture_copies_) {
        out.killed.clear();
        return run_texture_copy(b, out, worker);
    }
    const size_t R = uniform_only_ ? std::min<size_t>(L, 4) : L;   // lanes actually run
    if (builtins_read_ & kFrontFacing) {
        w.builtins.resize(R);
        for (size_t lane = 0; lane < R; ++lane) w.builtins[lane].i = b.front_facing[lane];
    }
    w.input_ptrs.assign(ir.inputs.size(), nullptr);
    for (size_t i = 0; i < ir.inputs.size(); ++i) {
        const int builtin = input_builtin_[i];
        if (input_word_[i] >= 0) w.input_ptrs[i] = reinterpret_cast<const Scalar*>(&b.varyings[size_t(input_word_[i]) * S]);
        else if (builtin >= 0 && builtin < 4) w.input_ptrs[i] = reinterpret_cast<const Scalar*>(&b.frag_coord[size_t(builtin) * S]);
        else if (builtin == 4) w.input_ptrs[i] = w.builtins.data();
        else if (builtin >= 5) w.input_ptrs[i] = reinterpret_cast<const Scalar*>(&b.point_coord[size_t(builtin - 5) * S]);
    }
    // Outputs go straight to the results; outputs nobody reads are not copied out.
    w.output_ptrs.assign(ir.outputs.size(), nullptr);
    const size_t written = broadcast_ ? 1 : O;   // broadcast: output 0 is copied below
    for (size_t k = 0; k < 4 * written; ++k) {
        if (color_slot_[k] >= 0) w.output_ptrs[size_t(color_slot_[k])] = reinterpret_cast<Scalar*>(&out.color[k * L]);
        else std::fill_n(&out.color[k * L], L, 0.0f);   // never written: undefined; softgl gives 0
    }
    if (depth_slot_ >= 0) {
        out.depth.resize(L);
        w.output_ptrs[size_t(depth_slot_)] = reinterpret_cast<Scalar*>(out.depth.data());
    }
    if (may_discard()) out.killed.assign(L, 0);
    else out.killed.clear();
    glsl::StageRun run;
    run.lane_count = int(R);
    run.inputs = w.input_ptrs.data();
    run.outputs = w.output_ptrs.data();
    run.uniforms = uniforms_;
    run.sampler = textures_ ? textures_ : &w.sampler;
    run.sampler_path = sampler_path_;
    run.fast_texture_queries = &w.fast_texture_queries;
    run.discarded = may_discard() ? out.killed.data() : nullptr;
    run.budget = budget_;
    w.executor->run(run);
    if (R < L) {
        for (size_t k = 0; k < 4 * written; ++k) {
            float* col = &out.color[k * L];
            const float quad[4] = {col[0], col[1], col[2], col[3]};
            size_t lane = R;
            for (; (lane & 3) == 0 && lane + 4 <= L; lane += 4) std::memcpy(&col[lane], quad, sizeof quad);
            for (; lane < L; ++lane) col[lane] = quad[lane & 3];
        }
        if (depth_slot_ >= 0)
            for (size_t lane = R; lane < L; ++lane) out.depth[lane] = out.depth[lane & 3];
    }
    if (broadcast_)
        for (size_t o = 1; o < O; ++o) std::copy_n(out.color.data(), 4 * L, &out.color[o * 4 * L]);
}

bool GlslFragmentShader::run_constant(FragmentResults& out, unsigned worker) const {
    if (!uniform_only_) return false;
    return run_one_quad(nullptr, out, worker);
}

bool GlslFragmentShader::run_flat(const uint32_t* varyings, FragmentResults& out, unsigned worker) const {
    if (!flat_) return false;
    return run_one_quad(varyings, out, worker);
}

// One quad, as run() shades it for a batch, every lane with the same inputs: `varyings` by word
// (null: zeros, for inputs whose values never reach an output); lane 0's results are kept.
bool GlslFragmentShader::run_one_quad(const uint32_t* varyings, FragmentResults& out, unsigned worker) const {
    Worker& w = workers_[worker];
    FragmentBatch& b = w.quad;
    const size_t L = 4;
    int words = 0;
    for (int word : input_word_) words = std::max(words, word + 1);
    b.lanes = L;
    b.varyings.assign(size_t(words) * L, 0);
    if (varyings)
        for (int word : input_word_)
            if (word >= 0) std::fill_n(&b.varyings[size_t(word) * L], L, varyings[word]);
    b.frag_coord.assign(4 * L, 0.0f);
    b.front_facing.assign(L, 0);
    b.point_coord.assign(2 * L, 0.0f);
    run(b, w.quad_results, worker);
    const FragmentResults& r = w.quad_results;
    out.outputs = r.outputs;
    out.color.resize(4 * size_t(r.outputs));
    for (size_t k = 0; k < out.color.size(); ++k) out.color[k] = r.color[k * L];
    out.depth.clear();
    if (depth_slot_ >= 0) out.depth.assign(1, r.depth[0]);
    out.killed.clear();   // uniform_only_ and flat_: the shader has no discard
    return true;
}

}  // namespace softgl
