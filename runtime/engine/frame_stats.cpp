// FrameStats stage names (frame_stats.h).
#include "runtime/engine/frame_stats.h"

namespace vista {

const char* stageName(Stage s) {
    switch (s) {
        case Stage::Cull: return "cull";
        case Stage::Near: return "near";
        case Stage::Readback: return "readback";
        case Stage::Opacity: return "opacity";
        case Stage::Seam: return "seam";
        case Stage::Horizon: return "horizon";
        case Stage::Cache: return "cache";
        case Stage::Haze: return "haze";
        case Stage::Reflect: return "reflect";
        case Stage::Rays: return "rays";
        case Stage::Composite: return "composite";
        case Stage::Count: break;
    }
    return "?";
}

}  // namespace vista
