// The draw plan: which kernels and fast paths a draw takes, and for each fast path it does not
// take, why not (docs/architecture.md, "The draw plan"). plan_draw turns the state, the program,
// the render target, the tuning and the draw call into this plain struct before any vertex is
// shaded; the tile pass (pipeline/tile_pass) reads it instead of deciding for itself, and fills in
// its second step, what only running the shader once tells (a uniform-only shader's constant
// colour and the blend table built from it). It prints, compares and hashes: the context keeps
// the last draw's plan for gl.last_draw_plan(), and later specialisation keys on it.
//
// To add a fast path: a field here (a Path: taken, or the first reason it is not), its decision
// in plan_draw (or plan_shading), its line in fields(), and the tile pass step that reads it.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "softgl/core/simd.h"
#include "softgl/core/tuning.h"
#include "softgl/pipeline/depth_stencil.h"
#include "softgl/pipeline/draw_inputs.h"
#include "softgl/pipeline/fog.h"
#include "softgl/pipeline/fragment_ops.h"
#include "softgl/surface/blend.h"

namespace softgl {

// Whether a fast path is taken (Taken), or the first reason it is not.
enum class Path : uint8_t {
    Taken,
    NotRasterized,          // the draw rasterizes nothing (rasterizer discard, or no output possible)
    NotShaded,              // no tile pass has run yet: the shader has not run once (second step)
    TuningOff,              // switched off in the context's Tuning (core/tuning.h)
    Discard,                // the shader may discard
    FragDepth,              // the shader writes gl_FragDepth
    CoverageOps,            // alpha-to-coverage or SAMPLE_COVERAGE (multisampled)
    NoDepthTest,
    StencilTest,
    LateTests,              // depth/stencil tests after shading
    DepthStencilTests,      // depth or stencil tests at all
    DepthNotPerQuad,        // a depth test that is not the quad early depth test
    DepthFunc,              // not LESS, LEQUAL, GREATER or GEQUAL
    BlendLab,               // the blend lab's hooks see every fragment (pipeline/fragment_sink.h)
    FramebufferObject,
    FloatDrawingBuffer,     // the drawing buffer holds floats (colour writes through RenderTarget)
    Smoothing,              // SOFTGL_smooth enabled (area coverage)
    Multisampled,
    NoColorWrite,
    ReadsDestination,       // blending reads the destination
    Fog,
    NotUniformOnly,         // the shader's colour depends on more than uniforms
    NotCopy,                // the shader does more than copy varyings or constants to colours
    NotOneVaryingVec4,      // a copy, but not of one whole vec4 varying to one colour output
    NotInterpolated,        // a copy of a flat varying, or points: nothing to interpolate
    GenericKernel,          // the blend has no colour kernel of its own (ColorKernel::Generic)
    NoBlending,             // nothing to look up: the colour is written as it is
    NotPerChannel,          // the blend mixes channels (blend_is_per_channel)
    FusedCopy,              // the varying goes straight into pixels: no shader batch (fused_copy)
    ConstantColor,          // the shader's colour is computed once: no shader batch (constant_color)
    QuadNeighbours,         // the shader takes derivatives or implicit-LOD lookups
    DepthNot24Bit,          // a DEPTH_COMPONENT16 or 32F attachment: its words are not the kernel's
    AttachmentSizesDiffer,  // the depth image is wider than the target: its rows are not the target's
    WritesColor,            // a colour buffer receives the shader's colour
    NotTextureCopy,         // the shader is not one texture lookup copied to its colour
    NotNearestBytes,        // the lookup is not NEAREST (nor one LINEAR level) of 8-bit unorm storage (TextureSampler::gives_words)
};
const char* path_name(Path p);

enum class DrawSkip : uint8_t { No, RasterizerDiscard, NoOutput };
enum class DrawTarget : uint8_t { DrawingBuffer, FloatDrawingBuffer, FramebufferObject };

// One field of a plan, for printing and for Python: a yes/no (Bool), a number (Int), a name
// (Name) or a fast path (Path: `value` the Path, `text` its name when not taken).
struct DrawPlanField {
    enum Kind : uint8_t { Bool, Int, Name, PathKind };
    const char* group;   // the stage the field belongs to (the printed line)
    const char* name;
    Kind kind;
    int64_t value;
    const char* text;    // Name and Path: the printed value
};

struct DrawPlan {
    // ---- the draw ----
    int vertices_per_primitive = 3;     // 1 points, 2 lines, 3 triangles
    DrawSkip skip = DrawSkip::No;       // ES 3.0 §2.15 rasterizer discard; nothing writable
    DrawTarget target = DrawTarget::DrawingBuffer;
    int samples = 1;
    SimdLevel simd = SimdLevel::Scalar;   // every stage's level: min(tuning.simd, best_simd_level())
    uint32_t batch_primitives = kDrawBatchPrimitivesDefault;
    bool blend_lab = false;             // the sink's hooks run (the RGBA8 drawing buffer only)
    // ---- tests ----
    bool depth_test = false, stencil_test = false;
    bool writes_depth_stencil = false;
    Path tests_before_shading = Path::Taken;   // the shader allows tests before it runs
    Path quad_depth = Path::Taken;             // early depth a quad at a time (pipeline/early_depth)
    Path depth_bounds = Path::Taken;           // per-tile depth bounds skip hidden primitives
    bool depth_bounds_sabotaged = false;       // ... at the wrong corner (Tuning, for tests)
    Path hidden_surface_removal = Path::Taken; // owner map: only the last fragment of a pixel is shaded
    bool hidden_surface_in_every_tile = false; // ... in every tile, not only where primitives pile up
    bool hidden_surface_by_boxes = false;      // ... piling up counted by bounding boxes, not triangle areas
    // ---- shading ----
    Path fragment_copies = Path::Taken;   // the shader only copies: its colours come from the batch
    int copied_word = -1;                 // ... one vec4 varying's first word, read in place
    Path fused_copy = Path::Taken;        // ... interpolated straight into pixels (smooth, not points)
    int copied_index = -1;                // ... its place among the interpolated words
    // The shader is one texture lookup at a varying, copied to its colour: run() asks the sampler
    // itself, without the executor (FragmentShader::copies_texture).
    Path texture_copy = Path::Taken;
    // ... whose texels' RGBA8 words go to the pixels as they are (second step: the bound texture
    // decides; FragmentShader::gives_texel_words).
    Path texel_words = Path::NotShaded;
    // Second step (plan_shading, when the first tile pass is prepared):
    bool shaded = false;                  // the second step ran
    bool uniform_only = false;            // FragmentShader::run_constant gave the colour
    Path constant_color = Path::NotShaded;   // that colour goes straight to the colour kernels
    Path blend_table = Path::NotShaded;      // ... blended by table lookup (fragment_ops.h)
    Path whole_rect_blend = Path::NotShaded; // ... whole blocks blended in place (whole_rect.h)
    // Fragments of many primitives of a tile gathered into full shader batches (tile_pass), and
    // in those batches only covered pixels, no helper lanes (the shader reads no quad neighbour).
    // Decided in the first step, and again in the second (a constant colour needs no batch).
    Path fragment_batches = Path::Taken;
    Path no_helper_lanes = Path::Taken;
    // Nothing reads the shader's results (no colour buffer written, tests before shading, no
    // coverage operations, no blend lab): fragments are tested (and depth/stencil written), not
    // shaded. ES 3.0 fragment shaders have no other effect (GLSL ES 3.00 §3.8: no side effects).
    Path depth_only = Path::Taken;
    // ... and single-sampled with the quad early depth test, no smoothing: the 8x8 blocks a
    // primitive covers whole are tested in place, without quads (whole_rect.h depth_covered_part).
    Path depth_blocks = Path::Taken;
    // ---- colour ----
    bool writes_color = false;
    ColorKernel kernel = ColorKernel::Plain;
    bool plain_write = true;              // no destination read
    bool all_channels = true;             // colour mask all true
    bool area_coverage = false;           // SOFTGL_smooth: coverage fractions scale alpha (S == 1)
    bool coverage_ops = false;
    bool fog = false;
    Path color_kernels = Path::Taken;     // chunks blended by the colour kernels, not lane by lane

    bool rasterizes() const { return skip == DrawSkip::No; }
    bool late_tests() const { return tests_before_shading != Path::Taken && (depth_test || stencil_test); }
    bool early_tests() const { return tests_before_shading == Path::Taken && (depth_test || stencil_test); }

    std::vector<DrawPlanField> fields() const;
    // key=value lines, one per group (draw, tests, shading, colour).
    std::string to_string() const;
    uint64_t hash() const;
    bool operator==(const DrawPlan& o) const;
    bool operator!=(const DrawPlan& o) const { return !(*this == o); }
};

// What the state asks of every fragment of a draw: blending, the depth and stencil tests, fog.
// Worked out once per draw, for the plan and the tile pass.
struct FragmentOps {
    BlendOp blend;
    DepthStencilOp depth_stencil;
    FogOp fog;
    static FragmentOps from(const DrawInputs& in);
};

// The plan's first step: everything the inputs decide (`ops`: FragmentOps::from(in)).
DrawPlan plan_draw(const DrawInputs& in, const DrawCall& call, const FragmentOps& ops);

// The second step, once the shader has run for its constant colour (FragmentShader::run_constant):
// `uniform_only` says whether it gave one.
void plan_shading(DrawPlan& plan, bool uniform_only, const BlendOp& blend);
// ... and, after it, whether a texture copy's texels go to the pixels as words (the shader
// prepared and the draw's textures bound: FragmentShader::gives_texel_words).
void plan_texel_words(DrawPlan& plan, const Tuning& tuning, const FragmentShader& fs);

}  // namespace softgl
