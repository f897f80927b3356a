#include "softgl/core/tuning.h"

namespace softgl {

Tuning& Tuning::process_default() {
    static Tuning tuning;
    return tuning;
}

}  // namespace softgl
