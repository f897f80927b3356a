// SOFTGL_fog entry points: the extension object's fogf / fogi / fogfv (OpenGL 1.x glFog*).
#include <cmath>

#include "softgl/api/context.h"

namespace softgl {

void Context::fog(const char* call, GLenum pname, const float* values, int count) {
    if (!ext_fog_) return error(gl::INVALID_OPERATION, call, "the SOFTGL_fog extension is not enabled");
    FogState& f = state_.fog;
    const float v = values[0];
    switch (pname) {
        case gl::FOG_MODE: {
            const GLenum mode = GLenum(v);
            if (float(mode) != v || (mode != gl::LINEAR && mode != gl::EXP && mode != gl::EXP2))
                return error(gl::INVALID_ENUM, call, "FOG_MODE must be LINEAR, EXP or EXP2");
            f.mode = mode;
            return;
        }
        case gl::FOG_DENSITY:
            if (!(v >= 0.0f)) return error(gl::INVALID_VALUE, call, "FOG_DENSITY must not be negative");
            f.density = v;
            return;
        case gl::FOG_START: f.start = v; return;
        case gl::FOG_END: f.end = v; return;
        case gl::FOG_COLOR:
            if (count < 4) return error(gl::INVALID_VALUE, call, "FOG_COLOR needs 4 values");
            for (int k = 0; k < 4; ++k) f.color[size_t(k)] = values[k] > 0 ? (values[k] < 1 ? values[k] : 1) : 0;  // GL 1.5: clamped
            return;
        case gl::FOG_COORDINATE_SOURCE: {
            const GLenum source = GLenum(v);
            if (float(source) != v || (source != gl::FRAGMENT_DEPTH && source != gl::WINDOW_DEPTH_SOFTGL))
                return error(gl::INVALID_ENUM, call, "FOG_COORDINATE_SOURCE must be FRAGMENT_DEPTH or WINDOW_DEPTH_SOFTGL");
            f.coordinate_source = source;
            return;
        }
        default:
            return error(gl::INVALID_ENUM, call, enum_name(pname) + " is not a fog parameter");
    }
}

}  // namespace softgl
