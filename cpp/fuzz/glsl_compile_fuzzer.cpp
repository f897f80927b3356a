// libFuzzer target for the GLSL compiler: any bytes must compile or fail with an info log, never
// crash, hang or trip AddressSanitizer/UndefinedBehaviorSanitizer. Built by tools/run_fuzzers.sh.
//
// Input layout: byte 0 selects the stage (bit 0) and the WebGL version (bit 1); the rest is the
// shader source. Sources that compile are also linked against a fixed partner shader.
#include <cstddef>
#include <cstdint>
#include <string>

#include "softgl/glsl/compiler.h"

using namespace softgl::glsl;

namespace {

const char* kPartnerFragment100 = "precision mediump float; void main() { gl_FragColor = vec4(1.0); }";
const char* kPartnerVertex100 = "attribute vec4 p; void main() { gl_Position = p; }";
const char* kPartnerFragment300 = "#version 300 es\nprecision mediump float; out vec4 o; void main() { o = vec4(1.0); }";
const char* kPartnerVertex300 = "#version 300 es\nin vec4 p; void main() { gl_Position = p; }";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    const Stage stage = (data[0] & 1) ? Stage::Fragment : Stage::Vertex;
    const int webgl_version = (data[0] & 2) ? 2 : 1;
    const std::string source(reinterpret_cast<const char*>(data + 1), size - 1);
    CompileResult result = compile(source, stage, webgl_version);
    if (!result.ok) return 0;
    const bool es300 = result.shader->version >= 300;
    const std::string partner = stage == Stage::Vertex ? (es300 ? kPartnerFragment300 : kPartnerFragment100)
                                                       : (es300 ? kPartnerVertex300 : kPartnerVertex100);
    CompileResult other = compile(partner, stage == Stage::Vertex ? Stage::Fragment : Stage::Vertex, webgl_version);
    if (!other.ok) return 0;
    if (stage == Stage::Vertex) link(*result.shader, *other.shader);
    else link(*other.shader, *result.shader);
    return 0;
}
