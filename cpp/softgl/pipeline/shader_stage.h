// The pipeline's view of a linked program: a vertex stage and a fragment stage that run over many
// lanes at once (structure of arrays). The GLSL executor implements these; tests may implement
// them directly in C++ to exercise the fixed-function stages.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "softgl/core/objects.h"
#include "softgl/core/tuning.h"
#include "softgl/pipeline/vertex_fetch.h"

namespace softgl {

// How the varyings a vertex shader writes are laid out: `words` 32-bit words per vertex; for each
// word, whether it is flat (integers and `flat` qualifiers) and whether the fragment stage reads it.
struct VaryingLayout {
    int words = 0;
    std::vector<uint8_t> flat;
    std::vector<uint8_t> read_by_fragment;
};

struct VertexShaderOutputs {
    size_t count = 0;
    std::vector<float> position;      // gl_Position, 4 floats per vertex
    std::vector<float> point_size;    // gl_PointSize per vertex (1 when not written)
    std::vector<uint32_t> varyings;   // layout.words words per vertex (float or int bit patterns)
};

// Where VertexShader::run writes its `count` vertices, in VertexShaderOutputs' layout: straight
// into the batch's arrays at the job's place (no copy of the results per job).
struct VertexDestination {
    float* position;      // [4 * v + c]
    float* point_size;    // [v]
    uint32_t* varyings;   // [v * layout.words + word]
};

class VertexShader {
public:
    virtual ~VertexShader() = default;
    virtual uint32_t used_attributes() const = 0;   // bit per attribute location
    virtual const VaryingLayout& varying_layout() const = 0;
    // Called once per draw before run(), with the draw's tuning (a context's may change between
    // draws, and each context has its own).
    virtual void prepare(const Tuning& tuning) const { (void)tuning; }
    // Shades `count` vertices; attribs[loc] holds their attribute values for each used location;
    // vertex_ids[v] is gl_VertexID and instance_ids[v] gl_InstanceID (the vertices of several
    // instances are shaded in one call). Writes every element of `out` for the `count` vertices.
    // Must be safe to call from several threads at once.
    virtual void run(const std::array<AttributeStream, kMaxVertexAttribs>& attribs, size_t count,
                     const uint32_t* vertex_ids, const uint32_t* instance_ids, const VertexDestination& out) const = 0;
};

// Fragments of whole 2x2 quads: lane 4*q + j is pixel j (dx = j & 1, dy = j >> 1) of quad q, so
// that derivatives are differences within a quad. Arrays are [component][lane], a component's
// lanes `stride()` apart. A shader that does not read its quad neighbours
// (FragmentShader::reads_quad_neighbours) may be given lanes that are single pixels, in any order.
struct FragmentBatch {
    size_t lanes = 0;
    size_t lane_stride = 0;            // 0: `lanes` (the arrays hold exactly the batch)
    std::vector<uint32_t> varyings;    // [word * stride() + lane]
    std::vector<float> frag_coord;     // [c * stride() + lane], c = x, y, z, w
    std::vector<uint8_t> front_facing; // [lane]
    std::vector<float> point_coord;    // [c * stride() + lane], c = s, t
    size_t stride() const { return lane_stride ? lane_stride : lanes; }
};

// Colour outputs of a fragment shader: gl_FragColor, gl_FragData[n] (ES 1.00, WEBGL_draw_buffers)
// or `layout(location = n) out` (ES 3.00), n < kMaxFragmentOutputs.
inline constexpr int kMaxFragmentOutputs = 8;

struct FragmentResults {
    // [(4 * o + c) * lanes + lane] for colour output o < outputs; output 0 comes first, so the
    // single-output layout is [c * lanes + lane].
    std::vector<float> color;
    int outputs = 1;                   // colour outputs in `color` (locations 0 .. outputs - 1)
    std::vector<float> depth;          // [lane], when the shader writes gl_FragDepth
    std::vector<uint8_t> killed;       // [lane], 1 where the shader discarded
};

// The colour outputs of a shader that only copies varyings or constants to them (docs/architecture.md, "Fast paths":
// such a shader needs no shading): component c of output o is varying word word[4 * o + c] of
// the lane, bit for bit, or the constant bits[4 * o + c] where that word is -1.
struct FragmentCopies {
    int outputs = 1;
    std::array<int, 4 * kMaxFragmentOutputs> word{};
    std::array<uint32_t, 4 * kMaxFragmentOutputs> bits{};
};

// Built-in fragment inputs, as bits of FragmentShader::builtins_read().
enum FragmentBuiltin : uint32_t {
    kFragCoordX = 1u << 0, kFragCoordY = 1u << 1, kFragCoordZ = 1u << 2, kFragCoordW = 1u << 3,
    kFrontFacing = 1u << 4, kPointCoordS = 1u << 5, kPointCoordT = 1u << 6,
};

class FragmentShader {
public:
    virtual ~FragmentShader() = default;
    virtual bool may_discard() const = 0;
    virtual bool writes_depth() const = 0;
    // Whether a lane reads values of the other lanes of its quad (dFdx, dFdy, fwidth, the implicit
    // LOD of a texture lookup): only then must helper pixels be shaded, and lanes come as quads.
    virtual bool reads_quad_neighbours() const { return true; }
    // The same for the current draw, with its bound textures: false also when the only reads are
    // implicit-LOD lookups whose LOD cannot change the result (the sampler's lod_matters_in), so
    // the derivatives are never taken. Asked once per draw, after the textures are bound.
    virtual bool reads_quad_neighbours_in_draw() const { return reads_quad_neighbours(); }
    // The built-ins run() reads (FragmentBuiltin bits): the pipeline fills only these arrays of
    // the batch (docs/architecture.md, "Fast paths": what the shader does not read is not computed). Varyings: the vertex
    // stage's VaryingLayout::read_by_fragment says which words are filled.
    virtual uint32_t builtins_read() const { return ~0u; }
    // Called once per draw before run(), with the draw's tuning: `workers` threads will call run()
    // concurrently.
    virtual void prepare(unsigned workers, const Tuning& tuning) const { (void)workers, (void)tuning; }
    // Runs on worker thread `worker` (< the prepared count), each with its own batch and results.
    virtual void run(const FragmentBatch& batch, FragmentResults& out, unsigned worker) const = 0;
    // docs/architecture.md, "Fast paths": a shader whose results depend only on uniforms gives every fragment of a draw
    // the same values. Such a shader fills `out` for one lane (lanes = 1 in the layout above) on
    // `worker` and returns true; any other returns false. After prepare(), like run().
    virtual bool run_constant(FragmentResults& out, unsigned worker) const { (void)out, (void)worker; return false; }
    // docs/architecture.md, "Fast paths": the results of one fragment whose varying words are
    // `varyings` (indexed by word), for a primitive where every fragment reads those same values.
    // Only a shader whose lanes are independent and read no built-in, cannot discard and does not
    // write depth gives them (as run_constant: one lane in `out`, true); any other returns false.
    virtual bool run_flat(const uint32_t* varyings, FragmentResults& out, unsigned worker) const {
        (void)varyings, (void)out, (void)worker;
        return false;
    }
    // Whether run_flat gives results (the same for every draw of the program).
    virtual bool runs_flat() const { return false; }
    // Non-null when the program only copies (FragmentCopies; no discard, no depth): the pipeline
    // copies the colours from the batch, or reads them there, instead of calling run() (unless the
    // context's Tuning turns fragment_copies off; run() always runs the program).
    virtual const FragmentCopies* copies() const { return nullptr; }
    // Whether the program's colour is one texture lookup that run() serves without the executor
    // when the draw's Tuning::texture_copies allows (docs/architecture.md, "Fast paths": texture
    // copies).
    virtual bool copies_texture() const { return false; }
    // Texel words (docs/architecture.md, "Fast paths"): whether, for this draw (after prepare, with
    // its textures bound), run() gives every lane the channels k / 255 of one 8-bit unorm texel
    // (a texture copy of a NEAREST lookup of byte storage), or, with Tuning::linear_words, a
    // LINEAR lookup of one such level; run_words then gives the RGBA8 words a plain write makes
    // of those channels, words[lane], instead of the floats.
    virtual bool gives_texel_words() const { return false; }
    virtual void run_words(const FragmentBatch& batch, uint32_t* words, unsigned worker) const {
        (void)batch, (void)words, (void)worker;
    }
    // The most instructions one invocation can run (glsl::instructions_bound); UINT64_MAX when
    // unknown. A draw whose fragment work has no small bound can be stopped after writing pixels,
    // so it keeps copies to put them back (pipeline/draw_rollback.h).
    virtual uint64_t instructions_bound() const { return ~uint64_t(0); }
};

}  // namespace softgl
